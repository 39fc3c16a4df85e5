"""The module's surface without the real frames: version, devices, config, cameras, banks, and
bad input, which must be a clear Python exception (never a crash)."""

import json
import os
import re
import subprocess
import sys

import numpy as np
import pytest

import vkpose
from conftest import REPO


def test_version_and_devices(cli):
    assert re.fullmatch(r"\d+\.\d+\.\d+", vkpose.__version__)
    code, out, _ = cli("--version")
    assert code == 0 and out.split()[-1] == vkpose.__version__
    devices = vkpose.devices()
    assert devices and any(d.usable for d in devices)
    assert all(d.index == i for i, d in enumerate(devices))
    device = vkpose.Device()
    assert device.name == devices[device.index].name
    assert vkpose.Device() == device  # opened once, shared
    assert vkpose.Device(device.index).name == device.name


def test_errors_are_value_and_runtime_errors():
    assert issubclass(vkpose.InputError, ValueError)
    assert issubclass(vkpose.DeviceError, RuntimeError)
    with pytest.raises(ValueError, match="at least one template bank"):
        vkpose.Detector([], None)
    with pytest.raises(ValueError, match="does not exist"):
        vkpose.Device(999)
    with pytest.raises(ValueError, match="device index"):
        vkpose.Device(-1)


def test_no_vulkan_driver_is_a_runtime_error():
    # A process whose Vulkan loader finds no driver: the module imports, and asking for a device
    # raises DeviceError (a RuntimeError) with the CLI's message.
    code = (
        "import vkpose\n"
        "try:\n"
        "    vkpose.Detector(['x.vkpb'])\n"
        "except ValueError as e:\n"
        "    print('bank first:', e)\n"
        "try:\n"
        "    vkpose.devices()\n"
        "except RuntimeError as e:\n"
        "    print(type(e).__name__, isinstance(e, vkpose.DeviceError), e)\n"
    )
    env = dict(os.environ, VK_ICD_FILENAMES="/nonexistent/icd.json", VK_DRIVER_FILES="/nonexistent/icd.json")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert p.returncode == 0, p.stderr
    assert "bank first: x.vkpb" in p.stdout
    assert "DeviceError True" in p.stdout


def test_config_defaults_are_the_cli_defaults(cli):
    code, out, _ = cli("config", "--print-defaults")
    assert code == 0
    assert vkpose.Config().to_dict() == json.loads(out)
    assert json.loads(vkpose.Config().to_json()) == json.loads(out)
    assert vkpose.Config() == vkpose.Config.load(REPO / "assets" / "config_defaults.json")


def test_config_attributes_and_names():
    c = vkpose.Config()
    assert c.verify.threshold == 0.4  # float32 shown as its shortest decimal
    c.verify.threshold = 0.5
    c["match.threshold"] = 85
    assert c["verify.threshold"] == 0.5 and c.match.threshold == 85.0
    assert "verify.threshold=0.5" in repr(c)
    assert "refine.voxel_size" in c.keys()
    assert set(dir(c.verify)) >= {"threshold", "resolution"}
    d = vkpose.Config({"verify": {"threshold": 0.5}, "match": {"threshold": 85}})
    assert d == c
    c.detector.estimate_poses = False
    assert c.to_dict()["detector"]["estimate_poses"] is False
    assert "verify.threshold" in c.explain()


def test_config_rejects_bad_values_and_keeps_its_values(cli, tmp_path):
    c = vkpose.Config()
    with pytest.raises(ValueError, match="expected a number"):
        c.verify.threshold = "high"
    with pytest.raises(ValueError, match="expected True or False"):
        c.detector.estimate_poses = 1
    with pytest.raises(ValueError, match="whole number"):
        c.cluster.min_templates = 2.5
    with pytest.raises(AttributeError, match="sections: match"):
        c.nosuch
    with pytest.raises(AttributeError, match="keys of verify"):
        c.verify.nosuch = 1
    with pytest.raises(KeyError):
        c["verify"]
    # Out of range: the library's message, the same as the CLI's for a config file.
    with pytest.raises(ValueError) as error:
        c.match.threshold = 0
    assert c == vkpose.Config()
    bad = tmp_path / "bad.json"
    bad.write_text('{"match": {"threshold": 0}}')
    code, _, err = cli("config", "--check", bad)
    assert code == 1 and str(error.value) in err
    with pytest.raises(ValueError, match="unknown"):
        vkpose.Config({"match": {"nosuch": 1}})
    path = tmp_path / "c.json"
    c.save(path)
    with pytest.raises(ValueError, match="overwrite=True"):
        c.save(path)
    assert vkpose.Config(path) == c


