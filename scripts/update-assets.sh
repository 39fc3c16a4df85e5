#!/usr/bin/env bash
# Regenerates what assets/ holds that the code defines: the default stage parameters
# (assets/config_defaults.json, `vkpose config --print-defaults`) and the demo's three objects as
# PLY in millimetres (assets/meshes/, `vkpose demo --write-meshes`), and four small metal parts for
# synthetic piles (assets/parts/, `vkpose demo --write-parts`). The camera files and the demo
# picture are written by hand. tests/assets_test.sh (ctest: Assets.MatchTheCode) fails when the
# files here no longer match the code: run this script and commit the result.
#   bash scripts/update-assets.sh [PATH/TO/vkpose]   (default: build/release/vkpose)
set -euo pipefail
cd "$(dirname "$0")/.."
vkpose="${1:-build/release/vkpose}"
[ -x "$vkpose" ] || { echo "update-assets: no $vkpose; build first (cmake --preset release && cmake --build --preset release)" >&2; exit 1; }
"$vkpose" config --print-defaults > assets/config_defaults.json
"$vkpose" -q demo --write-meshes assets/meshes --force
"$vkpose" -q demo --write-parts assets/parts --force
echo "update-assets: wrote assets/config_defaults.json, assets/meshes/ and assets/parts/"
