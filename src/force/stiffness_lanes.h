/* The projected stiffness blocks of one block of PIOLA_TET_BLOCK tets at once
 * (stiffness_lanes.c, a kernel built once per instruction set, common/isa.h; the plain name
 * runs the chosen variant), for stiffness_matrix.c's assembly. */
#ifndef PIOLA_FORCE_STIFFNESS_LANES_H
#define PIOLA_FORCE_STIFFNESS_LANES_H

#include <stdint.h>

#include "common/isa.h"
#include "force/elastic_body_internal.h"

/* out[e][l] = entry e of piola__tet_stiffness_blocks(body, block * PIOLA_TET_BLOCK + l) for
 * every lane l, the same bits, but for the fibre term of a muscle's or HGO's tet, which the
 * assembly adds tet by tet (stiffness_matrix.c). Only for blocks of real tets. */
#define PIOLA_STIFFNESS_BLOCK_LANES_PARAMS \
  (const piola_elastic_body * body, int32_t block, double out[54][PIOLA_TET_BLOCK])
PIOLA_ISA_DECLARE(void, piola__stiffness_block_lanes, PIOLA_STIFFNESS_BLOCK_LANES_PARAMS);
void piola__stiffness_block_lanes PIOLA_STIFFNESS_BLOCK_LANES_PARAMS;

#endif
