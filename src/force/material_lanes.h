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

#include "force/elastic_body_internal.h"
#include "force/svd_kernel.h"
#include "material/material_kernels.h"
#include "piola/material.h"

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
    switch (m->model) {                                                                    \
      case PIOLA_MODEL_COROTATED: PIOLA_MATERIAL_LANE_LOOP(corotated_stress_lanes, lanes); return; \
      case PIOLA_MODEL_STVK: PIOLA_MATERIAL_LANE_LOOP(stvk_stress_lanes, lanes); return;          \
      case PIOLA_MODEL_NEOHOOKEAN:                                                         \
      case PIOLA_MODEL_MUSCLE: PIOLA_MATERIAL_LANE_LOOP(neohookean_stress_lanes, lanes); return;  \
      case PIOLA_MODEL_SPLINE: PIOLA_MATERIAL_LANE_LOOP(spline_stress_lanes, lanes); return;      \
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

#endif
