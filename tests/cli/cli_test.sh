#!/usr/bin/env bash
# The CLI's answers to bad input, wrong usage and a machine without Vulkan: one or two lines
# on the terminal and the documented exit code (README: 1 bad input, 2 usage, 3 no device).
#   tests/cli/cli_test.sh PATH/TO/vkpose
set -u
vkpose=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
failed=0

# expect NAME CODE COMMAND...: exit code CODE and one or two lines of output.
expect() {
  local name=$1 want=$2
  shift 2
  local out code lines
  out=$("$@" 2>&1)
  code=$?
  lines=$(printf '%s' "$out" | grep -c '')
  if [ "$code" -ne "$want" ] || [ "$lines" -lt 1 ] || [ "$lines" -gt 2 ]; then
    echo "FAIL $name: exit $code (expected $want), $lines lines (expected 1 or 2):"
    printf '%s\n' "$out" | head -n 20
    failed=1
  else
    echo "ok   $name (exit $code): $out"
  fi
}

# A 5 cm cube and a small bank of it, a frame and a camera file.
cat >"$dir/cube.obj" <<'OBJ'
v -0.025 -0.025 -0.025
v 0.025 -0.025 -0.025
v 0.025 0.025 -0.025
v -0.025 0.025 -0.025
v -0.025 -0.025 0.025
v 0.025 -0.025 0.025
v 0.025 0.025 0.025
v -0.025 0.025 0.025
f 1 3 2
f 1 4 3
f 5 6 7
f 5 7 8
f 1 2 6
f 1 6 5
f 2 3 7
f 2 7 6
f 3 4 8
f 3 8 7
f 4 1 5
f 4 5 8
OBJ
if ! "$vkpose" -q train "$dir/cube.obj" --units m --views 2 --radii 0.6 --inplane 0 --out "$dir/cube.vkpb" >"$dir/train.log" 2>&1; then
  echo "FAIL: training the cube's bank failed:"
  cat "$dir/train.log"
  exit 1
fi
# The whole turn near the poles: a nonsense angle is refused before any work, no bank written.
"$vkpose" -q train "$dir/cube.obj" --units m --views 2 --radii 0.6 --inplane 0 --full-turn-within 95 \
  --out "$dir/turn.vkpb" >"$dir/turn.log" 2>&1
rc=$?
if [ $rc -ne 1 ] || [ -e "$dir/turn.vkpb" ] || ! grep -q "full-turn-within '95'" "$dir/turn.log"; then
  echo "FAIL train: --full-turn-within 95 is refused (exit $rc):"
  cat "$dir/turn.log"
  failed=1
else
  echo "ok   train: $(head -c 160 "$dir/turn.log")"
fi
# A part too small for LINEMOD's coarse level at its distance (16 pixels, 1 cell): refused with
# exit 1 and what to do, no bank written; with --allow-small a warning says so before the
# training (which may then find too few features in every view: either exit is fine there).
"$vkpose" -q train "$dir/cube.obj" --units m --views 2 --radii 3 --inplane 0 --out "$dir/far.vkpb" >"$dir/far.log" 2>&1
rc=$?
if [ $rc -ne 1 ] || [ -e "$dir/far.vkpb" ] || ! grep -q "allow-small" "$dir/far.log"; then
  echo "FAIL train: a part 16 pixels across is refused (exit $rc):"
  cat "$dir/far.log"
  failed=1
else
  echo "ok   train: too small is refused: $(head -c 160 "$dir/far.log")"
fi
"$vkpose" -q train "$dir/cube.obj" --units m --views 2 --radii 3 --inplane 0 --allow-small --out "$dir/far.vkpb" >"$dir/far.log" 2>&1
if ! grep -q "cells of LINEMOD's coarsest level" "$dir/far.log"; then
  echo "FAIL train: a part 16 pixels across, allowed, warns:"
  cat "$dir/far.log"
  failed=1
