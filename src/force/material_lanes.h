/* Stress and energy density for the PIOLA_TET_BLOCK tets of one block, from their Fhat.
 *
 * The models live in the materials module (one source of truth, src/material/
 * material_kernels.h); this adapter only decides how to call them for a block. When every
 * tet of the body uses one material, the switch on the model is hoisted out of the lane
 * loop and the per-model kernel is inlined into an `omp simd` loop, which vectorizes. A block
 * that mixes materials goes lane by lane through the run-time dispatch.
 *
 * The energy density is not on the hot path: it goes through the public
 * piola_material_energy_density, lane by lane, and only when the caller asks for it (stats,
 * or the per-tet energy getter). */
#ifndef PIOLA_FORCE_MATERIAL_LANES_H
#define PIOLA_FORCE_MATERIAL_LANES_H

#include <stdlib.h>

#include "force/elastic_body_internal.h"
#include "force/stable_step_modulus.h"
#include "force/svd_kernel.h"
#include "material/material_kernels.h"
#include "piola/material.h"

/* One lane loop over the constant COUNT lanes from lane FIRST, with KERNEL. */
#define PIOLA_NEOHOOKEAN_RUN(kernel, first, count)                                         \
  do {                                                                                     \
    _Pragma("omp simd") for (int l = 0; l < (count); ++l)                                  \
        kernel(m, fhat[0][(first) + l], fhat[1][(first) + l], fhat[2][(first) + l],        \
               &phat[0][(first) + l], &phat[1][(first) + l], &phat[2][(first) + l]);       \
  } while (0)

/* The same, KERNEL also writing each lane's step-bound modulus k into k_ (in scope). */
#define PIOLA_STEP_CACHED_RUN(kernel, first, count)                                        \
  do {                                                                                     \
    _Pragma("omp simd") for (int l = 0; l < (count); ++l)                                  \
        kernel(m, fhat[0][(first) + l], fhat[1][(first) + l], fhat[2][(first) + l],        \
               &phat[0][(first) + l], &phat[1][(first) + l], &phat[2][(first) + l],        \
               k_ + (first) + l);                                                          \
  } while (0)

/* The step bound's cache (stable_step_modulus.h) of the LANES / PIOLA_TET_BLOCK blocks from
 * tet BASE, from their lanes' k (NaN where an entry is clamped): per block the maxima of
 * w_e k_e below and above the stiff modulus, under the update's generation. A block with a
 * clamped lane or a padding tet, or a body without its weights yet, is marked not formed. */
PIOLA_KERNEL_INLINE void piola__step_cache_blocks(const piola_elastic_body *body, const piola_material *m,
                                                  int32_t base, const double *k, int lanes) {
  const double *w = body->step_weight;
  const double stiff = STEP_CACHE_STIFF * (m->lambda + 2.0 * m->mu);
  for (int j = 0; j < lanes / PIOLA_TET_BLOCK; ++j) {
    const int32_t first = base + j * PIOLA_TET_BLOCK;
    double *slot = body->step_cache + (size_t)(first / PIOLA_TET_BLOCK) * STEP_CACHE_SLOTS;
    if (!w || first + PIOLA_TET_BLOCK > body->tet_count) {
      slot[STEP_CACHE_KEY] = 0.0;
      continue;
    }
    const double *kj = k + j * PIOLA_TET_BLOCK, *wj = w + first;
    double low = 0, high = 0;
    int formed = 1;
#pragma omp simd reduction(max:low) reduction(max:high) reduction(&:formed)
    for (int l = 0; l < PIOLA_TET_BLOCK; ++l) {
      const double r = wj[l] * kj[l];
      const int above = kj[l] > stiff;
      formed &= kj[l] == kj[l];
      low = !above && r > low ? r : low;
      high = above && r > high ? r : high;
    }
    slot[STEP_CACHE_KEY] = formed ? (double)body->step_generation : 0.0;
    slot[STEP_CACHE_LOW] = low;
    slot[STEP_CACHE_HIGH] = high;
  }
}

/* The Ogden models' per-tet cache (material_kernels.h) for the blocks of LANES tets from
 * BASE that the step bound's cache does not hold (piola__step_cache_blocks marked them: a
 * lane clamped, a padding tet): the pass computes those blocks and takes their powers from
 * there. SLOTS holds the lanes' slots, slot s of lane l at s LANES + l. The blocks it holds
 * need no per-tet slots: writing every tet's (9 doubles) was a memory stream of a third of
 * the bound's cost. */
