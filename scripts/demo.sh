#!/usr/bin/env bash
# Installs what vkpose needs, builds it and runs the demo.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release
./build/release/vkpose demo "$@"