def test_camera():
    cam = vkpose.Camera.load(REPO / "assets" / "camera_primesense.json")
    K = cam.K
    assert K.shape == (3, 3) and K[0, 0] == cam.fx and K[1, 2] == cam.cy and K[2, 2] == 1
    again = vkpose.Camera.from_K(K, cam.width, cam.height)
    assert (again.fx, again.fy, again.cx, again.cy) == (cam.fx, cam.fy, cam.cx, cam.cy)
    with pytest.raises(ValueError, match="3x3"):
        vkpose.Camera.from_K(np.eye(2), 640, 480)
    with pytest.raises(ValueError, match="intrinsic matrix"):
        vkpose.Camera.from_K(np.ones((3, 3)), 640, 480)
    with pytest.raises(ValueError):
        vkpose.Camera(-500, 500, 320, 240)
    with pytest.raises(ValueError, match="nosuch.json"):
        vkpose.Camera.load("nosuch.json")


def test_missing_and_damaged_banks_give_the_cli_message(cli, tmp_path):
    missing = tmp_path / "missing.vkpb"
    with pytest.raises(ValueError) as error:
        vkpose.Bank.load(missing)
    code, _, err = cli("info", "--bank", missing)
    assert code == 1 and err.strip() == "vkpose: error: " + str(error.value)
    damaged = tmp_path / "damaged.vkpb"
    damaged.write_bytes(b"VKPB" + b"\0" * 60)
    with pytest.raises(ValueError, match="damaged.vkpb"):
        vkpose.Bank.load(damaged)
    with pytest.raises(ValueError, match="bank file paths"):
        vkpose.Detector([42])


def test_training_checks_its_arguments_before_any_work(tmp_path):
    mesh = REPO / "assets" / "meshes" / "angle_bracket.ply"
    with pytest.raises(ValueError, match="radii"):
        vkpose.train(mesh, radii="far")
    with pytest.raises(ValueError, match="hemisphere"):
        vkpose.train(mesh, hemisphere="lower")
    with pytest.raises(ValueError, match="units"):
        vkpose.train(mesh, units="inches")
    with pytest.raises(ValueError, match="nosuch.stl"):
        vkpose.train(tmp_path / "nosuch.stl")
    with pytest.raises(ValueError, match="progress"):
        vkpose.train(mesh, progress=5)
    with pytest.raises(ValueError, match="resting"):
        vkpose.train(mesh, resting="sideways")
    with pytest.raises(ValueError, match="full_turn_within"):
        vkpose.train(mesh, full_turn_within=95)


def test_training_refuses_an_object_too_small_for_linemod_unless_allowed():
    # The demo's bracket (136 mm) at 4 m: 20 pixels, 0.5 cells of the coarse level, under the 2
    # a part needs: refused. Allowed, training warns; it may then find too few features in
    # every view, and either way the warning came first.
    mesh = REPO / "assets" / "meshes" / "angle_bracket.ply"
    with pytest.raises(ValueError, match="allow_small"):
        vkpose.train(mesh, units="mm", views=2, radii=4.0, inplane=0)
    with pytest.warns(UserWarning, match="cells of LINEMOD's coarsest level"):
        try:
            vkpose.train(mesh, units="mm", views=2, radii=4.0, inplane=0, allow_small=True)
        except ValueError:
            pass


def test_training_finds_the_up_axis(meshes):
    small = dict(views=2, radii=0.6, inplane=0)
    milk = vkpose.train(meshes / "milk.stl", units="m", **small)
    assert milk.up_axis == "-z" and milk.hemisphere == "upper"
    assert "up axis -z" in repr(milk)
    assert vkpose.train(meshes / "milk.stl", units="m", up="+z", **small).up_axis == "+z"
    # Standing, seen from 0.6 m: no whole turn near the pole unless asked for.
    assert milk.full_turn_within == 0.0
    assert vkpose.train(meshes / "milk.stl", units="m", full_turn_within=25, **small).full_turn_within == 25.0
    with pytest.raises(ValueError, match="up axis 'z'"):
        vkpose.train(meshes / "milk.stl", units="m", up="z", **small)