PIOLA_KERNEL_INLINE void piola__ogden_cache_unformed(const piola_elastic_body *body, int32_t base,
                                                     const double *slots, int lanes) {
  if (!body->ogden_cache) return;
  for (int j = 0; j < lanes / PIOLA_TET_BLOCK; ++j) {
    const double *slot = body->step_cache + (size_t)(base / PIOLA_TET_BLOCK + j) * STEP_CACHE_SLOTS;
    if (slot[STEP_CACHE_KEY] != 0.0) continue; /* formed by this update */
    for (int s = 0; s < OGDEN_CACHE_SLOTS; ++s)
      for (int l = j * PIOLA_TET_BLOCK; l < (j + 1) * PIOLA_TET_BLOCK; ++l)
        body->ogden_cache[(size_t)s * (size_t)body->padded_tet_count + (size_t)(base + l)] = slots[s * lanes + l];
  }
}

/* 1 when every lane of the PIOLA_TET_BLOCK lanes from lane FIRST passes PREDICATE (no entry
 * below the threshold): the block then takes the plain formula (every extension adds exactly
 * zero there). */
#define PIOLA_BLOCK_UNCLAMPED(predicate, first, flag)                                      \
  do {                                                                                     \
    int all_ = 1;                                                                          \
    _Pragma("omp simd reduction(&:all_)") for (int l = 0; l < PIOLA_TET_BLOCK; ++l)        \
        all_ &= predicate(m, fhat[0][(first) + l], fhat[1][(first) + l],                   \
                          fhat[2][(first) + l]);                                           \
    (flag) = all_;                                                                         \
  } while (0)

/* Blocks whose lanes are all unclamped take PLAIN, the others EXTENDED, each lane loop run by
 * RUN; per block of PIOLA_TET_BLOCK, and a pair that agrees stays one interleaved loop. */
#define PIOLA_SPLIT_BY_BLOCK_WITH(run, predicate, plain, extended, lanes)                  \
  do {                                                                                     \
    int u0, u1 = 1;                                                                        \
    PIOLA_BLOCK_UNCLAMPED(predicate, 0, u0);                                               \
    if ((lanes) > PIOLA_TET_BLOCK) PIOLA_BLOCK_UNCLAMPED(predicate, PIOLA_TET_BLOCK, u1);  \
    if ((lanes) == PIOLA_TET_BLOCK || u0 == u1) {                                          \
      if (u0) run(plain, 0, (lanes));                                                      \
      else run(extended, 0, (lanes));                                                      \
    } else {                                                                               \
      if (u0) run(plain, 0, PIOLA_TET_BLOCK);                                              \
      else run(extended, 0, PIOLA_TET_BLOCK);                                              \
      if (u1) run(plain, PIOLA_TET_BLOCK, PIOLA_TET_BLOCK);                                \
      else run(extended, PIOLA_TET_BLOCK, PIOLA_TET_BLOCK);                                \
    }                                                                                      \
  } while (0)
#define PIOLA_SPLIT_BY_BLOCK(predicate, plain, extended, lanes)                            \
  PIOLA_SPLIT_BY_BLOCK_WITH(PIOLA_NEOHOOKEAN_RUN, predicate, plain, extended, lanes)

/* The models whose force loop forms the step bound's k (body->step_cache, stable_step_modulus.h):
 * returns from the stress body when it took the case. */
