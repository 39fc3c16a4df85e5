#!/usr/bin/env bash
# Configures, builds (warnings are errors) and runs the whole test suite with ctest, every test
# under the Vulkan validation layer (a validation error fails the test that caused it). The
# `asan` preset (AddressSanitizer + UndefinedBehaviorSanitizer) is not run here yet: see
# README.md, "Reliability", for what it still reports.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --preset release >/dev/null
cmake --build --preset release
ctest --preset release
