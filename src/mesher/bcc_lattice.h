/* The body-centred cubic (BCC) lattice of MBTF03.
 *
 * Nodes are the corners of a grid of cubes of edge h plus the cube centres. Each pair of
 * cube centres across a shared face, together with one of the four edges of that face,
 * spans a tetrahedron: 4 tets per interior face, 12 per cube. All of them are congruent,
 * with two edges of length h (centre-centre and corner-corner) and four of length
 * (sqrt(3)/2) h, dihedral angles of 60 and 90 degrees: the best-shaped tets that tile space
 * in a pattern that also refines into itself (red refinement of every tet gives the BCC
 * lattice of spacing h/2), which is why the mesher starts from it. */
#ifndef PIOLA_MESHER_BCC_LATTICE_H
#define PIOLA_MESHER_BCC_LATTICE_H

#include <stdint.h>

#include "math/mat3.h"
#include "piola/status.h"

typedef struct piola__bcc_lattice {
  int32_t cells[3];      /* cubes along x, y, z */
  double cell_size;      /* m */
  vec3 origin;           /* m: the corner of cube (0, 0, 0) */
  int32_t vertex_count;  /* (nx+1)(ny+1)(nz+1) corners, then nx ny nz centres */
  double *positions;     /* 3 * vertex_count */
  int32_t tet_count;
  int32_t *tets;         /* 4 * tet_count, all positively oriented */
} piola__bcc_lattice;

/* A lattice whose cubes cover the box [lo, hi] (m). Fails with INVALID_ARGUMENT when the
 * lattice would exceed max_tets tetrahedra. */
piola_status piola__bcc_lattice_build(vec3 lo, vec3 hi, double cell_size, int64_t max_tets,
                                      piola__bcc_lattice *out);
void piola__bcc_lattice_free(piola__bcc_lattice *lattice);

#endif