#define PIOLA_STEP_CACHED_STRESS(lanes)                                                    \
  if (body->step_cache && STEP_CACHE_MODEL(m->model)) {                                    \
    double k_[2 * PIOLA_TET_BLOCK], slots_[OGDEN_CACHE_SLOTS * 2 * PIOLA_TET_BLOCK];       \
    switch (m->model) {                                                                    \
      case PIOLA_MODEL_NEOHOOKEAN:                                                         \
      case PIOLA_MODEL_MUSCLE:                                                             \
        PIOLA_SPLIT_BY_BLOCK_WITH(PIOLA_STEP_CACHED_RUN, neohookean_lane_unclamped,        \
                                  neohookean_stress_modulus_unclamped,                     \
                                  neohookean_stress_lanes_uncached, lanes);                \
        break;                                                                             \
      case PIOLA_MODEL_COROTATED: PIOLA_STEP_CACHED_RUN(corotated_stress_modulus_lanes, 0, (lanes)); break; \
      case PIOLA_MODEL_STVK: PIOLA_STEP_CACHED_RUN(stvk_stress_modulus_lanes, 0, (lanes)); break; \
      case PIOLA_MODEL_SPLINE: PIOLA_STEP_CACHED_RUN(spline_stress_modulus_lanes, 0, (lanes)); break; \
      case PIOLA_MODEL_ROTATED_LINEAR:                                                     \
        PIOLA_STEP_CACHED_RUN(rotated_linear_stress_modulus_lanes, 0, (lanes));            \
        break;                                                                             \
      case PIOLA_MODEL_HGO: /* a body without fibres (STEP_CACHE_MODEL) */                 \
        PIOLA_SPLIT_BY_BLOCK_WITH(PIOLA_STEP_CACHED_RUN, hgo_lane_unclamped,               \
                                  hgo_matrix_stress_modulus_unclamped,                     \
                                  hgo_stress_lanes_uncached, lanes);                       \
        break;                                                                             \
      case PIOLA_MODEL_STABLE_NEOHOOKEAN:                                                  \
        PIOLA_SPLIT_BY_BLOCK_WITH(PIOLA_STEP_CACHED_RUN, lane_unclamped,                   \
                                  stable_neohookean_stress_modulus_unclamped,              \
                                  stable_neohookean_stress_lanes_uncached, lanes);         \
        break;                                                                             \
      case PIOLA_MODEL_MOONEY_RIVLIN: /* its powers in closed form: vector loops */        \
        PIOLA_SPLIT_BY_BLOCK_WITH(PIOLA_STEP_CACHED_RUN, mooney_rivlin_lane_unclamped,     \
                                  mooney_rivlin_stress_modulus_unclamped,                  \
                                  mooney_rivlin_stress_lanes_uncached, lanes);             \
        break;                                                                             \
      case PIOLA_MODEL_OGDEN: {                                                            \
        _Pragma("omp simd") for (int l = 0; l < (lanes); ++l)                              \
            ogden_stress_cached_lanes(m, fhat[0][l], fhat[1][l], fhat[2][l], &phat[0][l],   \
                                      &phat[1][l], &phat[2][l], slots_ + l, (lanes));      \
        _Pragma("omp simd") for (int l = 0; l < (lanes); ++l)                              \
            ogden_modulus_from_slots(m, slots_ + l, (lanes), k_ + l);                      \
        break;                                                                             \
      }                                                                                    \
      default: abort(); /* every STEP_CACHE_MODEL has its case: a new one must get its k */ \
    }                                                                                      \
    piola__step_cache_blocks(body, m, base, k_, (lanes));                                  \
    if (m->model == PIOLA_MODEL_OGDEN) piola__ogden_cache_unformed(body, base, slots_, (lanes)); \
    return;                                                                                \
  }

#define PIOLA_MATERIAL_LANE_LOOP(kernel, lanes)                                            \
  do {                                                                                     \
    _Pragma("omp simd") for (int l = 0; l < (lanes); ++l)                                  \
        kernel(m, fhat[0][l], fhat[1][l], fhat[2][l], &phat[0][l], &phat[1][l], &phat[2][l]); \
  } while (0)

/* The stress of LANES consecutive tets from base (PIOLA_TET_BLOCK, or 2 PIOLA_TET_BLOCK for
 * a pair of blocks, whose independent lanes the compiler then interleaves). */
