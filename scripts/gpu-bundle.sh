#!/usr/bin/env bash
# Packs the vkpose CLI, every shared library it loads and the benchmark data into .gpu/, for a
# remote GPU machine that has only glibc, libstdc++ and the NVIDIA driver and cannot download
# anything (the device tool's `run`: the working tree and carried folders, 64 MiB in all).
#
#   scripts/gpu-bundle.sh --bank BANK.vkpb [--data DIR]
#
# Builds the gpu-bundle preset (libpng instead of OpenCV's imgcodecs, whose ~140 libraries
# alone are over the limit), copies the binary and its ldd closure (stripped; glibc in a folder
# of its own, used only where the remote glibc is too old), the LM-O frame, the IC-BIN frames
# and camera, and the bank; packs it all as .gpu/vkpose-gpu.tar.xz and prints the sizes.
# .gpu/vkpose-gpu/run.sh runs the CLI from the unpacked bundle.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
data="$root/../shared/data"
bank=""
while (($#)); do
  case $1 in
    --bank) bank=$2; shift 2 ;;
    --data) data=$2; shift 2 ;;
    *) echo "usage: $0 --bank BANK.vkpb [--data DIR]" >&2; exit 2 ;;
  esac
done
[[ -n $bank && -f $bank ]] || { echo "$0: --bank BANK.vkpb (an existing bank) is required" >&2; exit 2; }
[[ -f $data/lmo_scene2_frame3/test/000002/rgb/000003.png ]] || { echo "$0: no LM-O frame under $data" >&2; exit 2; }

cd "$root"
nice -n 10 cmake --preset gpu-bundle >/dev/null
nice -n 10 cmake --build --preset gpu-bundle

out=.gpu/vkpose-gpu
rm -rf .gpu
mkdir -p "$out/bin" "$out/lib" "$out/glibc" "$out/data"
cp build/gpu-bundle/vkpose "$out/bin/"
# glibc's own libraries go apart: the remote's are used unless they are older than ours.
glibc='/(ld-linux-x86-64\.so\.2|lib(c|m|dl|pthread|rt|resolv|util)\.so\.[0-9.]+)$'
ldd "$out/bin/vkpose" | awk '/=> \// {print $3} /^\t\/.*ld-linux/ {print $1}' | sort -u | while read -r lib; do
  if [[ $lib =~ $glibc ]]; then cp -L "$lib" "$out/glibc/"; else cp -L "$lib" "$out/lib/"; fi
done
if ldd "$out/bin/vkpose" | grep -q "not found"; then echo "$0: unresolved libraries" >&2; exit 1; fi
strip --strip-unneeded "$out/bin/vkpose" "$out/lib/"*

# Data: the frames bench match and bench detect read (LM-O's, IC-BIN's), and the bank.
(cd "$data" && cp -r --parents lmo_scene2_frame3/camera.json lmo_scene2_frame3/test icbin "$root/$out/data/")
chmod -R u+w "$out/data"
cp "$bank" "$out/data/bank.vkpb"

cat >"$out/run.sh" <<'EOF'
#!/bin/sh
# Runs the bundled vkpose: bundled libraries first; the bundled glibc only where the
# system's is too old for them. Vulkan: the NVIDIA ICD unless VK_DRIVER_FILES is set.
here=$(cd "$(dirname "$0")" && pwd)
nvidia_icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
if [ -z "${VK_DRIVER_FILES:-}" ] && [ -z "${VK_ICD_FILENAMES:-}" ] && [ -f "$nvidia_icd" ]; then
  export VK_DRIVER_FILES="$nvidia_icd"
fi
path="$here/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}:/usr/local/nvidia/lib64"
if LD_LIBRARY_PATH="$path" "$here/bin/vkpose" --version >/dev/null 2>&1; then
  LD_LIBRARY_PATH="$path" exec "$here/bin/vkpose" "$@"
fi
echo "run.sh: the system's glibc does not run the bundle; using the bundled one" >&2
exec "$here/glibc/ld-linux-x86-64.so.2" --library-path "$here/lib:$here/glibc:$path" "$here/bin/vkpose" "$@"
EOF
chmod +x "$out/run.sh"

echo "packing (xz -9)..."
tar -C .gpu -cf - vkpose-gpu | nice -n 10 xz -9 -T2 >.gpu/vkpose-gpu.tar.xz
rm -rf "$out"
du -sh --apparent-size .gpu/vkpose-gpu.tar.xz
echo "remote (device tool's run, carry [\".gpu\"]; with the working tree under 64 MiB): bash scripts/gpu-bench-remote.sh"
