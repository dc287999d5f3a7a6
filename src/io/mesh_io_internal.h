/* Internal entry points of the mesh readers.
 *
 * Every reader parses a complete file held in memory (name, bytes, size); the path-based
 * public functions only load the file and dispatch on its extension. Parsing from memory
 * keeps the readers free of I/O concerns and lets the fuzzers (fuzz/) drive them directly.
 * `name` is used only in messages ("name:line: message", or "name: byte N: ..." for binary
 * data). Tet readers return meshes checked and oriented by piola__tet_mesh_finish. */
#ifndef PIOLA_IO_MESH_IO_INTERNAL_H
#define PIOLA_IO_MESH_IO_INTERNAL_H

#include <stddef.h>

#include "common/grow.h"
#include "piola/mesh.h"
#include "piola/mesh_io.h"

piola_status piola__read_tetgen_mem(const char *node_name, const char *node_data, size_t node_size,
                                    const char *ele_name, const char *ele_data, size_t ele_size,
                                    piola_tet_mesh *out);
piola_status piola__read_gmsh_mem(const char *name, const char *data, size_t size, piola_tet_mesh *out);
piola_status piola__read_vtu_mem(const char *name, const char *data, size_t size, piola_tet_mesh *out);
/* The whole content of a VTU file (cells as in the file, fields); see piola_vtu_read. */
piola_status piola__vtu_read_mem(const char *name, const char *data, size_t size, piola_vtu_data *out);
piola_status piola__read_medit_mem(const char *name, const char *data, size_t size, piola_tet_mesh *out);
piola_status piola__read_vega_mem(const char *name, const char *data, size_t size, piola_tet_mesh *out,
                                  piola_vega_material **materials, int32_t *material_count);
piola_status piola__read_obj_mem(const char *name, const char *data, size_t size, piola_tri_mesh *out);
piola_status piola__read_off_mem(const char *name, const char *data, size_t size, piola_tri_mesh *out);
piola_status piola__read_stl_mem(const char *name, const char *data, size_t size, piola_tri_mesh *out);

/* Merges vertices with bit-identical coordinates (-0 equals 0); remaps triangles. */
piola_status piola__weld_vertices(piola_tri_mesh *mesh, const char *source);

/* Checks a loaded surface: at least one triangle, finite positions, indices in range. */
piola_status piola__tri_mesh_finish(piola_tri_mesh *mesh, const char *source);


#endif
