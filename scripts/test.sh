#!/usr/bin/env bash
# The whole test suite: a warnings-as-errors build with every test, the unit tests again
# under AddressSanitizer + UndefinedBehaviorSanitizer, and a short libFuzzer run of every
# parser over seeds from ../shared/data. Exits non-zero if anything fails.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)
fuzz_seconds=${PIOLA_FUZZ_SECONDS:-20}
# the MPI tests (tests/mpi, docs/mpi.md) run mpirun, which refuses root without these
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# ctest runs two tests at once, each with OpenMP threads: idle threads that spin (libgomp's
# default) would take the core from the other test. The piola CLI sets this itself
# (docs/cli.md); the test programs link the library directly, so the suite sets it here.
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}

echo "== test build (warnings are errors)"
cmake -S . -B build/test -DCMAKE_BUILD_TYPE=Release -DPIOLA_WERROR=ON >/dev/null
cmake --build build/test -j "$jobs"
(cd build/test && ctest --output-on-failure -j "$jobs")

echo "== sanitizer build (AddressSanitizer + UndefinedBehaviorSanitizer)"
cmake -S . -B build/sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPIOLA_WERROR=ON \
  -DPIOLA_SANITIZE=ON -DPIOLA_BUILD_BENCH=OFF >/dev/null
cmake --build build/sanitize -j "$jobs"
# Heavy property tests read PIOLA_TEST_SCALE to run fewer samples under the sanitizers.
(cd build/sanitize && PIOLA_TEST_SCALE=0.05 ASAN_OPTIONS=detect_leaks=1 \
  UBSAN_OPTIONS=print_stacktrace=1 ctest --output-on-failure -j "$jobs" -L unit)

if ls fuzz/fuzz_*.c >/dev/null 2>&1; then
  echo "== fuzzing each parser for ${fuzz_seconds}s (libFuzzer + ASan + UBSan)"
  CC=clang cmake -S . -B build/fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPIOLA_BUILD_FUZZ=ON \
    -DPIOLA_BUILD_TESTS=OFF -DPIOLA_BUILD_BENCH=OFF >/dev/null
  cmake --build build/fuzz -j "$jobs"
  bash scripts/run-fuzzers.sh build/fuzz "$fuzz_seconds"
fi
echo "== all tests passed"
