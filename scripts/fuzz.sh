#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (+ AddressSanitizer and UBSan) and runs
# each for SECONDS (default 60), starting from the seed corpora in fuzz/corpus.
# A crash, leak, sanitizer report or uncaught exception fails the script.
# Usage: scripts/fuzz.sh [SECONDS] [BUILD_DIR]
set -euo pipefail
seconds=${1:-60}
build=${2:-build-fuzz}
cd "$(dirname "$0")/.."
targets=(fuzz_imu_file fuzz_truth fuzz_truth_text fuzz_config fuzz_mcap fuzz_ros1 fuzz_table)
# A build directory configured for fuzzing already (scripts/sanitize-test.sh's, with the tests)
# is used as it is: only the targets' own sources are left to build.
if ! grep -q '^WHEELINS_FUZZ:BOOL=ON' "$build/CMakeCache.txt" 2>/dev/null; then
  # -O1 -g1 (line tables), as the sanitizer suite (libFuzzer's documentation builds its
  # targets at -O1 or -O2).
  generator=()
  [ -f "$build/CMakeCache.txt" ] || generator=(-G Ninja)
  CXX=clang++ cmake -S . -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DWHEELINS_FUZZ=ON -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
    -DWHEELINS_BUILD_TESTS=OFF -DWHEELINS_BUILD_BENCH=OFF > /dev/null
fi
cmake --build "$build" -j"$(nproc)" --target "${targets[@]}"
for target in imu_file truth truth_text config mcap ros1 table; do
  corpus_seed="fuzz/corpus/${target%_file}"
  work="$build/corpus-$target"
  mkdir -p "$work"
  echo "== fuzz_$target for ${seconds} s"
  # A ROS 1 bag holds its message definitions twice (in the chunk and the index): 32 KiB.
  max_len=4096
  [ "$target" = ros1 ] && max_len=32768
  "$build/fuzz_$target" -max_total_time="$seconds" -print_final_stats=1 -max_len=$max_len \
    -artifact_prefix="$build/crash-$target-" "$work" "$corpus_seed" 2>&1 |
    grep -E "stat::number_of_executed_units|stat::new_units_added|ERROR|SUMMARY|Done" || true
  if ls "$build"/crash-"$target"-* > /dev/null 2>&1; then
    echo "fuzz_$target: crash artifacts in $build" >&2
    exit 1
  fi
done
