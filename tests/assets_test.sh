#!/usr/bin/env bash
# assets/ matches the code: the default config is what `vkpose config --print-defaults` prints,
# and the demo's meshes are what `vkpose demo --write-meshes` writes, byte for byte (the camera
# files are read by the Assets.CameraFilesAreValidCameras test). Regenerate with
# scripts/update-assets.sh.
set -euo pipefail
vkpose="$1"; root="$2"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
status=0
"$vkpose" config --print-defaults > "$tmp/config_defaults.json"
if ! cmp -s "$tmp/config_defaults.json" "$root/assets/config_defaults.json"; then
  echo "assets/config_defaults.json differs from vkpose config --print-defaults (run scripts/update-assets.sh):"
  diff "$root/assets/config_defaults.json" "$tmp/config_defaults.json" | head -20 || true
  status=1
fi
"$vkpose" -q demo --write-meshes "$tmp/meshes"
for f in "$tmp"/meshes/*.ply; do
  name=$(basename "$f")
  if ! cmp -s "$f" "$root/assets/meshes/$name"; then
    echo "assets/meshes/$name differs from what vkpose demo --write-meshes writes (run scripts/update-assets.sh)"
    status=1
  fi
done
n_code=$(ls "$tmp"/meshes/*.ply | wc -l); n_assets=$(ls "$root"/assets/meshes/*.ply | wc -l)
if [ "$n_code" -ne "$n_assets" ]; then echo "assets/meshes holds $n_assets meshes, the code makes $n_code"; status=1; fi
[ $status -eq 0 ] && echo "assets: config_defaults.json and $n_code meshes match the code"
exit $status
