#include "support/bench_support.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli/allocator_policy.h"

static double seconds_of(clockid_t clock) {
  struct timespec ts;
  clock_gettime(clock, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void bench_allocator(int *argc, char **argv) {
  int keep_defaults = 0, n = 1;
  for (int i = 1; i < *argc; ++i)
    if (strcmp(argv[i], "--default-allocator") == 0)
      keep_defaults = 1;
    else
      argv[n++] = argv[i];
  *argc = n;
  if (!keep_defaults) piola_cli_keep_freed_memory();
  printf("allocator: %s\n",
         keep_defaults ? "the C library's defaults" : "freed memory kept, as piola run does");
}

double bench_wall_seconds(void) { return seconds_of(CLOCK_MONOTONIC); }

double bench_cpu_seconds(void) { return seconds_of(CLOCK_PROCESS_CPUTIME_ID); }

double bench_thread_cpu_seconds(void) { return seconds_of(CLOCK_THREAD_CPUTIME_ID); }

int bench_compare_doubles(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

double bench_median(double *v, int n) {
  qsort(v, (size_t)n, sizeof *v, bench_compare_doubles);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;

void bench_seed(uint64_t seed) {
  /* xorshift's zero state is a fixed point: every seed maps to a non-zero one */
  rng_state = 0x9E3779B97F4A7C15ull ^ (seed * 0xD1B54A32D192ED03ull);
  if (!rng_state) rng_state = 0x9E3779B97F4A7C15ull;
}

double bench_uniform(double lo, double hi) {
  rng_state ^= rng_state << 13;
  rng_state ^= rng_state >> 7;
  rng_state ^= rng_state << 17;
  return lo + (hi - lo) * (double)(rng_state >> 11) * 0x1.0p-53;
}

piola_material_def bench_rows_material_def(piola_material_model model) {
  piola_material_def def = piola_default_material_def();
  def.model = model;
  def.inversion_mode = PIOLA_INVERSION_LINEAR;
  def.inversion_threshold = 0.3;
  return def;
}
