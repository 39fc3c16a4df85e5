#!/usr/bin/env bash
# Builds the libFuzzer targets of the file readers (preset `fuzz`, clang) and runs each for a
# bounded time over its seed corpus in tests/fuzz_corpus/<target>/, then prints the inputs
# tried per target (libFuzzer's "Done N runs"). A crash leaves its input in
# build/fuzz/artifacts/ and makes this script exit 1.
#   scripts/fuzz.sh [SECONDS_PER_TARGET (default 60)] [TARGET ...]
set -uo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(bank camera scene_gt scene_gt_info scene_camera models_info tejani_poses bop_results mesh config)
fi

cmake --preset fuzz >/dev/null || exit 1
cmake --build --preset fuzz || exit 1

out=build/fuzz
# Leaks inside third-party libraries (assimp) are suppressed, never ours (tests/lsan.supp).
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0"
mkdir -p "$out/artifacts" "$out/logs"
status=0
summary=()
for t in "${targets[@]}"; do
  corpus="$out/corpus/$t"  # grows as libFuzzer finds new coverage; the seeds stay as they are
  mkdir -p "$corpus"
  log="$out/logs/$t.log"
  echo "fuzz: $t for ${seconds}s"
  "$out/fuzz/fuzz_$t" "$corpus" "tests/fuzz_corpus/$t" -max_total_time="$seconds" -timeout=10 \
    -rss_limit_mb=2048 -malloc_limit_mb=1024 -max_len=65536 -print_final_stats=1 \
    -artifact_prefix="$out/artifacts/$t-" >"$log" 2>&1
  rc=$?
  runs=$(grep -o 'Done [0-9]* runs in [0-9]* second' "$log" | tail -1)
  if [ $rc -ne 0 ]; then
    status=1
    artifact=$(grep -o "Test unit written to [^ ]*" "$log" | tail -1 | cut -d' ' -f5)
    summary+=("$(printf '%-14s CRASH (exit %d) after %s runs: %s, log %s' "$t" "$rc" \
      "$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$')" "${artifact:-?}" "$log")")
  else
    summary+=("$(printf '%-14s %s' "$t" "${runs:-no 'Done' line, see $log}")")
  fi
done
echo
echo "fuzz summary (${seconds}s per target):"
printf '  %s\n' "${summary[@]}"
exit $status
