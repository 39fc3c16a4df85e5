#!/usr/bin/env bash
# Installs what vkpose needs, builds it, makes `import vkpose` work in python3, and runs the demo.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release
bash scripts/install-python.sh
./build/release/vkpose demo "$@"
