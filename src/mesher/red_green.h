/* Red-green refinement of the BCC lattice toward the surface (MBTF03 section 3).
 *
 * Red refinement splits a tet into 8 by its edge midpoints: 4 corner tets, and 4 tets
 * around one diagonal of the inner octahedron. Choosing the shortest diagonal (the one
 * joining the midpoint of the centre-centre edge with the midpoint of the corner-corner
 * edge) makes the 8 children tets of the BCC lattice of half the spacing, so refined
 * regions are again crystalline and congruent: quality never degrades with depth.
 *
 * Algorithm: the leaves are kept only red-refined (a non-conforming mesh with hanging
 * midpoints). Each level red-refines the leaves of the finest level whose nodes come within
 * one edge length of the surface. Then a closure loop red-refines every leaf that would
 * need a split pattern other than the two green ones: a leaf is red-refined when one of its
 * edges is split twice (a level jump of two), or when its split edges are neither a single
 * edge nor exactly the three edges of one face. Finally green closure splits the remaining
 * leaves: a single split edge bisects the tet into 2, a split face into 4 (the face into
 * 4 triangles, each joined to the opposite vertex). Every face then carries 0, 1 or 3 split
 * edges seen from either side, and both sides split it the same way, so the result is
 * conforming: no hanging nodes. Green tets are never refined further (they exist only in
 * the output), which is what keeps their quality bounded (MBTF03). */
#ifndef PIOLA_MESHER_RED_GREEN_H
#define PIOLA_MESHER_RED_GREEN_H

#include <stdint.h>

#include "mesher/shape_union.h"
#include "piola/status.h"

/* A growable tet mesh with the level set value at each vertex. */
typedef struct piola__tet_soup {
  int32_t vertex_count, vertex_capacity;
  double *positions; /* 3 per vertex, m */
  double *phi;       /* 1 per vertex, m */
  int32_t tet_count, tet_capacity;
  int32_t *tets;     /* 4 per tet */
} piola__tet_soup;

void piola__tet_soup_free(piola__tet_soup *soup);

/* Refines `levels` times toward phi = 0 and closes with green tets. cell_size is the edge of
 * the coarse lattice cubes (m). New vertices get phi from the shape union. */
piola_status piola__red_green_refine(piola__tet_soup *soup, const piola__shape_union *shapes,
                                     int levels, double cell_size);

#endif
