/* The blocked force loop of the elastic body (elastic_body.c calls it through
 * piola__force_block_range): F, its diagonalization, the stress, the nodal forces and the
 * per-tet state of blocks of PIOLA_TET_BLOCK tets. A kernel, compiled once per instruction
 * set (common/isa.h). Layout and determinism design are explained in
 * elastic_body_internal.h; the SVD kernel in svd_kernel.h. */
/* Fused multiply-adds in this file's kernels (see "Fused multiply-adds" in svd_kernel.h). */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("fp-contract=fast")
#endif
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "force/elastic_body_internal.h"
#include "force/fiber_lanes.h"
#include "force/force_lanes.h"
#include "force/material_lanes.h"
#include "force/stable_step.h"
#include "force/svd_kernel.h"

#define B PIOLA_TET_BLOCK

/* F = Ds Dm^-1 and det F of the B tets of one block (f[k][lane], entry k row-major). */
PIOLA_WIDE_VECTORS PIOLA_KERNEL_INLINE void block_deformation_gradients(const piola_elastic_body *body,
                                                                        const double *x, int32_t block,
                                                                        double f[9][B], double detf[B]) {
  const int32_t base = block * B;
  const int32_t *i0 = body->tet_vertices[0] + base, *i1 = body->tet_vertices[1] + base;
  const int32_t *i2 = body->tet_vertices[2] + base, *i3 = body->tet_vertices[3] + base;
  double *const *dmi = body->dm_inv;
#if defined(__AVX512F__)
  {
    /* 8-wide gathers by hand: GCC splits the gathers of the loop below into 4-wide ones
     * (int32 indices), two per coordinate; one 8-wide vgatherdpd each halves them */
    const __m256i three = _mm256_set1_epi32(3);
    __m256i ia = _mm256_mullo_epi32(_mm256_loadu_si256((const __m256i *)i0), three);
    __m256i ib = _mm256_mullo_epi32(_mm256_loadu_si256((const __m256i *)i1), three);
    __m256i ic = _mm256_mullo_epi32(_mm256_loadu_si256((const __m256i *)i2), three);
    __m256i id = _mm256_mullo_epi32(_mm256_loadu_si256((const __m256i *)i3), three);
    piola_v8d ds[3][3];
    PIOLA_UNROLL
    for (int k = 0; k < 3; ++k) {
      piola_v8d xa = (piola_v8d)_mm512_i32gather_pd(ia, x + k, 8);
      ds[k][0] = (piola_v8d)_mm512_i32gather_pd(ib, x + k, 8) - xa;
      ds[k][1] = (piola_v8d)_mm512_i32gather_pd(ic, x + k, 8) - xa;
      ds[k][2] = (piola_v8d)_mm512_i32gather_pd(id, x + k, 8) - xa;
    }
    piola_v8d m[9];
    PIOLA_UNROLL
    for (int k = 0; k < 9; ++k) m[k] = piola__v8_load(dmi[k] + base);
    piola_v8d fv[9];
    PIOLA_UNROLL
    for (int i = 0; i < 3; ++i)
      PIOLA_UNROLL
      for (int j = 0; j < 3; ++j) {
        fv[3 * i + j] = ds[i][0] * m[j] + ds[i][1] * m[3 + j] + ds[i][2] * m[6 + j];
        piola__v8_store(f[3 * i + j], fv[3 * i + j]);
      }
    piola__v8_store(detf, fv[0] * (fv[4] * fv[8] - fv[5] * fv[7]) - fv[1] * (fv[3] * fv[8] - fv[5] * fv[6]) +
                              fv[2] * (fv[3] * fv[7] - fv[4] * fv[6]));
  }
#else
#pragma omp simd
  for (int l = 0; l < B; ++l) {
    /* index arithmetic, not pointers, so GCC emits vector gathers */
    const int32_t a = 3 * i0[l], b = 3 * i1[l], c = 3 * i2[l], d = 3 * i3[l];
    double d00 = x[b] - x[a], d01 = x[c] - x[a], d02 = x[d] - x[a];
    double d10 = x[b + 1] - x[a + 1], d11 = x[c + 1] - x[a + 1], d12 = x[d + 1] - x[a + 1];
    double d20 = x[b + 2] - x[a + 2], d21 = x[c + 2] - x[a + 2], d22 = x[d + 2] - x[a + 2];
    double m00 = dmi[0][base + l], m01 = dmi[1][base + l], m02 = dmi[2][base + l];
    double m10 = dmi[3][base + l], m11 = dmi[4][base + l], m12 = dmi[5][base + l];
    double m20 = dmi[6][base + l], m21 = dmi[7][base + l], m22 = dmi[8][base + l];
    double f00 = d00 * m00 + d01 * m10 + d02 * m20, f01 = d00 * m01 + d01 * m11 + d02 * m21;
    double f02 = d00 * m02 + d01 * m12 + d02 * m22, f10 = d10 * m00 + d11 * m10 + d12 * m20;
    double f11 = d10 * m01 + d11 * m11 + d12 * m21, f12 = d10 * m02 + d11 * m12 + d12 * m22;
    double f20 = d20 * m00 + d21 * m10 + d22 * m20, f21 = d20 * m01 + d21 * m11 + d22 * m21;
    double f22 = d20 * m02 + d21 * m12 + d22 * m22;
    f[0][l] = f00; f[1][l] = f01; f[2][l] = f02;
    f[3][l] = f10; f[4][l] = f11; f[5][l] = f12;
    f[6][l] = f20; f[7][l] = f21; f[8][l] = f22;
    detf[l] = f00 * (f11 * f22 - f12 * f21) - f01 * (f10 * f22 - f12 * f20) +
              f02 * (f10 * f21 - f11 * f20);
  }

#endif
}

