/* The projected stiffness blocks of PIOLA_TET_BLOCK tets at once (stiffness_lanes.h).
 *
 * The material's part, dPhat/dFhat made semi-definite, goes tet by tet through
 * piola__tet_diagonal_stiffness (any model, no copy of the models here), except that for a
 * body of one material whose block has no entry of Fhat below the threshold, the model's
 * Phat and dPhat/dFhat (material_kernels.h's parts, what piola__material_stress_and_derivative
 * takes there) run in a lane loop with the model a constant, which vectorizes; the
 * projection then stays per tet. The six corner-pair blocks
 * -V0 U M_ab U^T, most of the arithmetic, run in one loop over the lanes that vectorizes.
 * The loop repeats piola__tet_stiffness_blocks's operations in its order and this file
 * fuses no multiply-adds, so each lane gives that function's bits. */
#include <string.h>

#include "force/element_stiffness.h"
#include "force/stiffness_lanes.h"
#include "force/stiffness_matrix.h"
#include "force/svd_kernel.h"
#include "material/material_kernels.h"

#define B PIOLA_TET_BLOCK

static const int PAIR_A[6] = {0, 0, 0, 1, 1, 2}, PAIR_B[6] = {1, 2, 3, 2, 3, 3};

/* The parts of MODEL (a constant) at the lanes' Fhat: phat[i][l], dphat[3 i + j][l]. */
#define PARTS_LANES(MODEL)                                                                     \
  do {                                                                                         \
    _Pragma("omp simd") for (int l = 0; l < B; ++l) {                                          \
      material_parts pa;                                                                       \
      material_model_parts(MODEL, m, KERNEL_EXACT_DIVIDE, fhat[3 * l], fhat[3 * l + 1],        \
                           fhat[3 * l + 2], &pa);                                              \
      PIOLA_UNROLL for (int i = 0; i < 3; ++i) phat[i][l] = pa.p[i];                           \
      PIOLA_UNROLL for (int e = 0; e < 9; ++e) dphat[e][l] = pa.k[e / 3][e % 3];               \
    }                                                                                          \
  } while (0)

/* Phat and dPhat/dFhat of the block's tets from one lane loop, the values (and bits) of
 * piola__material_stress_and_derivative; 0 (nothing written) where that takes the public
 * path for some lane: a body of several materials, an entry below the threshold. */
static int material_parts_lanes(const piola_elastic_body *body, int32_t base, double phat[3][B],
                                double dphat[9][B]) {
  if (body->uniform_material < 0) return 0;
  const piola_material *m = &body->materials[body->uniform_material];
  const double *fhat = body->fhat + 3 * (size_t)base, c = material_threshold_largest(m);
  int unclamped = 1;
  for (int e = 0; e < 3 * B; ++e) unclamped &= fhat[e] >= c;
  if (!unclamped) return 0;
  switch (piola__stress_parts_model(m->model)) {
    case PIOLA_MODEL_ROTATED_LINEAR: PARTS_LANES(PIOLA_MODEL_ROTATED_LINEAR); return 1;
    case PIOLA_MODEL_COROTATED: PARTS_LANES(PIOLA_MODEL_COROTATED); return 1;
    case PIOLA_MODEL_STVK: PARTS_LANES(PIOLA_MODEL_STVK); return 1;
    case PIOLA_MODEL_NEOHOOKEAN: PARTS_LANES(PIOLA_MODEL_NEOHOOKEAN); return 1;
    case PIOLA_MODEL_SPLINE: PARTS_LANES(PIOLA_MODEL_SPLINE); return 1;
    case PIOLA_MODEL_STABLE_NEOHOOKEAN: PARTS_LANES(PIOLA_MODEL_STABLE_NEOHOOKEAN); return 1;
    case PIOLA_MODEL_OGDEN: PARTS_LANES(PIOLA_MODEL_OGDEN); return 1;
    case PIOLA_MODEL_HGO: PARTS_LANES(PIOLA_MODEL_HGO); return 1;
    default: return 0;
  }
}

