/* The force kernels' entry points under their plain names: each runs the variant the CPU
 * runs best, or the one PIOLA_ISA asks for (common/isa.h). The calls are per block range,
 * per body or per batch, so the indirection costs nothing measurable. */
#include "force/damping_matrix.h"
#include "force/fiber_lanes.h"
#include "force/force_lanes.h"
#include "force/stable_step.h"
#include "force/stiffness_lanes.h"
#include "force/svd_kernel.h"

void piola__force_block_range(piola_elastic_body *body, const double *x, double stiffness_scale,
                              int want_energy, int32_t b0, int32_t b1, double *out) {
  PIOLA_ISA_SELECT(piola__force_block_range)(body, x, stiffness_scale, want_energy, b0, b1, out);
}

void piola__elastic_body_update_block_pair(piola_elastic_body *body, const double *x,
                                           double stiffness_scale, int want_energy, int32_t first,
                                           int count, double *out) {
  PIOLA_ISA_SELECT(piola__elastic_body_update_block_pair)(body, x, stiffness_scale, want_energy,
                                                          first, count, out);
}

void piola__elastic_body_refill_step_cache(piola_elastic_body *body) {
  PIOLA_ISA_SELECT(piola__elastic_body_refill_step_cache)(body);
}

double piola__fiber_energy_density(const piola_elastic_body *body, int32_t t) {
  return PIOLA_ISA_SELECT(piola__fiber_energy_density)(body, t);
}

piola_status piola__fiber_copy(piola_elastic_body *body, const piola_elastic_body_def *def) {
  return PIOLA_ISA_SELECT(piola__fiber_copy)(body, def);
}

void piola__damping_matrix_assemble(piola__damping_matrix *matrix, const piola_elastic_body *body,
                                    double shear_viscosity, double bulk_viscosity) {
  PIOLA_ISA_SELECT(piola__damping_matrix_assemble)(matrix, body, shear_viscosity, bulk_viscosity);
}

void piola__stiffness_block_lanes(const piola_elastic_body *body, int32_t block,
                                  double out[54][PIOLA_TET_BLOCK]) {
  PIOLA_ISA_SELECT(piola__stiffness_block_lanes)(body, block, out);
}

void piola__svd3_kernel_batch(int32_t n, const double *f, double *u, double *fhat, double *v) {
  PIOLA_ISA_SELECT(piola__svd3_kernel_batch)(n, f, u, fhat, v);
}

double piola__elastic_body_state_rate2(piola_elastic_body *body, int32_t *worst_tet) {
  return PIOLA_ISA_SELECT(piola__elastic_body_state_rate2)(body, worst_tet);
}

double piola__elastic_body_tet_modulus(const piola_elastic_body *body, int32_t tet,
                                       const double fhat[3]) {
  return PIOLA_ISA_SELECT(piola__elastic_body_tet_modulus)(body, tet, fhat);
}

double piola__elastic_body_tet_state_rate2(const piola_elastic_body *body, int32_t tet) {
  return PIOLA_ISA_SELECT(piola__elastic_body_tet_state_rate2)(body, tet);
}

const double *piola__elastic_body_step_weights(piola_elastic_body *body) {
  return PIOLA_ISA_SELECT(piola__elastic_body_step_weights)(body);
}

double piola__elastic_body_tet_rest_altitude(const piola_elastic_body *body, int32_t tet) {
  return PIOLA_ISA_SELECT(piola__elastic_body_tet_rest_altitude)(body, tet);
}
