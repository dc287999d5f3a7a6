/* The vectorized SVD kernel over a batch of matrices (for benchmarks and accuracy tests;
 * the force loop inlines piola__svd3_kernel directly). */
#include "force/svd_kernel.h"

#define BATCH_LANES 8

PIOLA_WIDE_VECTORS void piola__svd3_kernel_batch(int32_t n, const double *f, double *u, double *fhat, double *v) {
  int32_t full = n - n % BATCH_LANES;
  for (int32_t base = 0; base < full; base += BATCH_LANES) {
    double fl[9][BATCH_LANES], ul[9][BATCH_LANES], vl[9][BATCH_LANES], sl[3][BATCH_LANES];
    for (int k = 0; k < 9; ++k)
      for (int l = 0; l < BATCH_LANES; ++l) fl[k][l] = f[9 * (base + l) + k];
#pragma omp simd
    for (int l = 0; l < BATCH_LANES; ++l)
      piola__svd3_kernel(&fl[0][l], BATCH_LANES, &ul[0][l], &vl[0][l], BATCH_LANES, &sl[0][l],
                         BATCH_LANES);
    for (int l = 0; l < BATCH_LANES; ++l) {
      for (int k = 0; k < 9; ++k) {
        u[9 * (base + l) + k] = ul[k][l];
        v[9 * (base + l) + k] = vl[k][l];
      }
      for (int k = 0; k < 3; ++k) fhat[3 * (base + l) + k] = sl[k][l];
    }
  }
  for (int32_t t = full; t < n; ++t)
    piola__svd3_kernel(f + 9 * t, 1, u + 9 * t, v + 9 * t, 1, fhat + 3 * t, 1);
}
