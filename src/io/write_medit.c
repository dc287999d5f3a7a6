/* Medit .mesh writer (ASCII, version 2; tet ref = region, 0 without regions). */
#include <stdlib.h>

#include "common/status_report.h"
#include "io/mesh_writers.h"
#include "io/text_writer.h"
#include "piola/files.h"

piola_status piola__write_medit(const char *path, const piola_tet_mesh *mesh) {
  text_writer *w = malloc(sizeof *w);
  if (!w) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
  piola_atomic_file f;
  piola_status s = piola_atomic_file_open(&f, path);
  if (s != PIOLA_OK) {
    free(w);
    return s;
  }
  piola__tw_init(w, f.stream);
  piola__tw_str(w, "MeshVersionFormatted 2\nDimension 3\nVertices\n");
  piola__tw_int(w, mesh->vertex_count);
  piola__tw_char(w, '\n');
  for (int32_t v = 0; v < mesh->vertex_count; ++v) {
    for (int k = 0; k < 3; ++k) {
      piola__tw_double(w, mesh->positions[3 * (size_t)v + (size_t)k]);
      piola__tw_char(w, ' ');
    }
    piola__tw_str(w, "0\n");
  }
  piola__tw_str(w, "Tetrahedra\n");
  piola__tw_int(w, mesh->tet_count);
  piola__tw_char(w, '\n');
  for (int32_t t = 0; t < mesh->tet_count; ++t) {
    const int32_t *q = mesh->tets + 4 * (size_t)t;
    for (int k = 0; k < 4; ++k) {
      piola__tw_int(w, (int64_t)q[k] + 1);
      piola__tw_char(w, ' ');
    }
    piola__tw_int(w, mesh->tet_regions ? mesh->tet_regions[t] : 0);
    piola__tw_char(w, '\n');
  }
  piola__tw_str(w, "End\n");
  piola__tw_flush(w);
  free(w);
  return piola_atomic_file_commit(&f);
}
