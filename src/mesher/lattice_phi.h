/* The level set at every lattice node, fast for triangle surfaces.
 *
 * An exact signed distance to a surface costs a closest-point query and a winding number
 * per node, and most lattice nodes are far from the surface where only the sign matters.
 * So for surfaces we compute the distance only within a band (|phi| < band, with
 * band >= the longest lattice edge) and, beyond it, the sign by connectivity: two nodes
 * joined by a lattice edge that are both farther than the band from the surface cannot
 * have the surface between them (every point of the edge is within half an edge of one of
 * them), so each connected set of far nodes has one sign, found with one winding number.
 * Far nodes get phi = +-band: the right sign and a magnitude that is a lower bound, which is
 * all the selection and refinement rules look at. Analytic shapes are evaluated exactly. */
#ifndef PIOLA_MESHER_LATTICE_PHI_H
#define PIOLA_MESHER_LATTICE_PHI_H

#include <stdint.h>

#include "mesher/shape_union.h"

piola_status piola__lattice_phi(const piola__shape_union *shapes, const double *positions,
                                int32_t vertex_count, const int32_t *tets, int32_t tet_count,
                                double band, double *phi);

#endif
