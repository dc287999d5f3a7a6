/* Cost of the diagonal stress Phat(Fhat) per evaluation, for each model: through the public
 * function (one call per tet) and through the inline per-model kernel in a `#pragma omp simd`
 * loop over a block (how the force loop uses it). 10% of the samples lie below the inversion
 * threshold, some inverted. Prints the bench_median of 9 runs in ns per evaluation.
 *
 *   build/NAME/bench_material [count]      (default 65536 tets per run) */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "material/material_kernels.h"
#include "piola/material.h"
#include "support/bench_support.h"

static void simd_block(const piola_material *m, long n, const double *restrict f0,
                       const double *restrict f1, const double *restrict f2, double *restrict p0,
                       double *restrict p1, double *restrict p2) {
  switch (m->model) { /* the switch is hoisted: one simd loop per model */
#define PIOLA_BENCH_LOOP(fn)                                \
  {                                                         \
    _Pragma("omp simd") for (long i = 0; i < n; ++i)        \
        fn(m, f0[i], f1[i], f2[i], &p0[i], &p1[i], &p2[i]); \
  }                                                         \
  break;
    case PIOLA_MODEL_ROTATED_LINEAR:
      PIOLA_BENCH_LOOP(rotated_linear_stress)
    case PIOLA_MODEL_COROTATED:
      PIOLA_BENCH_LOOP(corotated_stress)
    case PIOLA_MODEL_STVK:
      PIOLA_BENCH_LOOP(stvk_stress)
    case PIOLA_MODEL_NEOHOOKEAN:
      PIOLA_BENCH_LOOP(neohookean_stress)
    case PIOLA_MODEL_SPLINE:
      PIOLA_BENCH_LOOP(spline_stress)
    case PIOLA_MODEL_STABLE_NEOHOOKEAN:
      PIOLA_BENCH_LOOP(stable_neohookean_stress)
    default:
      break;
#undef PIOLA_BENCH_LOOP
  }
}

static void simd_block_energy(const piola_material *m, long n, const double *restrict f0,
                              const double *restrict f1, const double *restrict f2,
                              double *restrict p0, double *restrict p1, double *restrict p2,
                              double *restrict psi) {
  switch (m->model) {
#define PIOLA_BENCH_LOOP(fn)                                         \
  {                                                                  \
    _Pragma("omp simd") for (long i = 0; i < n; ++i)                 \
        fn(m, f0[i], f1[i], f2[i], &p0[i], &p1[i], &p2[i], &psi[i]); \
  }                                                                  \
  break;
    case PIOLA_MODEL_ROTATED_LINEAR:
      PIOLA_BENCH_LOOP(rotated_linear_stress_energy)
    case PIOLA_MODEL_COROTATED:
      PIOLA_BENCH_LOOP(corotated_stress_energy)
    case PIOLA_MODEL_STVK:
      PIOLA_BENCH_LOOP(stvk_stress_energy)
    case PIOLA_MODEL_NEOHOOKEAN:
      PIOLA_BENCH_LOOP(neohookean_stress_energy)
    case PIOLA_MODEL_SPLINE:
      PIOLA_BENCH_LOOP(spline_stress_energy)
    case PIOLA_MODEL_STABLE_NEOHOOKEAN:
      PIOLA_BENCH_LOOP(stable_neohookean_stress_energy)
    default:
      break;
#undef PIOLA_BENCH_LOOP
  }
}

int main(int argc, char **argv) {
  const long n = argc > 1 ? atol(argv[1]) : 65536;
  if (n <= 0) return 1;
  double *buf = malloc(sizeof(double) * 7 * (size_t)n);
  if (!buf) return 1;
  double *f0 = buf, *f1 = buf + n, *f2 = buf + 2 * n, *p0 = buf + 3 * n, *p1 = buf + 4 * n,
         *p2 = buf + 5 * n, *psi = buf + 6 * n;
  unsigned long long state = 88172645463325252ull;
  for (long i = 0; i < 3 * n; ++i) {
    state ^= state << 13, state ^= state >> 7, state ^= state << 17;
    const double u = (double)(state >> 11) / 9007199254740992.0;
    buf[i] = (i % 10 == 0) ? -0.5 + 0.7 * u : 0.6 + 0.9 * u;
  }
  enum { RUNS = 9 };
  printf(
      "| model | public stress | simd stress | public stress + energy | simd stress + energy |\n");
  printf("|---|---|---|---|---|\n");
  double sink = 0;
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model) {
    piola_material_def def = bench_rows_material_def((piola_material_model)model);
    piola_material m;
    if (piola_material_init(&def, &m) != PIOLA_OK) return 1;
    double t_pub[RUNS], t_simd[RUNS], t_pub_e[RUNS], t_simd_e[RUNS];
    for (int r = 0; r < RUNS; ++r) {
      double t = bench_wall_seconds();
      for (long i = 0; i < n; ++i) {
        const double f[3] = {f0[i], f1[i], f2[i]};
        double p[3];
        piola_material_stress(&m, f, p);
        p0[i] = p[0], p1[i] = p[1], p2[i] = p[2];
      }
      t_pub[r] = (bench_wall_seconds() - t) / (double)n * 1e9;
      sink += p0[n / 2];
      t = bench_wall_seconds();
      simd_block(&m, n, f0, f1, f2, p0, p1, p2);
      t_simd[r] = (bench_wall_seconds() - t) / (double)n * 1e9;
      sink += p1[n / 3];
      t = bench_wall_seconds();
      for (long i = 0; i < n; ++i) {
        const double f[3] = {f0[i], f1[i], f2[i]};
        double p[3];
        piola_material_stress(&m, f, p);
        psi[i] = piola_material_energy_density(&m, f);
        p0[i] = p[0], p1[i] = p[1], p2[i] = p[2];
      }
      t_pub_e[r] = (bench_wall_seconds() - t) / (double)n * 1e9;
      sink += psi[n / 2];
      t = bench_wall_seconds();
      simd_block_energy(&m, n, f0, f1, f2, p0, p1, p2, psi);
      t_simd_e[r] = (bench_wall_seconds() - t) / (double)n * 1e9;
      sink += psi[n / 3];
    }
    printf("| %s | %.1f | %.1f | %.1f | %.1f |\n", piola_material_model_name(m.model),
           bench_median(t_pub, RUNS), bench_median(t_simd, RUNS), bench_median(t_pub_e, RUNS),
           bench_median(t_simd_e, RUNS));
  }
  fprintf(stderr, "(checksum %g)\n", sink);
  free(buf);
  return 0;
}
