/* Internal writers, one file per format; all write through piola_atomic_file. */
#ifndef PIOLA_IO_MESH_WRITERS_H
#define PIOLA_IO_MESH_WRITERS_H

#include "piola/mesh.h"

piola_status piola__write_gmsh41(const char *path, const piola_tet_mesh *mesh);
piola_status piola__write_tetgen(const char *path, const piola_tet_mesh *mesh);
piola_status piola__write_medit(const char *path, const piola_tet_mesh *mesh);
piola_status piola__write_obj(const char *path, const piola_tri_mesh *mesh);
piola_status piola__write_off(const char *path, const piola_tri_mesh *mesh);
piola_status piola__write_stl(const char *path, const piola_tri_mesh *mesh);

/* Drops vertices that no triangle uses and renumbers the rest in order. */
piola_status piola__tri_mesh_compact(piola_tri_mesh *mesh);

/* Appends the shortest-enough decimal form of v that reads back exactly ("%.17g"). */
int piola__format_double(char *out, double v);

#endif