/* The rest of count (1 or 2) consecutive blocks once their F, U, V (in the body's arrays),
 * Fhat and stress are known: P, nodal forces added into out in tet order, per-tet state,
 * block statistics. Consecutive blocks are consecutive in every per-tet array, so the two
 * blocks of a pair are one lane loop of 2 B lanes, whose halves the compiler interleaves.
 * fhat, phat and detf hold lane l of entry i at [i * 2 B + l]. */
#define LANES (2 * B)
PIOLA_WIDE_VECTORS PIOLA_KERNEL_INLINE void finish_blocks(piola_elastic_body *body, double stiffness_scale,
                                                          int want_energy, int32_t first, int count,
                                                          const double *fhat, const double *phat,
                                                          const double *detf, double *out) {
  const int32_t base = first * B;
  const int lanes = count * B;
  double *const *dmi = body->dm_inv;
  const double *uo = body->u[0] + base, *vo = body->v[0] + base;
  const long stride = body->padded_tet_count;
  double psi[LANES];
  if (want_energy)
    for (int l = 0; l < lanes; ++l) {
      double fh[3] = {fhat[l], fhat[LANES + l], fhat[2 * LANES + l]};
      psi[l] = piola_material_energy_density(&body->materials[body->tet_material[base + l]], fh);
    }

  const double *volume = body->rest_volume + base;
  double tf[12 * LANES]; /* 12 rows (3 corner + component) of LANES lanes */
#pragma omp simd
  for (int l = 0; l < lanes; ++l) {
    double p0 = phat[l] * stiffness_scale, p1 = phat[LANES + l] * stiffness_scale,
           p2 = phat[2 * LANES + l] * stiffness_scale;
    /* P = U diag(phat) V^T */
    double pm[3][3];
    PIOLA_UNROLL
    for (int i = 0; i < 3; ++i)
      PIOLA_UNROLL
      for (int j = 0; j < 3; ++j)
        pm[i][j] = uo[3 * i * stride + l] * p0 * vo[3 * j * stride + l] +
                   uo[(3 * i + 1) * stride + l] * p1 * vo[(3 * j + 1) * stride + l] +
                   uo[(3 * i + 2) * stride + l] * p2 * vo[(3 * j + 2) * stride + l];
    /* G = P Bm = -V0 P Dm^-T: column j is the force on corner j + 1; corner 0 balances */
    double w = -volume[l];
    PIOLA_UNROLL
    for (int i = 0; i < 3; ++i) {
      double g0 = 0.0;
      PIOLA_UNROLL
      for (int j = 0; j < 3; ++j) {
        double g = w * (pm[i][0] * dmi[3 * j][base + l] + pm[i][1] * dmi[3 * j + 1][base + l] +
                        pm[i][2] * dmi[3 * j + 2][base + l]);
        tf[(3 * (j + 1) + i) * LANES + l] = g;
        g0 -= g;
      }
      tf[i * LANES + l] = g0;
    }
  }

  if (body->fiber[0]) /* muscle fibres (fiber_lanes.h), block by block */
    for (int k = 0; k < count; ++k) {
      double fh[3][B], tfk[12 * B] = {0}, psik[B] = {0};
      for (int i = 0; i < 3; ++i)
        for (int l = 0; l < B; ++l) fh[i][l] = fhat[i * LANES + k * B + l];
      PIOLA_ISA_NAME(piola__fiber_forces_lanes)(body, base + k * B, fh, stiffness_scale, tfk,
                                                want_energy ? psik : NULL);
      for (int r = 0; r < 12; ++r)
        for (int l = 0; l < B; ++l) tf[r * LANES + k * B + l] += tfk[r * B + l];
      if (want_energy)
        for (int l = 0; l < B; ++l) psi[k * B + l] += psik[l];
    }

  /* add the forces into out, tet by tet in order (padding tets are skipped) */
  int32_t real_tets = body->tet_count - base < lanes ? body->tet_count - base : lanes;
  for (int l = 0; l < real_tets; ++l)
    for (int c = 0; c < 4; ++c) {
      double *o = out + 3 * (size_t)body->tet_vertices[c][base + l];
      o[0] += tf[(3 * c) * LANES + l];
      o[1] += tf[(3 * c + 1) * LANES + l];
      o[2] += tf[(3 * c + 2) * LANES + l];
    }

  /* per-tet state for the getters (fhat AoS as the public API has it), then statistics,
   * which only a caller asking for stats needs */
  double *fhat_out = body->fhat + 3 * (size_t)base, *det_out = body->det_f + base;
#pragma omp simd
  for (int l = 0; l < lanes; ++l) {
    fhat_out[3 * l] = fhat[l];
    fhat_out[3 * l + 1] = fhat[LANES + l];
    fhat_out[3 * l + 2] = fhat[2 * LANES + l];
    det_out[l] = detf[l];
  }
  if (!want_energy) return;
  for (int k = 0; k < count; ++k) {
    const int32_t block = first + k, bbase = block * B;
    int32_t real = body->tet_count - bbase < B ? body->tet_count - bbase : B;
    double energy = 0, min_det = INFINITY;
    int32_t inverted = 0;
    for (int l = k * B; l < (k + 1) * B; ++l) {
      body->energy_density[base + l] = psi[l] * stiffness_scale;
      if (l - k * B < real) {
        energy += volume[l] * psi[l] * stiffness_scale;
        inverted += detf[l] < 0;
        min_det = fmin(min_det, detf[l]);
      }
    }
    body->block_energy[block] = energy;
    body->block_inverted[block] = inverted;
    body->block_min_det[block] = min_det;
  }
}

