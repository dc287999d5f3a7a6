/* Medit .mesh writer (ASCII, version 2; tet ref = region, 0 without regions). */
#include "common/status_internal.h"
#include "io/atomic_file.h"
#include "io/mesh_writers.h"

piola_status piola__write_medit(const char *path, const piola_tet_mesh *mesh) {
  atomic_file f;
  PIOLA_TRY(atomic_file_open(&f, path));
  FILE *o = f.stream;
  char a[32], b[32], c[32];
  fprintf(o, "MeshVersionFormatted 2\nDimension 3\nVertices\n%d\n", (int)mesh->vertex_count);
  for (int32_t v = 0; v < mesh->vertex_count; ++v) {
    piola__format_double(a, mesh->positions[3 * v]);
    piola__format_double(b, mesh->positions[3 * v + 1]);
    piola__format_double(c, mesh->positions[3 * v + 2]);
    fprintf(o, "%s %s %s 0\n", a, b, c);
  }
  fprintf(o, "Tetrahedra\n%d\n", (int)mesh->tet_count);
  for (int32_t t = 0; t < mesh->tet_count; ++t) {
    const int32_t *q = mesh->tets + 4 * (size_t)t;
    fprintf(o, "%d %d %d %d %d\n", q[0] + 1, q[1] + 1, q[2] + 1, q[3] + 1,
            mesh->tet_regions ? (int)mesh->tet_regions[t] : 0);
  }
  fprintf(o, "End\n");
  return atomic_file_commit(&f);
}
