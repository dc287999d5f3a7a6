/* The vectorized SVD kernel over a batch of matrices (for benchmarks and accuracy tests;
 * the force loop inlines piola__svd3_kernel_v8 directly). */
/* Fused multiply-adds in this file's kernels (see "Fused multiply-adds" in svd_kernel.h). */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("fp-contract=fast")
#endif
#include "force/svd_kernel.h"

#define BATCH_LANES 8

PIOLA_WIDE_VECTORS void piola__svd3_kernel_batch(int32_t n, const double *f, double *u, double *fhat, double *v) {
  for (int32_t base = 0; base < n; base += BATCH_LANES) {
    int32_t lanes = n - base < BATCH_LANES ? n - base : BATCH_LANES;
    double fl[9][BATCH_LANES], ul[9][BATCH_LANES], vl[9][BATCH_LANES], sl[3][BATCH_LANES];
    for (int k = 0; k < 9; ++k)
      for (int l = 0; l < BATCH_LANES; ++l) fl[k][l] = l < lanes ? f[9 * (base + l) + k] : 0.0;
    piola__svd3_kernel_v8(&fl[0][0], BATCH_LANES, &ul[0][0], &vl[0][0], BATCH_LANES, &sl[0][0],
                          BATCH_LANES);
    for (int l = 0; l < lanes; ++l) {
      for (int k = 0; k < 9; ++k) {
        u[9 * (base + l) + k] = ul[k][l];
        v[9 * (base + l) + k] = vl[k][l];
      }
      for (int k = 0; k < 3; ++k) fhat[3 * (base + l) + k] = sl[k][l];
    }
  }
}
