/* Moving the boundary nodes of the kept lattice tets onto the surface phi = 0.
 *
 * MBTF03 compresses the lattice onto the surface with a physical simulation. We use a
 * guarded geometric version of the same idea: each boundary node is moved toward its
 * projection on the surface (p - phi grad phi, iterated), a quarter, then a third, then
 * half of the remaining way, then all of it, Gauss-Seidel, node by node. Before a move is
 * accepted the minimum dihedral angle of the tets around the node is checked; if it would
 * fall below the guard (PIOLA__SNAP_MIN_DIHEDRAL_DEG) the move is halved (a line search
 * on the fraction, down to not moving at all). Between sweeps the interior nodes next to
 * the boundary are smoothed (moved toward the mean of their neighbours when that raises
 * the worst angle around them), which makes room for the boundary to move further.
 *
 * Guarantee: a move is accepted only if it keeps every affected tet at or above the guard
 * angle (or, for a tet already below it, does not lower it). Lattice tets start at 60
 * degrees, green tets at more than the guard, so no output tet is inverted or flatter than
 * the guard. The price is that a node whose move would break the guard stays short of the
 * surface; the tests measure how many and how far. */
#ifndef PIOLA_MESHER_BOUNDARY_SNAP_H
#define PIOLA_MESHER_BOUNDARY_SNAP_H

#include "mesher/shape_union.h"
#include "piola/mesh.h"

/* The smallest dihedral angle (degrees) a snapped tet may have. */
#define PIOLA__SNAP_MIN_DIHEDRAL_DEG 10.0

/* Moves mesh boundary nodes onto the surface of `shapes`; h is the finest lattice spacing
 * (m), used for tolerances. */
piola_status piola__boundary_snap(piola_tet_mesh *mesh, const piola__shape_union *shapes,
                                  double h);

#endif
