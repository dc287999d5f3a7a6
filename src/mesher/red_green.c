#include "mesher/red_green.h"

#include "common/status_internal.h"

piola_status piola__red_green_refine(piola__tet_soup *soup, const piola__shape_union *shapes,
                                     int levels, double cell_size) {
  (void)soup;
  (void)shapes;
  (void)cell_size;
  return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED, "mesher: refinement_levels %d: not yet", levels);
}
