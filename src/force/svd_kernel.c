/* The vectorized SVD kernel over a batch of matrices (for benchmarks and accuracy tests;
 * the force loop inlines piola__svd3_kernel_v8 directly): a kernel, compiled once per
 * instruction set (common/isa.h). */
/* Fused multiply-adds in this file's kernels (see "Fused multiply-adds" in svd_kernel.h). */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("fp-contract=fast")
#endif
#include "force/svd_kernel.h"

#define BATCH_LANES 8

PIOLA_WIDE_VECTORS void PIOLA_ISA_NAME(piola__svd3_kernel_batch)(int32_t n, const double *f, double *u, double *fhat, double *v) {
  /* two blocks at a time through the interleaved kernel, as the force loop does */
  for (int32_t base = 0; base < n; base += 2 * BATCH_LANES) {
    int32_t lanes = n - base < 2 * BATCH_LANES ? n - base : 2 * BATCH_LANES;
    double fl[2][9][BATCH_LANES], ul[2][9][BATCH_LANES], vl[2][9][BATCH_LANES], sl[2][3][BATCH_LANES];
    for (int b = 0; b < 2; ++b)
      for (int k = 0; k < 9; ++k)
        for (int l = 0; l < BATCH_LANES; ++l) {
          int32_t i = b * BATCH_LANES + l;
          fl[b][k][l] = i < lanes ? f[9 * (base + i) + k] : 0.0;
        }
    if (lanes > BATCH_LANES)
      piola__svd3_kernel_v8x2(&fl[0][0][0], &fl[1][0][0], BATCH_LANES, &ul[0][0][0], &vl[0][0][0],
                              &ul[1][0][0], &vl[1][0][0], BATCH_LANES, &sl[0][0][0], &sl[1][0][0],
                              BATCH_LANES);
    else
      piola__svd3_kernel_v8(&fl[0][0][0], BATCH_LANES, &ul[0][0][0], &vl[0][0][0], BATCH_LANES,
                            &sl[0][0][0], BATCH_LANES);
    for (int32_t i = 0; i < lanes; ++i) {
      int b = i / BATCH_LANES, l = i % BATCH_LANES;
      for (int k = 0; k < 9; ++k) {
        u[9 * (base + i) + k] = ul[b][k][l];
        v[9 * (base + i) + k] = vl[b][k][l];
      }
      for (int k = 0; k < 3; ++k) fhat[3 * (base + i) + k] = sl[b][k][l];
    }
  }
}
