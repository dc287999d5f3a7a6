/* piola: reading and writing mesh files.
 *
 * The format is chosen by file extension:
 *   tetrahedral meshes  .node/.ele (TetGen; give either file), .msh (Gmsh 2.2 and 4.1, ASCII
 *                       and binary), .mesh (Medit), .veg (Vega, TET elements), .vtu (VTK)
 *   triangle surfaces   .obj, .off, .stl (ASCII and binary; vertices welded)
 * Readers never crash on malformed input: they return PIOLA_ERROR_PARSE (or _IO,
 * _UNSUPPORTED) with a message naming the file and the line or byte offset. Loaded tets are
 * oriented positively (piola_tet_mesh_orient). See docs/file-formats.md.
 *
 * Writers write the whole file or nothing: they write a temporary file in the same folder
 * and rename it over the target only once it is complete. */
#ifndef PIOLA_MESH_IO_H
#define PIOLA_MESH_IO_H

#include "piola/export.h"
#include "piola/mesh.h"
#include "piola/status.h"

#ifdef __cplusplus
extern "C" {
#endif

PIOLA_API piola_status piola_tet_mesh_read(const char *path, piola_tet_mesh *out);
PIOLA_API piola_status piola_tri_mesh_read(const char *path, piola_tri_mesh *out);

/* .msh (Gmsh 4.1 ASCII), .vtu, .node or .ele (writes both), .mesh (Medit), and the boundary
 * surface as .obj, .off or .stl (binary); others are PIOLA_ERROR_UNSUPPORTED. */
PIOLA_API piola_status piola_tet_mesh_write(const char *path, const piola_tet_mesh *mesh);
/* .obj, .off, .stl (binary) */
PIOLA_API piola_status piola_tri_mesh_write(const char *path, const piola_tri_mesh *mesh);

/* A named field of doubles for VTU output: `components` values per point or per cell. */
typedef struct piola_vtu_field {
  const char *name;
  int components;          /* 1 (scalar) or 3 (vector) */
  const double *values;    /* components * count values */
} piola_vtu_field;

/* Tetrahedra (and optional triangles, e.g. shells) with point and cell fields, as VTK
 * UnstructuredGrid XML (appended raw binary). Points are the tet mesh's vertices followed by
 * the triangle mesh's vertices (when both are given they are written as separate pieces of
 * one point list); point fields cover the same list. Cell fields cover the tets first, then
 * the triangles. positions override the meshes' positions when not NULL (current state). */
typedef struct piola_vtu_frame {
  const piola_tet_mesh *tets;          /* may be NULL */
  const piola_tri_mesh *triangles;     /* may be NULL */
  const piola_vtu_field *point_fields;
  int point_field_count;
  const piola_vtu_field *cell_fields;
  int cell_field_count;
  const double *positions;             /* 3 * point count, m, or NULL */
} piola_vtu_frame;

PIOLA_API piola_status piola_vtu_write(const char *path, const piola_vtu_frame *frame);

/* A named field read from a VTU file: `components` values per point or per cell, converted
 * to double whatever their stored type. */
typedef struct piola_vtu_array {
  char name[64];           /* "" when the DataArray has no (or a too long) Name */
  int components;          /* 1..64 */
  double *values;          /* components * count values */
} piola_vtu_array;

/* Everything piola_vtu_read takes from a VTU file. Cells keep the file's vertex order (they
 * are not reoriented, so inverted elements stay inverted). Tets are VTK type 10 and the
 * corners of quadratic tets (24); triangles are type 5 and the corners of quadratic
 * triangles (22); other cells count in cell_count but are not kept. tet_cells and
 * triangle_cells give each element's index among all cells, which is what cell fields are
 * indexed by. Fields of non-numeric type (String) are skipped. */
typedef struct piola_vtu_data {
  int32_t point_count;
  double *positions;               /* 3 * point_count, m */
  int32_t cell_count;              /* all cells of the file */
  int32_t tet_count;
  int32_t *tets;                   /* 4 * tet_count vertex indices */
  int32_t *tet_cells;              /* tet_count cell indices */
  int32_t triangle_count;
  int32_t *triangles;              /* 3 * triangle_count vertex indices */
  int32_t *triangle_cells;         /* triangle_count cell indices */
  piola_vtu_array *point_fields;   /* values per point */
  int32_t point_field_count;
  piola_vtu_array *cell_fields;    /* values per cell (cell_count of them) */
  int32_t cell_field_count;
} piola_vtu_data;

/* Reads a VTK XML UnstructuredGrid file (one Piece; ascii, base64 or appended raw data;
 * little-endian; not compressed) with its point and cell fields. Every count and offset is
 * checked against the file, so a truncated file (a frame still being written) fails with
 * PIOLA_ERROR_PARSE; on failure *out is empty. Free with piola_vtu_data_free. */
PIOLA_API piola_status piola_vtu_read(const char *path, piola_vtu_data *out);
PIOLA_API void piola_vtu_data_free(piola_vtu_data *data);
/* The field named `name` among `fields`, or NULL. */
PIOLA_API const piola_vtu_array *piola_vtu_find_field(const piola_vtu_array *fields, int32_t count,
                                                      const char *name);

/* A material of a Vega .veg file (*MATERIAL name, ENU density E nu). Other material kinds
 * keep their name and kind with density/E/nu set to 0. */
typedef struct piola_vega_material {
  char name[64];
  char kind[32];            /* "ENU", ... */
  double density;           /* kg/m^3 */
  double youngs_modulus;    /* Pa */
  double poisson_ratio;     /* dimensionless */
} piola_vega_material;

/* Reads a .veg file with its materials. mesh->tet_regions[t] is the index into *materials
 * of the material that a *REGION assigns to tet t, or -1 when no region covers it.
 * *materials is malloc'ed (free it with free()); it may be NULL when there are none. */
PIOLA_API piola_status piola_vega_read(const char *path, piola_tet_mesh *mesh, piola_vega_material **materials,
                                       int32_t *material_count);

#ifdef __cplusplus
}
#endif

#endif