else
  echo "ok   train: allowed, too small to match well: $(grep warning "$dir/far.log")"
fi
if grep -q "cells of LINEMOD" "$dir/train.log"; then
  echo "FAIL train: the cube at 0.6 m (82 pixels) warns:"
  cat "$dir/train.log"
  failed=1
fi
python3 - "$dir" <<'PY' 2>/dev/null || printf '\x89PNG' >"$dir/rgb.png"
import sys, zlib, struct
def png(path, w, h, bits, colour_type, row):
    raw = b''.join(b'\x00' + row for _ in range(h))
    def chunk(t, d): return struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d))
    ihdr = struct.pack('>IIBBBBB', w, h, bits, colour_type, 0, 0, 0)
    open(path, 'wb').write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', ihdr) + chunk(b'IDAT', zlib.compress(raw)) + chunk(b'IEND', b''))
d = sys.argv[1]
png(d + '/rgb.png', 64, 48, 8, 2, bytes([40, 80, 120]) * 64)
png(d + '/depth.png', 64, 48, 16, 0, struct.pack('>H', 700) * 64)
PY
echo '{"fx": 572.4, "fy": 573.6, "cx": 32, "cy": 24}' >"$dir/camera.json"
frame=(--rgb "$dir/rgb.png" --depth "$dir/depth.png" --camera "$dir/camera.json")

expect "detect: the frame works" 0 "$vkpose" -q detect --bank "$dir/cube.vkpb" "${frame[@]}" --no-pose
expect "detect: -q after the subcommand" 0 "$vkpose" detect --bank "$dir/cube.vkpb" "${frame[@]}" --no-pose -q
expect "detect: missing bank file" 1 "$vkpose" detect --bank "$dir/absent.vkpb" "${frame[@]}"
expect "detect: missing depth image" 1 "$vkpose" detect --bank "$dir/cube.vkpb" --rgb "$dir/rgb.png" \
  --depth "$dir/absent.png" --camera "$dir/camera.json"
# Colour only: the same frame without its depth image (a uniform image: nothing found, exit 0).
expect "detect: a frame without depth (colour only)" 0 "$vkpose" -q detect --bank "$dir/cube.vkpb" --rgb "$dir/rgb.png" \
  --camera "$dir/camera.json"
expect "detect: grasps need depth" 1 "$vkpose" -q detect --bank "$dir/cube.vkpb" --rgb "$dir/rgb.png" \
  --camera "$dir/camera.json" --grasps "$dir/absent.grasps.json"
# Grasp files: one for another object, one with a direction that is not unit length.
echo '{"object": "mug", "grasps": [{"name": "top", "position_mm": [0, 0, 25], "approach": [0, 0, -1], "opening_mm": 60}]}' \
  >"$dir/mug.grasps.json"
echo '{"object": "cube", "grasps": [{"name": "top", "position_mm": [0, 0, 25], "approach": [0, 0, -2], "opening_mm": 60}]}' \
  >"$dir/long.grasps.json"
echo '{"object": "cube", "grasps": [{"name": "top", "position_mm": [0, NaN, 25], "approach": [0, 0, -1]}]}' \
  >"$dir/nan.grasps.json"
expect "detect: grasps of an object no bank is for" 1 "$vkpose" -q detect --bank "$dir/cube.vkpb" "${frame[@]}" \
  --grasps "$dir/mug.grasps.json"
expect "detect: a grasp approach that is not unit length" 1 "$vkpose" -q detect --bank "$dir/cube.vkpb" "${frame[@]}" \
  --grasps "$dir/long.grasps.json"
expect "detect: a grasp file with NaN" 1 "$vkpose" -q detect --bank "$dir/cube.vkpb" "${frame[@]}" \
  --grasps "$dir/nan.grasps.json"
# Picking flags without --grasps would do nothing: a usage error.
expect "detect: --max-tilt without --grasps" 2 "$vkpose" -q detect --bank "$dir/cube.vkpb" "${frame[@]}" --max-tilt 30
expect "detect: --min-outline-fit without --grasps" 2 "$vkpose" -q detect --bank "$dir/cube.vkpb" "${frame[@]}" \
  --min-outline-fit 0.3
