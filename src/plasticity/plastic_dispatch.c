/* The plastic lanes' entry point under its plain name: the variant of plastic_lanes.c the
 * CPU runs best, or the one PIOLA_ISA asks for (common/isa.h). */
#include "plasticity/plastic_state.h"

int32_t piola__plastic_update_blocks(piola_plastic_state *s, int32_t first, int32_t end,
                                     int32_t *limited, double *bound) {
  return PIOLA_ISA_SELECT(piola__plastic_update_blocks)(s, first, end, limited, bound);
}
