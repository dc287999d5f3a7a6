/* Tet-mesh topology and element quality used by the mesher.
 *
 * The mesher works on plain index arrays (4 vertex ids per tet) and needs three things
 * again and again: the tets around a vertex (a CSR table), the tet across each face (to
 * find the boundary), and a quality number it can guard while it moves nodes. The quality
 * is the minimum dihedral angle: it is what the docs promise, it goes to zero for every
 * kind of degenerate tet (needle, wedge, sliver, cap), and a positive value also certifies
 * a positively oriented tet. Faces follow piola/mesh.h: (0,2,1), (0,1,3), (0,3,2), (1,2,3),
 * wound outward; face f is opposite vertex 3 - f. */
#ifndef PIOLA_MESHER_TET_TOPOLOGY_H
#define PIOLA_MESHER_TET_TOPOLOGY_H

#include <stdint.h>

#include "math/mat3.h"
#include "piola/status.h"

/* Compressed rows: the items of row r are items[offsets[r] .. offsets[r+1]). */
typedef struct piola__csr {
  int32_t rows;
  int32_t *offsets; /* rows + 1 */
  int32_t *items;
} piola__csr;

void piola__csr_free(piola__csr *csr);

/* Row v lists the tets that use vertex v. Tets with keep[t] == 0 are left out (keep may be
 * NULL: all tets). */
piola_status piola__vertex_tets(int32_t vertex_count, const int32_t *tets, int32_t tet_count,
                                const uint8_t *keep, piola__csr *out);

/* The local vertex indices of face f of a tet (outward winding). */
extern const int piola__tet_face[4][3];

/* neighbor[4 t + f] = the kept tet across face f of kept tet t, -1 on the boundary, or -2
 * when more than one other tet uses the face (not a valid tet mesh). Entries of tets that
 * are not kept are -1. vertex_tets must have been built with the same keep. */
void piola__face_neighbors(const int32_t *tets, int32_t tet_count, const uint8_t *keep,
                           const piola__csr *vertex_tets, int32_t *neighbor);

/* Signed volume (x1-x0).((x2-x0)x(x3-x0))/6, m^3. */
static inline double piola__tet_volume(vec3 a, vec3 b, vec3 c, vec3 d) {
  return vec3_dot(vec3_sub(b, a), vec3_cross(vec3_sub(c, a), vec3_sub(d, a))) / 6.0;
}

/* Cosine of the smallest dihedral angle (larger = worse), or 2 when the tet is not
 * positively oriented: ordered like the angle, without any acos, for the inner loops of the
 * quality guard. */
double piola__tet_min_dihedral_cosine(vec3 a, vec3 b, vec3 c, vec3 d);

#endif
