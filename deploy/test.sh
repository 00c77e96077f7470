#!/usr/bin/env bash
# mufric's test command (the README's, and what .ci/run calls) on a fresh Debian 12 machine.
#
#   bash deploy/test.sh          the whole suite, ~29 min on 2 cores:
#       dependencies; a Release build (unity) and every test but the long ones (unit, micro-solver,
#       service, CLI, client, examples, container image around this build's executable); a
#       ThreadSanitizer build of the shared-handle client tests; one clang build with ASan + UBSan +
#       libFuzzer coverage that runs every fuzz target and then the unit, service and CLI tests.
#   bash deploy/test.sh --long   the long verification studies (CTest label "long": the Westergaard
#       and Challen-Oxley studies, the container image compiled from source), ~11 min after the build.
#       Run them before resolving a physics issue.
#
# Each stage's time is printed at the end, also when a stage fails
# (bench/studies/test_time/README.md, "The test
# command's time", records them). Environment: MUFRIC_JOBS (parallel jobs, default 2),
# MUFRIC_FUZZ_SECONDS (seconds per fuzz target, default 10).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=${MUFRIC_JOBS:-2}
fuzz_seconds=${MUFRIC_FUZZ_SECONDS:-10}
mode=all
case "${1:-}" in
  "") ;;
  --long) mode=long ;;
  -h|--help) sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
  *) echo "deploy/test.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
esac

# Stage timer: `stage NAME` closes the running stage and opens the next; the table prints on exit.
stage_names=() stage_seconds=() current_stage="" stage_started=0
close_stage() {
  [[ -n $current_stage ]] || return 0
  stage_names+=("$current_stage")
  stage_seconds+=($((SECONDS - stage_started)))
  current_stage=""
}
stage() {
  close_stage
  current_stage=$1 stage_started=$SECONDS
  echo "== $1"
}
print_stage_times() {
  local rc=$? failed=$current_stage i
  close_stage
  echo
  echo "== Stage times ($(nproc) cores, MUFRIC_JOBS=$jobs)"
  for i in "${!stage_names[@]}"; do
    printf '%6d s  %s%s\n' "${stage_seconds[$i]}" "${stage_names[$i]}" \
      "$([[ ${stage_names[$i]} == "$failed" && $rc != 0 ]] && echo '   <- FAILED')"
  done
  printf '%6d s  total (%s)\n' "$SECONDS" "$([[ $rc == 0 ]] && echo passed || echo "failed, exit $rc")"
  exit "$rc"
}
trap print_stage_times EXIT

stage "dependencies (deploy/install-deps.sh)"
bash deploy/install-deps.sh

# Unity build: each library and test executable compiles as a few large translation units, which
# parses Eigen's and gRPC's headers once per unit instead of once per file (-35 % CPU here).
stage "Release build"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DMUFRIC_BUILD_TESTS=ON -DCMAKE_UNITY_BUILD=ON >/dev/null
cmake --build build -j "$jobs"

if [[ $mode == long ]]; then
  stage "long verification studies (ctest -L long)"
  ctest --test-dir build -L long -j "$jobs" --output-on-failure --timeout 1800
  exit 0
fi

stage "Release tests (ctest -LE long)"
ctest --test-dir build -LE long -j "$jobs" --output-on-failure --timeout 900

# Only the client side is instrumented; the server runs as the Release build's `mufric serve`.
stage "ThreadSanitizer build: one client handle shared by many threads"
cmake -S . -B build-tsan -G Ninja -DCMAKE_BUILD_TYPE=Check -DCMAKE_UNITY_BUILD=ON -DMUFRIC_TSAN=ON \
  -DMUFRIC_NATIVE=OFF -DMUFRIC_BUILD_BENCH=OFF -DMUFRIC_BUILD_TESTS=ON \
  -DMUFRIC_TEST_SERVE_BINARY="$PWD/build/app/mufric" >/dev/null
cmake --build build-tsan -j "$jobs" --target mufric_client_threads_tests
stage "ThreadSanitizer tests (ctest -L threads)"
ctest --test-dir build-tsan -L threads --output-on-failure --timeout 600

# One clang build serves both the fuzz targets and the sanitizer run of the suite: every library is
# compiled once with ASan + UBSan and libFuzzer's coverage (which costs the tests ~3 %).
stage "ASan + UBSan + libFuzzer build (clang, build type Check)"
CC=clang-14 CXX=clang++-14 cmake -S . -B build-check -G Ninja -DCMAKE_BUILD_TYPE=Check -DCMAKE_UNITY_BUILD=ON \
  -DMUFRIC_FUZZ=ON -DMUFRIC_SANITIZE=ON -DMUFRIC_NATIVE=OFF -DMUFRIC_BUILD_BENCH=OFF -DMUFRIC_BUILD_TESTS=ON >/dev/null
cmake --build build-check -j "$jobs" --target fuzz_targets mufric mufric_unit_tests mufric_micro_tests \
  mufric_service_tests mufric_cli_tests

stage "fuzzing: every target ${fuzz_seconds} s, faults triaged"
MUFRIC_JOBS=$jobs bash tests/fuzz/run_fuzzers.sh build-check build/app/mufric "$fuzz_seconds" build-check/fuzz-run

stage "ASan + UBSan tests: unit (incl. micro-solver), service and CLI"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-check -j "$jobs" -L "^(unit|service|cli)$" --output-on-failure --timeout 900
