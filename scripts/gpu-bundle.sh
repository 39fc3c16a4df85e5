#!/usr/bin/env bash
# Packs a built vkpose for a GPU machine that has the NVIDIA driver but none of vkpose's Debian
# libraries and no package registry (the device tool's `run`: the working tree and the carried
# folders, 64 MiB in all).
#
#   cmake --build --preset release && bash scripts/gpu-bundle.sh [build/release/vkpose]
#
# Writes .gpu/ (and adds it to .git/info/exclude):
#   vkpose.tar.xz  the stripped binary and every shared library it loads, but glibc and the
#                  Vulkan/GL loaders (about 30 MB)
#   *.deb          Debian's Vulkan and glvnd loader packages (libvulkan1, libglvnd0, libglx0,
#                  libegl1, libgl1, libopengl0, libgles2), for the remote to unpack into /
#   data/          the real frames and meshes the benchmarks read (../shared/data)
#   run.sh         a copy of scripts/gpu-run.sh
# Then, on the GPU machine (device tool: carry [".gpu"]):
#   bash .gpu/run.sh 'vkpose bench detect --bank /tmp/cup.vkpb --source icbin --json $OUT/icbin.json'
#
# What makes Vulkan find the NVIDIA driver there (found on an H200, 2026-11-28): the loader
# packages unpacked into / with `dpkg -x` then `ldconfig`, VK_DRIVER_FILES pointing at the
# driver's ICD file, and the bundle carrying none of libvulkan, libGLX or libGLdispatch. The
# NVIDIA ICD (libGLX_nvidia) loads through glvnd: carried in LD_LIBRARY_PATH instead, the
# loader fails with "Could not get 'vkCreateInstance' ... for ICD libGLX_nvidia.so.0".
#
# OpenCV's imgcodecs links GDAL, whose own dependencies are over 100 MB; vkpose never reads a
# GDAL format, so a stub library defining the GDAL symbols imgcodecs names (each returning 0)
# takes its place.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bin=${1:-build/release/vkpose}
data=${VKPOSE_DATA:-$root/../shared/data}
[ -x "$bin" ] || { echo "gpu-bundle: no $bin: build first (cmake --build --preset release)" >&2; exit 1; }
[ -d "$data/icbin" ] || { echo "gpu-bundle: no real frames under $data (set VKPOSE_DATA)" >&2; exit 1; }
mkdir -p .git/info .gpu
grep -qx '/.gpu/' .git/info/exclude 2>/dev/null || echo '/.gpu/' >> .git/info/exclude
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/vk/lib"
strip -o "$work/vk/vkpose" "$bin"

# The GDAL stub: every GDAL symbol imgcodecs needs, as a function returning 0.
imgcodecs=$(ldd "$bin" | awk '/libopencv_imgcodecs/{print $3}')
if [ -n "$imgcodecs" ]; then
  { echo .text
    for s in $(nm -D --undefined-only "$imgcodecs" | awk '{print $2}' | grep GDAL); do
      printf '.globl %s\n.type %s,@function\n%s: xor %%eax,%%eax; ret\n' "$s" "$s" "$s"
    done; } > "$work/gdal.s"
  gcc -shared -nostdlib -Wl,-soname,libgdal.so.32 -o "$work/vk/lib/libgdal.so.32" "$work/gdal.s"
fi

# The library closure, walked by DT_NEEDED, without GDAL's subtree, glibc and the loaders.
python3 - "$bin" "$work/vk/lib" <<'PY'
import os, re, shutil, subprocess, sys
binary, out = sys.argv[1], sys.argv[2]
paths = {}
for line in subprocess.run(["ldd", binary], capture_output=True, text=True).stdout.splitlines():
    m = re.match(r"\s*(\S+) => (\S+)", line)
    if m:
        paths[m.group(1)] = m.group(2)
def needed(path):
    dyn = subprocess.run(["readelf", "-d", path], capture_output=True, text=True).stdout
    return re.findall(r"NEEDED.*\[(.*?)\]", dyn)
skip = {"libc.so.6", "libm.so.6", "libpthread.so.0", "libdl.so.2", "librt.so.1", "ld-linux-x86-64.so.2",
        "libgdal.so.32", "libvulkan.so.1", "libGLX.so.0", "libGLdispatch.so.0"}
seen, todo = set(), needed(binary)
while todo:
    name = todo.pop()
    if name in seen or name in skip:
        continue
    seen.add(name)
    todo += needed(paths[name])
for name in seen:
    shutil.copy(os.path.realpath(paths[name]), os.path.join(out, name))
print(f"gpu-bundle: {len(seen)} libraries")
PY
tar -C "$work" -cf - vk | xz -T0 -6 > .gpu/vkpose.tar.xz

(cd .gpu && rm -f ./*.deb && apt-get download -qq libvulkan1 libglvnd0 libglx0 libegl1 libgl1 libopengl0 libgles2) ||
  { echo "gpu-bundle: apt-get download failed: the GPU machine needs the loader packages" >&2; exit 1; }

rm -rf .gpu/data
mkdir -p .gpu/data/lmo_scene2_frame3
cp -r "$data/icbin" "$data/meshes" .gpu/data/
cp -r "$data/lmo_scene2_frame3/"{camera.json,models,test} .gpu/data/lmo_scene2_frame3/
cp scripts/gpu-run.sh .gpu/run.sh
du -sh .gpu
echo "gpu-bundle: ready; carry [\".gpu\"] and run: bash .gpu/run.sh 'vkpose info'"
