#!/usr/bin/env bash
# Reliability checks of issue #7 (docs/RELIABILITY.md), run by .ci/run after scripts/test.sh:
#   1. clang, AddressSanitizer + UndefinedBehaviorSanitizer (+ LeakSanitizer): build everything
#      (with the libFuzzer targets) and run the whole ctest suite;
#   2. libFuzzer: each fuzz target for FUZZ_SECONDS (default 60) from the seed corpus;
#   3. ThreadSanitizer: the concurrency tests, of the queries and of the builds on threads;
#   4. valgrind memcheck on pcd_collision over data/ (the Release build of scripts/test.sh).
# Build directories: ${BUILD_PREFIX}asan and ${BUILD_PREFIX}tsan, BUILD_PREFIX=build- by default
# (never build/, which step 4 only reads; PCD_COLLISION_EXE names another pcd_collision).
# Each step builds only what it runs: no benchmarks, no evaluation, and the TSan tree only the
# seven programs holding the concurrency tests. Budget (issue #7): sanitizer and fuzz steps within
# 15 minutes on 2 cores; measured times are in docs/RELIABILITY.md.
# Usage: bash scripts/ci-reliability.sh [all | asan|fuzz|tsan|valgrind ...]   (default: all, in order)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
jobs=${JOBS:-2}
fuzz_seconds=${FUZZ_SECONDS:-60}
asan_dir=${BUILD_PREFIX:-build-}asan
tsan_dir=${BUILD_PREFIX:-build-}tsan
steps=("$@")
[ ${#steps[@]} -gt 0 ] && [ "${steps[*]}" != all ] || steps=(asan fuzz tsan valgrind)

bash scripts/install-ci-extras.sh

declare -a timings=()
all_start=$SECONDS
timed () {
  local name=$1; shift
  local start=$SECONDS
  echo "=== ci-reliability: $name"
  "$@"
  timings+=("$name: $((SECONDS - start)) s")
  echo "=== ci-reliability: $name done in $((SECONDS - start)) s"
}

# -O1 keeps the instrumented build and its tests affordable on 2 cores.
sanitized_configure () {  # dir sanitizers extra-args...
  local dir=$1 san=$2; shift 2
  CC=clang CXX=clang++ cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g" "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O1 -g" \
    -DPCL_PROBCOLLISION_SANITIZE="$san" -DPCL_PROBCOLLISION_BUILD_BENCHMARKS=OFF \
    -DPCL_PROBCOLLISION_BUILD_EVALUATION=OFF "$@"
}

# The whole suite (tools, examples and their tests) plus the fuzzers, one tree.
asan_build () {
  sanitized_configure "$asan_dir" address,undefined -DPCL_PROBCOLLISION_BUILD_FUZZERS=ON
  cmake --build "$asan_dir" -j"$jobs"
}
asan_test () {
  # Left out here, run by scripts/test.sh: downstream_find_package installs the library and
  # links a plain, uninstrumented consumer against it: a packaging test, meaningless with an
  # instrumented static library.
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir "$asan_dir" --output-on-failure -j"$jobs" -E '^downstream_find_package$' --timeout 1500
}

fuzz_one () {  # target corpus-name [more input directories...]
  local target=$1 corpus=$2; shift 2
  local work="$asan_dir/fuzz/run-$corpus"
  rm -rf "$work"; mkdir -p "$work/corpus" "$work/artifacts"
  # New inputs go to the first (scratch) directory; the repository's seeds stay as they are.
  if ! ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
      "$asan_dir/fuzz/$target" -max_total_time="$fuzz_seconds" -timeout=30 -rss_limit_mb=4096 \
      -print_final_stats=1 -artifact_prefix="$work/artifacts/" \
      "$work/corpus" "fuzz/corpus/$corpus" "$@" > "$work/log.txt" 2>&1; then
    tail -n 80 "$work/log.txt"
    echo "ci-reliability: $target found a failure; reproduce with: $asan_dir/fuzz/$target $work/artifacts/*" >&2
    ls -l "$work/artifacts" >&2
    return 1
  fi
  grep -E '^stat::number_of_executed_units|^stat::new_units_added|^stat::peak_rss_mb' "$work/log.txt" || true
}
fuzz_all () {
  [ -x "$asan_dir/fuzz/fuzz_collide" ] && [ -x "$asan_dir/fuzz/fuzz_mesh_file" ] || asan_build
  # Each fuzzer is single-threaded: run the two side by side, one per core.
  fuzz_one fuzz_collide collide fuzz/regressions &  # regressions replayed first, like the seeds
  local collide=$!
  fuzz_one fuzz_cli_options cli &
  local cli=$! rc=0
  wait "$collide" || rc=1
  wait "$cli" || rc=1
  fuzz_one fuzz_mesh_file mesh || rc=1  # the mesh readers (OBJ, PLY header check, legacy VTK)
  return "$rc"
}

tsan_options="halt_on_error=1:second_deadlock_stack=1:suppressions=$root/test/tools/tsan.supp"
tsan_build () {
  # gtest_discover_tests runs the instrumented tests at build time: they need the options too.
  export TSAN_OPTIONS="$tsan_options"
  sanitized_configure "$tsan_dir" thread -DPCL_PROBCOLLISION_BUILD_EXAMPLES=OFF
  cmake --build "$tsan_dir" -j"$jobs" --target test_collide test_bvh_traversal test_robust_classifier \
    test_probabilistic_collision test_covariance_estimation test_probabilistic_bvh test_cloud_model
}
tsan_test () {
  # The queries' threads run only our code (collide(), collideBatch() with and without its
  # in-order handover, computeBatch(), classify(), the traversal) on hierarchies built before
  # they start; the builds' threads run ours and FLANN's (header-only, so instrumented too).
  # test/tools/tsan.supp holds the one suppression (libOpenNI2's static initializer).
  export TSAN_OPTIONS="$tsan_options"
  "$tsan_dir/test/test_collide" --gtest_filter='*Concurrent*:CollideBatch.Streamed*:CollideBatch.AnExceptionFromReady*'
  "$tsan_dir/test/test_bvh_traversal" --gtest_filter='*Threads*'
  "$tsan_dir/test/test_robust_classifier" --gtest_filter='*Concurrent*'
  "$tsan_dir/test/test_probabilistic_collision" --gtest_filter='*Concurrent*'
  # The builds on threads: the covariance estimation (its side thread beside FLANN's tree
  # build), the hierarchy's parts, and a whole model with the merged one built beside.
  "$tsan_dir/test/test_covariance_estimation" --gtest_filter='*Thread*:*Afresh*'
  "$tsan_dir/test/test_probabilistic_bvh" --gtest_filter='*ThreadCount*:*Packed*'
  "$tsan_dir/test/test_cloud_model" --gtest_filter='*ThreadCount*:*IndependentOfThreads*'
}

valgrind_cli () {
  local exe=${PCD_COLLISION_EXE:-build/tools/pcd_collision}  # built by scripts/test.sh
  [ -x "$exe" ] || { cmake -S . -B build -DCMAKE_BUILD_TYPE=Release && cmake --build build -j"$jobs" --target pcd_collision; }
  local out; out=$(mktemp -d)
  local vg=(valgrind --tool=memcheck --error-exitcode=99 --leak-check=full --errors-for-leak-kinds=definite
            --show-leak-kinds=definite --track-origins=no --suppressions="$root/test/tools/valgrind.supp" -q)
  "${vg[@]}" "$exe" data/gripper.obj data/table_mug.pcd -poses data/demo_poses.txt -json > "$out/batch.json"
  "${vg[@]}" "$exe" data/gripper.obj data/table_mug.pcd -pose -0.15,0.05,-0.02,0,0,0 -o "$out/result.pcd"
  "${vg[@]}" "$exe" data/gripper.obj data/table_mug.pcd -sensor kinect -pose 0,0,0.005,0,0,0 > /dev/null
  # Error paths too: exit 1 or 2, but still no memory error (99).
  local rc=0
  "${vg[@]}" "$exe" data/gripper.obj data/missing.pcd 2> /dev/null || rc=$?
  [ "$rc" -ne 99 ] || { echo "valgrind: memory errors on the error path" >&2; return 1; }
  rc=0
  "${vg[@]}" "$exe" data/gripper.obj data/table_mug.pcd -sigma 1O 2> /dev/null || rc=$?
  [ "$rc" -ne 99 ] || { echo "valgrind: memory errors on the usage-error path" >&2; return 1; }
  [ "$(wc -l < "$out/batch.json")" -eq 3 ] || { echo "valgrind run: expected 3 JSON lines" >&2; return 1; }
  rm -rf "$out"
}

for s in "${steps[@]}"; do
  case "$s" in
    asan) timed "asan+ubsan build" asan_build; timed "asan+ubsan ctest" asan_test ;;
    fuzz) timed "fuzz (${fuzz_seconds} s each)" fuzz_all ;;
    tsan) timed "tsan build" tsan_build; timed "tsan tests" tsan_test ;;
    valgrind) timed "valgrind pcd_collision" valgrind_cli ;;
    *) echo "ci-reliability: unknown step '$s' (asan, fuzz, tsan, valgrind)" >&2; exit 2 ;;
  esac
done
echo "=== ci-reliability: summary"
printf '  %s\n' "${timings[@]}"
echo "  total: $((SECONDS - all_start)) s"
