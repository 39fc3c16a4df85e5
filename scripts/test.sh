#!/usr/bin/env bash
# Configures, builds (warnings are errors) and runs the whole test suite with ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --preset release >/dev/null
cmake --build --preset release
ctest --preset release