/* count (1 or 2) consecutive blocks from first: F of each, their SVDs (two blocks have their
 * Jacobi rotations interleaved, see piola_svd8 in svd_kernel.h; the results are the same as
 * one at a time), then the rest block by block, in order. U and V go straight into the
 * body's SoA arrays (stride padded_tet_count). */
PIOLA_WIDE_VECTORS static void update_blocks(piola_elastic_body *body, const double *x, double stiffness_scale,
                                             int want_energy, int32_t first, int count, double *out) {
  /* Fhat and the stress of both blocks side by side, [entry][2 B lanes], so that the stress
   * of the pair is one lane loop of 2 B independent lanes */
  double f[2][9][B], detf[2][B], fhat[3][2 * B], phat[3][2 * B];
  double *u = body->u[0], *v = body->v[0];
  const long stride = body->padded_tet_count;
  const int32_t base0 = first * B, base1 = (first + 1) * B;
  block_deformation_gradients(body, x, first, f[0], detf[0]);
  if (count == 2) {
    block_deformation_gradients(body, x, first + 1, f[1], detf[1]);
    piola__svd3_kernel_v8x2(&f[0][0][0], &f[1][0][0], B, u + base0, v + base0, u + base1, v + base1,
                            stride, &fhat[0][0], &fhat[0][B], 2 * B);
    piola__material_stress_lanes2(body, base0, fhat, phat);
  } else {
    piola__svd3_kernel_v8(&f[0][0][0], B, u + base0, v + base0, stride, &fhat[0][0], 2 * B);
    double fh1[3][B], ph1[3][B];
    for (int i = 0; i < 3; ++i)
      for (int l = 0; l < B; ++l) fh1[i][l] = fhat[i][l];
    piola__material_stress_lanes(body, base0, fh1, ph1);
    for (int i = 0; i < 3; ++i)
      for (int l = 0; l < B; ++l) phat[i][l] = ph1[i][l];
  }
  if (count == 2)
    finish_blocks(body, stiffness_scale, want_energy, first, 2, &fhat[0][0], &phat[0][0], &detf[0][0], out);
  else
    finish_blocks(body, stiffness_scale, want_energy, first, 1, &fhat[0][0], &phat[0][0], &detf[0][0], out);
}