PIOLA_WIDE_VECTORS void PIOLA_ISA_NAME(piola__stiffness_block_lanes)(const piola_elastic_body *body, int32_t block,
                                                  double out[54][B]) {
  const int32_t base = block * B;
  double kd[9][B], ka[3][B], kb[3][B], phat[3][B], dphat[9][B];
  const int parts = material_parts_lanes(body, base, phat, dphat);
  const int project = piola__stiffness_projection(body);
  for (int l = 0; l < B; ++l) {
    piola__diagonal_stiffness k;
    if (parts) {
      const double *fhat = body->fhat + 3 * (size_t)(base + l);
      const double p[3] = {phat[0][l], phat[1][l], phat[2][l]};
      for (int e = 0; e < 9; ++e) k.block[e / 3][e % 3] = dphat[e][l];
      piola__diagonal_stiffness_from(fhat, p, project, &k);
    } else {
      piola__tet_diagonal_stiffness(body, base + l, &k);
    }
    for (int e = 0; e < 9; ++e) kd[e][l] = k.block[e / 3][e % 3];
    for (int p = 0; p < 3; ++p) ka[p][l] = k.pair_a[p], kb[p][l] = k.pair_b[p];
  }
  const double *u0 = body->u[0] + base, *v0 = body->v[0] + base;
  const size_t stride = (size_t)body->padded_tet_count;
  const double *const d0 = body->dm_inv[0] + base, *const d1 = body->dm_inv[1] + base;
  const double *const d2 = body->dm_inv[2] + base, *const d3 = body->dm_inv[3] + base;
  const double *const d4 = body->dm_inv[4] + base, *const d5 = body->dm_inv[5] + base;
  const double *const d6 = body->dm_inv[6] + base, *const d7 = body->dm_inv[7] + base;
  const double *const d8 = body->dm_inv[8] + base, *const volume = body->rest_volume + base;
  const double stiffness_scale = body->last_stiffness_scale;
#pragma omp simd
  for (int l = 0; l < B; ++l) {
    double u[3][3], v[3][3];
    PIOLA_UNROLL
    for (int k = 0; k < 9; ++k) {
      u[k / 3][k % 3] = u0[k * stride + l];
      v[k / 3][k % 3] = v0[k * stride + l];
    }
    const double dm[3][3] = {{d0[l], d1[l], d2[l]}, {d3[l], d4[l], d5[l]}, {d6[l], d7[l], d8[l]}};
    double g[4][3], gh[4][3];
    PIOLA_UNROLL
    for (int j = 0; j < 3; ++j) {
      g[0][j] = -(dm[0][j] + dm[1][j] + dm[2][j]);
      PIOLA_UNROLL
      for (int a = 1; a < 4; ++a) g[a][j] = dm[a - 1][j];
    }
    PIOLA_UNROLL
    for (int a = 0; a < 4; ++a)
      PIOLA_UNROLL
      for (int p = 0; p < 3; ++p)
        gh[a][p] = v[0][p] * g[a][0] + v[1][p] * g[a][1] + v[2][p] * g[a][2];
    const double scale = -volume[l] * stiffness_scale;
    PIOLA_UNROLL
    for (int n = 0; n < 6; ++n) {
      const int a = PAIR_A[n], b = PAIR_B[n];
      /* M_ab as piola__tet_stiffness_blocks builds it: pair (p, q) of the diagonal frame is
       * 2x2 block k = p + q - 1 */
      double mm[3][3];
      PIOLA_UNROLL
      for (int p = 0; p < 3; ++p) {
        double diag = gh[a][p] * gh[b][p] * kd[4 * p][l];
        PIOLA_UNROLL
        for (int q = 0; q < 3; ++q)
          if (q != p) {
            const int pr = p + q - 1;
            diag += gh[a][q] * gh[b][q] * ka[pr][l];
            mm[p][q] = gh[a][p] * gh[b][q] * kd[3 * p + q][l] + gh[a][q] * gh[b][p] * kb[pr][l];
          }
        mm[p][p] = diag;
      }
      double um[3][3];
      PIOLA_UNROLL
      for (int i = 0; i < 3; ++i)
        PIOLA_UNROLL
        for (int q = 0; q < 3; ++q)
          um[i][q] = u[i][0] * mm[0][q] + u[i][1] * mm[1][q] + u[i][2] * mm[2][q];
      PIOLA_UNROLL
      for (int i = 0; i < 3; ++i)
        PIOLA_UNROLL
        for (int j = 0; j < 3; ++j) {
          out[9 * n + 3 * i + j][l] =
              scale * (um[i][0] * u[j][0] + um[i][1] * u[j][1] + um[i][2] * u[j][2]);
        }
    }
  }
}
