/* Timing of the invertible diagonalization (piola_diagonalize3, piola_diagonalize3x2).
 *
 * Usage: bench_diagonalize [matrices] [runs]      (defaults 1000000 and 7)
 *
 * Each scene is a fixed set of random deformation gradients; one run diagonalizes all of them
 * once on one thread. Printed: median and minimum ns per matrix (thread CPU time) over the
 * runs. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "piola/diagonalize.h"
#include "support/bench_support.h"

typedef struct rng {
  uint64_t s;
} rng;

static double uniform(rng *r) {
  r->s ^= r->s << 13;
  r->s ^= r->s >> 7;
  r->s ^= r->s << 17;
  return (double)((r->s * 0x2545F4914F6CDD1Dull) >> 11) * 0x1.0p-53;
}

static double normal(rng *r) {
  double u1 = fmax(uniform(r), 1e-300), u2 = uniform(r);
  return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

/* A deformed element: I + 0.3 G for most, a few percent inverted (one axis pushed through
 * zero), a few percent near flat (one direction squashed to 1e-6..1e-2). */
static piola_mat3 simulation_like(rng *r) {
  piola_mat3 f;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) f.m[i][j] = (i == j) + 0.3 * normal(r);
  double kind = uniform(r);
  if (kind < 0.04 || kind >= 0.96) {
    int axis = (int)(uniform(r) * 3) % 3;
    double factor = kind < 0.04 ? -uniform(r) : pow(10.0, -2.0 - 4.0 * uniform(r));
    for (int i = 0; i < 3; ++i) f.m[i][axis] *= factor;
  }
  return f;
}

static piola_mat3 gaussian(rng *r) {
  piola_mat3 f;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) f.m[i][j] = normal(r);
  return f;
}

typedef struct timing {
  double median_ns, min_ns;
} timing;

static timing time_runs(double *samples, int runs, long n) {
  qsort(samples, (size_t)runs, sizeof *samples, bench_compare_doubles);
  return (timing){samples[runs / 2] * 1e9 / (double)n, samples[0] * 1e9 / (double)n};
}

static timing bench3(const piola_mat3 *fs, long n, int runs, double *checksum) {
  double *t = malloc(sizeof *t * (size_t)runs);
  for (int run = 0; run < runs; ++run) {
    double start = bench_thread_cpu_seconds(), sum = 0;
    for (long k = 0; k < n; ++k) {
      piola_mat3 u, v;
      piola_vec3 d;
      piola_diagonalize3(&fs[k], &u, &d, &v);
      sum += d.z + u.m[2][2] + v.m[1][2];
    }
    t[run] = bench_thread_cpu_seconds() - start;
    *checksum += sum;
  }
  timing out = time_runs(t, runs, n);
  free(t);
  return out;
}

static timing bench3x2(const piola_mat3x2 *fs, long n, int runs, double *checksum) {
  double *t = malloc(sizeof *t * (size_t)runs);
  for (int run = 0; run < runs; ++run) {
    double start = bench_thread_cpu_seconds(), sum = 0;
    for (long k = 0; k < n; ++k) {
      piola_mat3x2 u;
      piola_mat2 v;
      double d[2];
      piola_diagonalize3x2(&fs[k], &u, d, &v);
      sum += d[1] + u.m[2][1] + v.m[1][0];
    }
    t[run] = bench_thread_cpu_seconds() - start;
    *checksum += sum;
  }
  timing out = time_runs(t, runs, n);
  free(t);
  return out;
}

int main(int argc, char **argv) {
  long n = argc > 1 ? atol(argv[1]) : 1000000;
  int runs = argc > 2 ? atoi(argv[2]) : 7;
  if (n < 1 || runs < 1) {
    fprintf(stderr, "usage: %s [matrices >= 1] [runs >= 1]\n", argv[0]);
    return 2;
  }
  rng r = {0x9E3779B97F4A7C15ull};
  piola_mat3 *sim = malloc(sizeof *sim * (size_t)n), *gau = malloc(sizeof *gau * (size_t)n);
  piola_mat3x2 *shell = malloc(sizeof *shell * (size_t)n);
  if (!sim || !gau || !shell) {
    fprintf(stderr, "out of memory\n");
    return 1;
  }
  for (long k = 0; k < n; ++k) {
    sim[k] = simulation_like(&r);
    gau[k] = gaussian(&r);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 2; ++j) shell[k].m[i][j] = (i == j) + 0.3 * normal(&r);
    if (k % 25 == 0) /* a few collapsed triangles */
      for (int i = 0; i < 3; ++i) shell[k].m[i][1] = 2.0 * shell[k].m[i][0];
  }
  double checksum = 0;
  timing a = bench3(sim, n, runs, &checksum);
  timing b = bench3(gau, n, runs, &checksum);
  timing c = bench3x2(shell, n, runs, &checksum);
  printf("%-48s %12s %12s\n", "scene (1 thread)", "median ns", "min ns");
  printf("%-48s %12.1f %12.1f\n", "diagonalize3, I+0.3G, 4% inverted, 4% near-flat", a.median_ns,
         a.min_ns);
  printf("%-48s %12.1f %12.1f\n", "diagonalize3, Gaussian entries", b.median_ns, b.min_ns);
  printf("%-48s %12.1f %12.1f\n", "diagonalize3x2, I+0.3G, 4% collapsed", c.median_ns, c.min_ns);
  printf("(%ld matrices per scene, %d runs; checksum %.6g)\n", n, runs, checksum);
  free(sim);
  free(gau);
  free(shell);
  return 0;
}