#undef LANES

/* One or two consecutive blocks (the work split's unit, work_split.c). */
void PIOLA_ISA_NAME(piola__elastic_body_update_block_pair)(piola_elastic_body *body, const double *x,
                                                           double stiffness_scale, int want_energy,
                                                           int32_t first, int count, double *out) {
  update_blocks(body, x, stiffness_scale, want_energy, first, count, out);
}

/* The stress lane kernels of the blocks from first (count 1 or 2, as update_blocks pairs
 * them) on the stored Fhat, for what they write into the step bound's cache. */
PIOLA_WIDE_VECTORS static void refill_blocks(piola_elastic_body *body, int32_t first, int count) {
  double fhat[3][2 * B], phat[3][2 * B];
  const int32_t base = first * B;
  for (int l = 0; l < count * B; ++l)
    for (int i = 0; i < 3; ++i) fhat[i][l] = body->fhat[3 * (size_t)(base + l) + i];
  if (count == 2) {
    piola__material_stress_lanes2(body, base, fhat, phat);
  } else {
    double fh1[3][B], ph1[3][B];
    for (int i = 0; i < 3; ++i)
      for (int l = 0; l < B; ++l) fh1[i][l] = fhat[i][l];
    piola__material_stress_lanes(body, base, fh1, ph1);
  }
}

void PIOLA_ISA_NAME(piola__elastic_body_refill_step_cache)(piola_elastic_body *body) {
  if (!body->step_cache) return;
  ++body->step_generation; /* no block of an earlier update holds */
  if (!body->has_state) return;
  (void)PIOLA_ISA_NAME(piola__elastic_body_step_weights)(body);
  const int32_t blocks = body->padded_tet_count / B;
  if (body->split_held) { /* a local split: the blocks this process holds, one by one */
    for (int32_t b = 0; b < blocks; ++b)
      if (body->split_held[b]) refill_blocks(body, b, 1);
    return;
  }
  for (int32_t b = 0; b < blocks; b += 2) refill_blocks(body, b, blocks - b >= 2 ? 2 : 1);
}

/* Blocks [b0, b1) in pairs (the pairing depends only on b0 and b1, not on threads). */
void PIOLA_ISA_NAME(piola__force_block_range)(piola_elastic_body *body, const double *x,
                                              double stiffness_scale, int want_energy, int32_t b0,
                                              int32_t b1, double *out) {
  for (int32_t b = b0; b < b1; b += 2)
    update_blocks(body, x, stiffness_scale, want_energy, b, b1 - b >= 2 ? 2 : 1, out);
}