expect "eval: --min-colour-fit without --grasps" 2 "$vkpose" -q eval --dataset "$dir" --bank 1="$dir/cube.vkpb" \
  --min-colour-fit 0.3
# Sequences: a folder of frames (rgb/ and depth/) and a list file, one detector for all frames.
mkdir -p "$dir/seq/rgb" "$dir/seq/depth"
for n in 000000 000001; do cp "$dir/rgb.png" "$dir/seq/rgb/$n.png"; cp "$dir/depth.png" "$dir/seq/depth/$n.png"; done
expect "detect: a folder of frames" 0 "$vkpose" -q detect --bank "$dir/cube.vkpb" --frames "$dir/seq" \
  --camera "$dir/camera.json" --out-dir "$dir/seq_out" --no-pose
for n in 000000 000001; do
  [ -s "$dir/seq_out/$n.json" ] || { echo "FAIL detect --frames wrote no $n.json"; failed=1; }
done
printf '# colour depth\nseq/rgb/000000.png seq/depth/000000.png\nseq/rgb/000001.png seq/depth/absent.png\n' >"$dir/frames.txt"
expect "detect: a list with a missing depth image" 1 "$vkpose" -q detect --bank "$dir/cube.vkpb" --list "$dir/frames.txt" \
  --camera "$dir/camera.json" --jsonl "$dir/frames.jsonl" --no-pose
[ "$(grep -c '' "$dir/frames.jsonl")" -eq 2 ] || { echo "FAIL detect --list: expected a JSON line per frame"; failed=1; }
expect "detect: sequence outputs exist" 1 "$vkpose" -q detect --bank "$dir/cube.vkpb" --frames "$dir/seq" \
  --camera "$dir/camera.json" --out-dir "$dir/seq_out" --no-pose
expect "detect: a sequence without --out-dir or --jsonl" 1 "$vkpose" detect --bank "$dir/cube.vkpb" --frames "$dir/seq" \
  --camera "$dir/camera.json"
expect "detect: neither a frame nor a sequence" 2 "$vkpose" detect --bank "$dir/cube.vkpb" --camera "$dir/camera.json"
expect "detect: a frame and a sequence" 2 "$vkpose" detect --bank "$dir/cube.vkpb" "${frame[@]}" --frames "$dir/seq"
expect "detect: wrong flag" 2 "$vkpose" detect --bank "$dir/cube.vkpb" "${frame[@]}" --no-such-flag
# A stage flag's range is the parameter table's, the same as the config file's.
expect "detect: a flag outside its range" 2 "$vkpose" detect --bank "$dir/cube.vkpb" "${frame[@]}" --threshold 0
printf '{"match": {"threshold": 0}}' >"$dir/zero_threshold.json"
expect "detect: a config value outside its range" 1 "$vkpose" detect --bank "$dir/cube.vkpb" "${frame[@]}" \
  --config "$dir/zero_threshold.json"
expect "detect: an unknown sensor" 1 "$vkpose" detect --bank "$dir/cube.vkpb" "${frame[@]}" --sensor kinnect
expect "detect: a sensor profile" 0 "$vkpose" -q detect --bank "$dir/cube.vkpb" "${frame[@]}" --no-pose --sensor ideal
expect "detect: no Vulkan driver" 3 env VK_ICD_FILENAMES=/nonexistent/icd.json VK_DRIVER_FILES=/nonexistent/icd.json \
  "$vkpose" detect --bank "$dir/cube.vkpb" "${frame[@]}"
# Regression: an error in a subcommand that runs inside parsing (bench train) was uncaught
# and aborted the program.
touch "$dir/exists.json"
expect "bench train: existing --json" 1 "$vkpose" bench train --json "$dir/exists.json"
exit $failed
