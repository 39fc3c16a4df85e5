#!/usr/bin/env bash
# assets/ matches the code: the default config is what `vkpose config --print-defaults` prints,
# and the demo's meshes and the parts are what `vkpose demo --write-meshes` and `--write-parts`
# write, byte for byte (the camera files are read by the Assets.CameraFilesAreValidCameras test).
# Regenerate with scripts/update-assets.sh.
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
"$vkpose" -q demo --write-parts "$tmp/parts"
for kind in meshes parts; do
  for f in "$tmp/$kind"/*.ply; do
    name=$(basename "$f")
    if ! cmp -s "$f" "$root/assets/$kind/$name"; then
      echo "assets/$kind/$name differs from what vkpose demo --write-$kind writes (run scripts/update-assets.sh)"
      status=1
    fi
  done
  n_code=$(ls "$tmp/$kind"/*.ply | wc -l); n_assets=$(ls "$root/assets/$kind"/*.ply | wc -l)
  if [ "$n_code" -ne "$n_assets" ]; then echo "assets/$kind holds $n_assets meshes, the code makes $n_code"; status=1; fi
done
[ $status -eq 0 ] && echo "assets: config_defaults.json, the demo's meshes and the parts match the code"
exit $status
