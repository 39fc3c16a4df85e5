"""vkpose: detection and 6-DoF pose of texture-poor objects in RGB-D images, on Vulkan.

The pipeline of the C++ library and the `vkpose` command, with numpy in and out::

    import cv2, vkpose
    bank = vkpose.Bank.load("cup.vkpb")                # or vkpose.train("cup.stl", units="mm")
    det = vkpose.Detector([bank])
    result = det.detect(cv2.imread("rgb.png"), cv2.imread("depth.png", cv2.IMREAD_UNCHANGED), K)
    for d in result:
        print(d.object, d.score, d.R, d.t)
    cv2.imwrite("overlay.png", vkpose.draw(cv2.imread("rgb.png"), result))

Errors: bad input raises InputError (a ValueError) with the message the CLI prints; no usable
Vulkan device raises DeviceError (a RuntimeError).
"""

import sys as _sys

try:
    import numpy as _numpy  # noqa: F401  (arrays in and out)
except ImportError:  # pragma: no cover - depends on the machine
    raise ImportError(
        "vkpose needs numpy for this Python (%s). On Debian: apt-get install python3-numpy, and run "
        "vkpose with /usr/bin/python3 (or run scripts/install-python.sh, which makes Debian's packages "
        "visible to this interpreter)." % _sys.executable
    ) from None

try:
    from ._vkpose import (  # noqa: F401
        __version__,
        Bank,
        Camera,
        Config,
        ConfigSection,
        Detection,
        Detector,
        Device,
        DeviceError,
        DeviceInfo,
        InputError,
        Result,
        devices,
        draw,
        evaluate,
        load_frame,
        load_scene_cameras,
        plan_picks,
        read_bop_results,
        synth,
        synth_frame,
        train,
        write_bop_results,
    )
except ImportError as _error:  # pragma: no cover - depends on the machine
    raise ImportError(
        "vkpose's extension module could not be loaded into Python %d.%d (%s): %s. It is built for the "
        "Python that CMake found (/usr/bin/python3 on Debian); rebuild with -DPython3_EXECUTABLE=%s to use "
        "this one." % (_sys.version_info[0], _sys.version_info[1], _sys.executable, _error, _sys.executable)
    ) from None

# Shown as vkpose.X, not vkpose._vkpose.X.
for _name in ("Bank", "Camera", "Config", "ConfigSection", "Detection", "Detector", "Device", "DeviceError",
              "DeviceInfo", "InputError", "Result"):
    globals()[_name].__module__ = "vkpose"

InputError.__doc__ = "Bad input: a missing or corrupt file, inconsistent images, nonsense values (a ValueError)."
DeviceError.__doc__ = "No usable Vulkan device, or the device failed (a RuntimeError)."


class _ProgressBar:
    """progress=True: a one-line bar on stderr (only on a terminal), like the CLI's."""

    def __init__(self, label):
        self.label = label
        self.enabled = _sys.stderr.isatty()
        self.drawn = False

    def __call__(self, done, total):
        if not self.enabled or total <= 0:
            return
        width = 30
        filled = int(width * done / total)
        _sys.stderr.write(
            "\r%s [%s%s] %d/%d  %3.0f%%" % (self.label, "#" * filled, "." * (width - filled), done, total,
                                           100.0 * done / total))
        self.drawn = True
        if done >= total:
            _sys.stderr.write("\n")
            self.drawn = False
        _sys.stderr.flush()


__all__ = [
    "__version__",
    "Bank",
    "Camera",
    "Config",
    "ConfigSection",
    "Detection",
    "Detector",
    "Device",
    "DeviceError",
    "DeviceInfo",
    "InputError",
    "Result",
    "devices",
    "draw",
    "evaluate",
    "load_frame",
    "load_scene_cameras",
    "plan_picks",
    "read_bop_results",
    "synth",
    "synth_frame",
    "train",
    "write_bop_results",
]
