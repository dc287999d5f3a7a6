/* The blocked force loop (force_lanes.c), a kernel built once per instruction set
 * (common/isa.h). */
#ifndef PIOLA_FORCE_FORCE_LANES_H
#define PIOLA_FORCE_FORCE_LANES_H

#include "common/isa.h"
#include "force/elastic_body_internal.h"

/* Blocks [b0, b1) of body at positions x (m): their forces (N), times stiffness_scale, added
 * into out in tet order, and the per-tet state (U, V, Fhat, det F); with want_energy, the
 * energy densities and the per-block statistics too. Blocks go in pairs from b0. */
#define PIOLA_FORCE_BLOCK_RANGE_PARAMS                                                      \
  (piola_elastic_body * body, const double *x, double stiffness_scale, int want_energy,    \
   int32_t b0, int32_t b1, double *out)
PIOLA_ISA_DECLARE(void, piola__force_block_range, PIOLA_FORCE_BLOCK_RANGE_PARAMS);
void piola__force_block_range PIOLA_FORCE_BLOCK_RANGE_PARAMS;

#endif
