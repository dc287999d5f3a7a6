/* piola: quality and topology measures of tet meshes and triangle surfaces.
 *
 * Used by `piola mesh info`, the tests and the mesher. Angles in degrees, volumes in m^3,
 * ratios dimensionless. */
#ifndef PIOLA_MESH_QUALITY_H
#define PIOLA_MESH_QUALITY_H

#include "piola/export.h"
#include "piola/mesh.h"
#include "piola/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The six interior dihedral angles of the tet (x0..x3, 3 doubles each), in degrees, at
 * edges (0,1), (0,2), (0,3), (1,2), (1,3), (2,3). Flat tets give angles of 0 or 180. */
PIOLA_API void piola_tet_dihedral_angles(const double *x0, const double *x1, const double *x2, const double *x3,
                                         double angles_degrees[6]);

/* Aspect ratio: longest edge / (2 sqrt(6) inradius); 1 for the regular tet, larger is
 * worse, +inf for a flat tet. */
PIOLA_API double piola_tet_aspect_ratio(const double *x0, const double *x1, const double *x2, const double *x3);

/* Mean-ratio-like quality 6 sqrt(2) |V| / l_rms^3: 1 for the regular tet, 0 when flat. */
PIOLA_API double piola_tet_mean_ratio(const double *x0, const double *x1, const double *x2, const double *x3);

#define PIOLA_QUALITY_WORST 5

typedef struct piola_tet_mesh_quality {
  double volume;                 /* sum of signed volumes, m^3 */
  double min_volume, max_volume; /* signed, m^3 */
  double min_dihedral_degrees, max_dihedral_degrees;
  double min_mean_ratio;
  int32_t worst_count;                      /* entries used in the arrays below */
  int32_t worst_tets[PIOLA_QUALITY_WORST];  /* tets with the largest aspect ratios, worst first */
  double worst_aspect[PIOLA_QUALITY_WORST];
} piola_tet_mesh_quality;

PIOLA_API piola_status piola_tet_mesh_measure(const piola_tet_mesh *mesh, piola_tet_mesh_quality *out);

typedef struct piola_surface_topology {
  int32_t used_vertices;      /* vertices referenced by a triangle */
  int32_t edges;              /* distinct undirected edges */
  int32_t open_edges;         /* edges with one triangle */
  int32_t nonmanifold_edges;  /* edges with more than two triangles */
  int32_t misoriented_edges;  /* edges whose two triangles run the same way along them */
  int32_t nonmanifold_vertices; /* (closed surfaces) vertices whose triangles form more than one fan */
  int32_t euler_characteristic; /* used_vertices - edges + triangles */
  int closed;                 /* no open and no non-manifold edges */
  int manifold;               /* no non-manifold edges and no non-manifold vertices */
  int oriented;               /* no misoriented edges */
} piola_surface_topology;

PIOLA_API piola_status piola_tri_mesh_topology(const piola_tri_mesh *mesh, piola_surface_topology *out);

/* Volume enclosed by a closed surface (divergence theorem), m^3; positive when wound outward. */
PIOLA_API double piola_tri_mesh_enclosed_volume(const piola_tri_mesh *mesh);

#ifdef __cplusplus
}
#endif

#endif
