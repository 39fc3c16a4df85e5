#!/bin/bash
# On the GPU machine, from the bundle scripts/gpu-bundle.sh made (copied there as .gpu/run.sh):
#   bash .gpu/run.sh 'CMD' ['CMD' ...]
# Unpacks the bundle once, puts the Vulkan/glvnd loaders in place (dpkg -x into /, ldconfig),
# points the loader at the NVIDIA driver, and runs each quoted CMD in /tmp with `vkpose` the
# bundled binary and $D the bundled data; what a CMD writes under $OUT comes back. Banks a CMD
# names are trained first (each once): /tmp/cup.vkpb (the IC-BIN cup, IC-BIN's camera) and
# /tmp/obj_0000NN.vkpb (the LM-O objects, LM-O's camera, radii 0.9-1.3 m as the LM-O test).
set -u
g=$(cd "$(dirname "$0")" && pwd)
T0=$SECONDS
if [ ! -x /tmp/vk/vkpose ]; then
  tar -C /tmp -xJf "$g/vkpose.tar.xz"
  for f in "$g"/*.deb; do dpkg -x "$f" /; done
  ldconfig
fi
export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json}
export LD_LIBRARY_PATH=/tmp/vk/lib D=$g/data PATH=/tmp/vk:$PATH
nvidia-smi -L 2>/dev/null
vkpose info | grep -qi nvidia || { VK_LOADER_DEBUG=error,warn vkpose info; echo "gpu-run: no NVIDIA Vulkan device"; exit 3; }
train() { [ -f "$2" ] || vkpose -q train "$1" --units "$3" --camera "$4" ${5:-} --out "$2"; }
for c in "$@"; do
  case "$c" in *"/tmp/cup.vkpb"*) train "$D/meshes/coffee_cup.stl" /tmp/cup.vkpb m "$D/icbin/camera.json" ;; esac
  for m in "$D"/lmo_scene2_frame3/models/obj_*.ply; do
    n=$(basename "$m" .ply)
    case "$c" in *"/tmp/$n.vkpb"*)
      train "$m" "/tmp/$n.vkpb" mm "$D/lmo_scene2_frame3/camera.json" "--radii 0.9:1.3:0.1" ;;
    esac
  done
  echo "== [$((SECONDS - T0)) s] $c"
  (cd /tmp && eval "$c") 2>&1
done
echo "== [$((SECONDS - T0)) s] done"
