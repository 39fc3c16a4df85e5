#!/usr/bin/env bash
# The public API is include/vkpose/: its headers include nothing but each other and outside
# libraries (never a src/ header, which users do not have), and the CLI and the example use
# nothing else of the library (the CLI also has its own cli/, the benchmarks' bench/ and the
# generic util/ helpers); the Python bindings (python/src/) use the public headers alone. Prints each offending include; exits 1 if there is one.
set -euo pipefail
root="$1"
status=0
while IFS= read -r line; do
  echo "public header includes an internal one: $line"; status=1
done < <(grep -Hn '#include "' "$root"/include/vkpose/*.hpp | grep -v '#include "vkpose/' || true)
while IFS= read -r line; do
  echo "the CLI or the example includes an internal header: $line"; status=1
done < <(grep -Hn '#include "' "$root"/src/cli/*.?pp "$root"/examples/*.cpp \
           | grep -Ev '#include "(vkpose|cli|bench|util)/' || true)
while IFS= read -r line; do
  echo "the Python bindings include an internal header: $line"; status=1
done < <(grep -Hn '#include "' "$root"/python/src/*.?pp | grep -Ev '#include "(vkpose/|arrays\.hpp")' || true)
count=$(ls "$root"/include/vkpose/*.hpp | wc -l)
echo "include/vkpose: $count public headers"
# 11: detection.hpp (what the detector finds) is apart from detector.hpp (the Detector) so that
# the pose stages fill a Detection without seeing the class that runs them. 12: picking.hpp
# (grasps, the bin, the pick list) is a concept of its own, on top of the detections.
if [ "$count" -gt 12 ]; then echo "more than 12 public headers: keep the API small (docs/api.md)"; status=1; fi
[ $status -eq 0 ] && echo "public API: ok"
exit $status
