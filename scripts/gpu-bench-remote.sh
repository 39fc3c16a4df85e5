#!/usr/bin/env bash
# On the remote GPU machine (the device tool's `run`, with `.gpu` carried): unpacks the bundle
# made by scripts/gpu-bundle.sh and runs `vkpose info`, `bench match` and
# `bench detect --no-pose`, writing their output and JSON to $OUT (or ./gpu-out).
#   bash scripts/gpu-bench-remote.sh [extra arguments of bench match]
# DETECT_ARGS (environment) adds arguments to bench detect.
set -uo pipefail

out=${OUT:-gpu-out}
mkdir -p "$out" /tmp/vkpose-bundle
cd "$(dirname "$0")/.." || exit 1
tar -xJf .gpu/vkpose-gpu.tar.xz -C /tmp/vkpose-bundle 2>/dev/null ||
  python3 -m tarfile -e .gpu/vkpose-gpu.tar.xz /tmp/vkpose-bundle || exit 1
b=/tmp/vkpose-bundle/vkpose-gpu
frame=$b/data/lmo_scene2_frame3/test/000002

"$b/run.sh" info 2>&1 | tee "$out/info.txt"
echo "== bench match"
"$b/run.sh" -q bench match --rgb "$frame/rgb/000003.png" --depth "$frame/depth/000003.png" \
  --json "$out/match.json" "$@" 2>&1 | tee "$out/match.txt"
echo "== bench detect --no-pose"
# shellcheck disable=SC2086
"$b/run.sh" -q bench detect --bank "$b/data/bank.vkpb" --data "$b/data" --no-pose \
  --json "$out/detect.json" ${DETECT_ARGS:-} 2>&1 | tee "$out/detect.txt"
