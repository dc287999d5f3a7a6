/* piola: tetrahedral and triangle meshes as plain data.
 *
 * Meshes are plain structs of arrays that the caller may fill directly or get from a
 * reader (piola/mesh_io.h). Arrays are allocated with malloc; the *_free functions release
 * them and zero the struct. Indices are 0-based. Positions are in metres. */
#ifndef PIOLA_MESH_H
#define PIOLA_MESH_H

#include <stddef.h>
#include <stdint.h>

#include "piola/export.h"
#include "piola/math_types.h"
#include "piola/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct piola_tet_mesh {
  int32_t vertex_count;
  double *positions;      /* 3 * vertex_count, m */
  int32_t tet_count;
  int32_t *tets;          /* 4 * tet_count vertex indices */
  int32_t *tet_regions;   /* tet_count region ids (physical group, attribute, ref), or NULL */
  double *tet_fibers;     /* 3 * tet_count fibre directions (muscle, wood...) in world space,
                             dimensionless, as given (not normalized), or NULL when the file has
                             none. Read from a .vtu cell array or a .msh $ElementData named
                             "fiber" or "fibers" (docs/file-formats.md) */
} piola_tet_mesh;

typedef struct piola_tri_mesh {
  int32_t vertex_count;
  double *positions;      /* 3 * vertex_count, m */
  int32_t triangle_count;
  int32_t *triangles;     /* 3 * triangle_count vertex indices */
} piola_tri_mesh;

PIOLA_API void piola_tet_mesh_free(piola_tet_mesh *mesh);
PIOLA_API void piola_tri_mesh_free(piola_tri_mesh *mesh);

/* Deep copy. */
PIOLA_API piola_status piola_tet_mesh_copy(const piola_tet_mesh *source, piola_tet_mesh *out);

/* Maps the mesh by x' = linear x + translation (positions in m) and carries its fibres
 * along as material directions: d' = linear d, rescaled to the length of d (unit fibres stay
 * unit; a zero fibre stays zero). det(linear) must be > 0 so tets keep their orientation;
 * a singular or mirroring map (PIOLA_ERROR_INVALID_ARGUMENT) or a non-finite entry of
 * linear or translation (PIOLA_ERROR_NOT_FINITE) is refused and leaves the mesh as it
 * was. With linear = R S (a rotation times a scale) this is the scene's `transform`. */
PIOLA_API piola_status piola_tet_mesh_transform(piola_tet_mesh *mesh, piola_mat3 linear,
                                                piola_vec3 translation);

/* Checks counts, index ranges, finite positions and finite fibres; names the first
 * offending entry. */
PIOLA_API piola_status piola_tet_mesh_validate(const piola_tet_mesh *mesh);

/* Signed volume of tet t, (x1-x0) . ((x2-x0) x (x3-x0)) / 6, in m^3. */
PIOLA_API double piola_tet_mesh_signed_volume(const piola_tet_mesh *mesh, int32_t t);

/* Swaps two vertices of every negatively oriented tet so all have positive volume.
 * Returns the number of tets flipped. */
PIOLA_API int32_t piola_tet_mesh_orient(piola_tet_mesh *mesh);

/* The boundary surface: faces used by exactly one tet, wound outward. Faces of tets are
 * (0,2,1), (0,1,3), (0,3,2), (1,2,3). The result shares vertex numbering with the mesh. */
PIOLA_API piola_status piola_tet_mesh_boundary(const piola_tet_mesh *mesh, piola_tri_mesh *out);

/* A structured box mesh: nx * ny * nz cells of spacing (m) along x, y, z, with a corner at
 * the origin, each cell split into 6 tets around its main diagonal (a conforming
 * triangulation). Vertex (i, j, k) is number i + (nx + 1) (j + (ny + 1) k) at
 * (i spacing.x, j spacing.y, k spacing.z). Half of the tets come out negatively oriented;
 * piola_tet_mesh_orient or an elastic body fixes that. For tests, benchmarks and quick
 * scenes; real shapes go through the mesher. */
PIOLA_API piola_status piola_tet_mesh_box_grid(int32_t nx, int32_t ny, int32_t nz,
                                               piola_vec3 spacing, piola_tet_mesh *out);

#ifdef __cplusplus
}
#endif

#endif
