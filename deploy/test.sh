#!/usr/bin/env bash
# The whole test suite on a fresh Debian 12 machine: installs dependencies, builds (Release, with
# tests) and runs every test, runs the shared-handle client tests under ThreadSanitizer, runs every
# libFuzzer target briefly (a clang build), then builds the unit tests with AddressSanitizer +
# UndefinedBehaviorSanitizer and runs them again. This is the
# README's test command and what .ci/run calls.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=${MUFRIC_JOBS:-2}

bash deploy/install-deps.sh

echo "== Release build and full test suite"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DMUFRIC_BUILD_TESTS=ON
cmake --build build -j "$jobs"
ctest --test-dir build -j "$jobs" --output-on-failure --timeout 600

echo "== ThreadSanitizer build: one client handle shared by many threads (C ABI in-process and over gRPC, C++ stream)"
# Only the client side is instrumented; the server runs as this Release build's `mufric serve`.
cmake -S . -B build-tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMUFRIC_TSAN=ON -DMUFRIC_NATIVE=OFF \
  -DMUFRIC_BUILD_BENCH=OFF -DMUFRIC_BUILD_TESTS=ON -DMUFRIC_TEST_SERVE_BINARY="$PWD/build/app/mufric"
cmake --build build-tsan -j "$jobs" --target mufric_client_threads_tests
ctest --test-dir build-tsan -L threads --output-on-failure --timeout 600

echo "== Fuzzing: clang build with libFuzzer + ASan/UBSan, every target ${MUFRIC_FUZZ_SECONDS:-10} s, faults triaged"
CC=clang-14 CXX=clang++-14 cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMUFRIC_FUZZ=ON \
  -DMUFRIC_NATIVE=OFF -DMUFRIC_BUILD_TESTS=OFF -DMUFRIC_BUILD_BENCH=OFF
cmake --build build-fuzz -j "$jobs" --target fuzz_targets
bash tests/fuzz/run_fuzzers.sh build-fuzz build/app/mufric "${MUFRIC_FUZZ_SECONDS:-10}" build-fuzz/run

echo "== AddressSanitizer + UndefinedBehaviorSanitizer build: unit (incl. micro-solver), service and CLI tests"
# Portable code generation here: the sanitizers check correctness, and GCC 12 emits false
# uninitialised-variable warnings inside its AVX-512 intrinsics under -fsanitize.
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMUFRIC_SANITIZE=ON -DMUFRIC_NATIVE=OFF \
  -DMUFRIC_BUILD_BENCH=OFF -DMUFRIC_BUILD_TESTS=ON
cmake --build build-asan -j "$jobs" --target mufric mufric_unit_tests mufric_micro_tests mufric_service_tests mufric_cli_tests
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-asan -j "$jobs" -L "^(unit|service|cli)$" --output-on-failure --timeout 600
