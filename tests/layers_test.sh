#!/usr/bin/env bash
# The layers of src/ and the one direction they may include each other in (docs/pipeline.md,
# layout of the source). A folder may include its own floor and the floors below it, never one
# above: the GPU layer knows no stage, training knows no pose stage, the pose stages know no
# Detector, the Detector knows no file format or CLI. The public headers (include/vkpose/)
# are everyone's. Prints each include that runs up; exits 1 if there is one.
#   tests/layers_test.sh ROOT
set -euo pipefail
root="$1"
# floor of each folder of src/, lowest first
declare -A floor=(
  [util]=0
  [gpu]=1 [geometry]=1 [config]=1
  [match]=2 [render]=2
  [training]=3
  [hypotheses]=4
  [pose]=5
  [pipeline]=6
  [io]=7
  [eval]=8 [pick]=8
  [synth]=9
  [cli]=10 [python]=10 [bench]=10
)
status=0
checked=0
for dir in "$root"/src/*/; do
  layer=$(basename "$dir")
  if [ -z "${floor[$layer]+x}" ]; then
    echo "src/$layer/ has no floor in tests/layers_test.sh: give it one"
    status=1
    continue
  fi
  while IFS= read -r line; do
    file=${line%%:*}
    target=$(sed -E 's/.*#include "([a-z_]+)\/.*/\1/' <<<"$line")
    [ "$target" = vkpose ] && continue
    checked=$((checked + 1))
    if [ -z "${floor[$target]+x}" ]; then
      echo "${file#"$root"/}: includes $target/, a folder with no floor"
      status=1
    elif [ "${floor[$target]}" -gt "${floor[$layer]}" ]; then
      echo "${file#"$root"/}: $layer (floor ${floor[$layer]}) includes $target (floor ${floor[$target]}): a lower layer includes a higher one"
      status=1
    fi
  done < <(grep -Hn '#include "[a-z_]*/' "$dir"*.?pp 2>/dev/null || true)
done
# The CMake targets: each layer's vkpose_layer(...) in CMakeLists.txt may link only layers of
# its floor and below.
links=0
while IFS= read -r entry; do
  layer=${entry%%:*}
  for dep in ${entry#*:}; do
    target=${dep#vkpose_}
    [ "$target" = "$dep" ] && continue   # a library from outside (Vulkan::Vulkan, ...)
    [ "$target" = shaders ] && continue  # the embedded SPIR-V, below every layer
    links=$((links + 1))
    if [ -z "${floor[$target]+x}" ] || [ -z "${floor[$layer]+x}" ]; then
      echo "CMakeLists.txt: vkpose_$layer links vkpose_$target, a layer with no floor"
      status=1
    elif [ "${floor[$target]}" -gt "${floor[$layer]}" ]; then
      echo "CMakeLists.txt: vkpose_$layer (floor ${floor[$layer]}) links vkpose_$target (floor ${floor[$target]})"
      status=1
    fi
  done
done < <(awk '/^vkpose_layer\(/ { name = substr($1, 14); inl = 1; next }
              inl && /^ *(LINK|PRIVATE_LINK) / { line = $0; sub(/^ *(PRIVATE_)?LINK /, "", line); sub(/\)$/, "", line);
                                                 print name ":" line }
              inl && /\)$/ { inl = 0 }' "$root/CMakeLists.txt")
[ "$links" -gt 0 ] || { echo "CMakeLists.txt: no vkpose_layer() links found"; status=1; }
echo "src/: $checked includes between folders checked, $links links between layer targets"
[ $status -eq 0 ] && echo "layers: ok"
exit $status
