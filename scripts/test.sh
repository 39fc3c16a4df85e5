#!/usr/bin/env bash
# Configures, builds (warnings are errors) and runs the whole test suite with ctest, every test
# under the Vulkan validation layer (a validation error fails the test that caused it); then
# the `asan` preset (AddressSanitizer + UndefinedBehaviorSanitizer) builds and runs the tests
# of the CPU stages, the file readers and the CLI (docs/reliability.md).
set -euo pipefail
cd "$(dirname "$0")/.."
# In CI the real frames are always there: a test that would skip for want of them fails instead.
if [ "${CI:-}" = true ]; then export VKPOSE_REQUIRE_DATA=1; fi
cmake --preset release >/dev/null
cmake --build --preset release
ctest --preset release
cmake --preset asan >/dev/null
cmake --build --preset asan
ctest --preset asan
