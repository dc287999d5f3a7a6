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

# cpu_now: sets cpu to the user+sys seconds of this shell's finished children so far, from
# bash's `times` (run in this shell: a subshell would count only its own children)
times_file=$(mktemp); trap 'rm -f "$times_file"' EXIT
cpu_now() {
  times > "$times_file"
  cpu=$(awk 'NR == 2 { for (i = 1; i <= 2; i++) { split($i, t, "m"); s += t[1] * 60 + t[2] } }
             END { printf "%.0f", s }' "$times_file")
}
# phase NAME COMMAND...: runs the command and prints its wall and CPU seconds for the CI log
phase() {
  local name=$1; shift
  local wall0=$SECONDS cpu0
  cpu_now; cpu0=$cpu
  "$@"
  cpu_now
  echo "== $name: $((SECONDS - wall0)) s wall, $((cpu - cpu0)) s CPU (user+sys)"
}

echo "== test build (warnings are errors)"
cmake -S . -B build/test -DCMAKE_BUILD_TYPE=Release -DPIOLA_WERROR=ON >/dev/null
phase "test build" cmake --build build/test -j "$jobs"
phase "tests" ctest --test-dir build/test --output-on-failure -j "$jobs"

echo "== sanitizer build (AddressSanitizer + UndefinedBehaviorSanitizer)"
cmake -S . -B build/sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPIOLA_WERROR=ON \
  -DPIOLA_SANITIZE=ON -DPIOLA_BUILD_BENCH=OFF >/dev/null
# only what the unit label runs (the test programs and the CLI), with the kernels as baseline
# and AVX-512 only (CMakeLists.txt: AVX2 is the baseline's source; the test build has all three)
phase "sanitizer build" cmake --build build/sanitize -j "$jobs" --target piola_unit_tests
# Heavy property tests read PIOLA_TEST_SCALE to run fewer samples under the sanitizers.
phase "sanitizer tests" env PIOLA_TEST_SCALE=0.05 ASAN_OPTIONS=detect_leaks=1 \
  UBSAN_OPTIONS=print_stacktrace=1 ctest --test-dir build/sanitize --output-on-failure \
  -j "$jobs" -L unit

if ls fuzz/fuzz_*.c >/dev/null 2>&1; then
  echo "== fuzzing each parser for ${fuzz_seconds}s (libFuzzer + ASan + UBSan)"
  CC=clang cmake -S . -B build/fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPIOLA_BUILD_FUZZ=ON \
    -DPIOLA_BUILD_TESTS=OFF -DPIOLA_BUILD_BENCH=OFF >/dev/null
  # the fuzzers and the core library they link, nothing else
  phase "fuzz build" cmake --build build/fuzz -j "$jobs" --target piola_fuzzers
  # one fuzzer per core at a time, each for the full time
  phase "fuzzing" bash scripts/run-fuzzers.sh build/fuzz "$fuzz_seconds" "$jobs"
fi
echo "== all tests passed"