#define PIOLA_MATERIAL_STRESS_LANES_BODY(lanes)                                            \
  if (body->uniform_material >= 0) {                                                       \
    const piola_material *m = &body->materials[body->uniform_material];                    \
    if (m->inversion_mode == PIOLA_INVERSION_ENERGY) {                                     \
      switch (m->model) {                                                                  \
        case PIOLA_MODEL_COROTATED: PIOLA_MATERIAL_LANE_LOOP(corotated_stress_energy_mode_lanes, lanes); return; \
        case PIOLA_MODEL_STVK: PIOLA_MATERIAL_LANE_LOOP(stvk_stress_energy_mode_lanes, lanes); return; \
        case PIOLA_MODEL_NEOHOOKEAN:                                                       \
        case PIOLA_MODEL_HGO:                                                              \
        case PIOLA_MODEL_MUSCLE:                                                           \
          PIOLA_SPLIT_BY_BLOCK(neohookean_lane_unclamped, neohookean_stress_lanes_unclamped, \
                               neohookean_stress_energy_mode_lanes, lanes);                \
          return;                                                                          \
        case PIOLA_MODEL_STABLE_NEOHOOKEAN:                                                \
          PIOLA_SPLIT_BY_BLOCK(lane_unclamped, stable_neohookean_stress_lanes_unclamped,   \
                               stable_neohookean_stress_energy_mode_lanes, lanes);         \
          return;                                                                          \
        case PIOLA_MODEL_SPLINE: PIOLA_MATERIAL_LANE_LOOP(spline_stress_energy_mode_lanes, lanes); return; \
        case PIOLA_MODEL_MOONEY_RIVLIN:                                                    \
        case PIOLA_MODEL_OGDEN: PIOLA_MATERIAL_LANE_LOOP(ogden_stress_energy_mode_lanes, lanes); return; \
        case PIOLA_MODEL_ROTATED_LINEAR:                                                   \
        default: PIOLA_MATERIAL_LANE_LOOP(rotated_linear_stress_energy_mode_lanes, lanes); return; \
      }                                                                                    \
    }                                                                                      \
    PIOLA_STEP_CACHED_STRESS(lanes)                                                        \
    switch (m->model) {                                                                    \
      case PIOLA_MODEL_COROTATED: PIOLA_MATERIAL_LANE_LOOP(corotated_stress_lanes, lanes); return; \
      case PIOLA_MODEL_STVK: PIOLA_MATERIAL_LANE_LOOP(stvk_stress_lanes, lanes); return;          \
      case PIOLA_MODEL_NEOHOOKEAN:                                                         \
      case PIOLA_MODEL_MUSCLE:                                                             \
        PIOLA_SPLIT_BY_BLOCK(neohookean_lane_unclamped, neohookean_stress_lanes_unclamped, \
                             neohookean_stress_lanes, lanes);                              \
        return;                                                                            \
      case PIOLA_MODEL_HGO: /* neo-Hookean with the threshold's rise with J */             \
        PIOLA_SPLIT_BY_BLOCK(hgo_lane_unclamped, neohookean_stress_lanes_unclamped,        \
                             hgo_stress_lanes, lanes);                                     \
        return;                                                                            \
      case PIOLA_MODEL_STABLE_NEOHOOKEAN:                                                  \
        PIOLA_SPLIT_BY_BLOCK(lane_unclamped, stable_neohookean_stress_lanes_unclamped,     \
                             stable_neohookean_stress_lanes, lanes);                       \
        return;                                                                            \
      case PIOLA_MODEL_SPLINE: PIOLA_MATERIAL_LANE_LOOP(spline_stress_lanes, lanes); return;      \
      case PIOLA_MODEL_MOONEY_RIVLIN:                                                      \
        PIOLA_SPLIT_BY_BLOCK(mooney_rivlin_lane_unclamped, mooney_rivlin_stress_lanes_unclamped, \
                             mooney_rivlin_stress_lanes, lanes);                           \
        return;                                                                            \
      case PIOLA_MODEL_OGDEN:                                                              \
        if (body->ogden_cache) { /* the step bound's powers (material_kernels.h) */        \
          double *cache_ = body->ogden_cache + base;                                       \
          const long stride_ = body->padded_tet_count;                                     \
          _Pragma("omp simd") for (int l = 0; l < (lanes); ++l)                            \
              ogden_stress_cached_lanes(m, fhat[0][l], fhat[1][l], fhat[2][l], &phat[0][l], \
                                        &phat[1][l], &phat[2][l], cache_ + l, stride_);    \
          return;                                                                          \
        }                                                                                  \
        PIOLA_MATERIAL_LANE_LOOP(ogden_stress_lanes, lanes);                               \
        return;                                                                            \
      case PIOLA_MODEL_ROTATED_LINEAR:                                                     \
      default: PIOLA_MATERIAL_LANE_LOOP(rotated_linear_stress_lanes, lanes); return;             \
    }                                                                                      \
  }                                                                                        \
  for (int l = 0; l < (lanes); ++l) {                                                      \
    const piola_material *m = &body->materials[body->tet_material[base + l]];              \
    material_stress_kernel(m, fhat[0][l], fhat[1][l], fhat[2][l], &phat[0][l], &phat[1][l], \
                           &phat[2][l]);                                                   \
  }

PIOLA_KERNEL_INLINE void piola__material_stress_lanes(const piola_elastic_body *body,
                                                      int32_t base,
                                                      double fhat[3][PIOLA_TET_BLOCK],
                                                      double phat[3][PIOLA_TET_BLOCK]) {
  PIOLA_MATERIAL_STRESS_LANES_BODY(PIOLA_TET_BLOCK)
}

PIOLA_KERNEL_INLINE void piola__material_stress_lanes2(const piola_elastic_body *body,
                                                       int32_t base,
                                                       double fhat[3][2 * PIOLA_TET_BLOCK],
                                                       double phat[3][2 * PIOLA_TET_BLOCK]) {
  PIOLA_MATERIAL_STRESS_LANES_BODY(2 * PIOLA_TET_BLOCK)
}

#undef PIOLA_MATERIAL_STRESS_LANES_BODY
#undef PIOLA_MATERIAL_LANE_LOOP
#undef PIOLA_NEOHOOKEAN_RUN
#undef PIOLA_BLOCK_UNCLAMPED
#undef PIOLA_SPLIT_BY_BLOCK
#undef PIOLA_SPLIT_BY_BLOCK_WITH
#undef PIOLA_STEP_CACHED_RUN
#undef PIOLA_STEP_CACHED_STRESS

#endif
