/* TetGen writer: path.node and path.ele (1-based; the region as one element attribute). */
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "io/mesh_writers.h"
#include "io/text_writer.h"
#include "piola/files.h"

piola_status piola__write_tetgen(const char *path, const piola_tet_mesh *mesh) {
  size_t n = strlen(path);
  const char *dot = strrchr(path, '.');
  size_t stem = dot ? (size_t)(dot - path) : n;
  char *node_path = malloc(stem + 8), *ele_path = malloc(stem + 8);
  if (!node_path || !ele_path) {
    free(node_path);
    free(ele_path);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
  }
  memcpy(node_path, path, stem);
  memcpy(ele_path, path, stem);
  strcpy(node_path + stem, ".node");
  strcpy(ele_path + stem, ".ele");
  text_writer *w = malloc(sizeof *w);
  piola_atomic_file f;
  piola_status s = w ? piola_atomic_file_open(&f, node_path) : PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
  if (s == PIOLA_OK) {
    fprintf(f.stream, "%d 3 0 0\n", (int)mesh->vertex_count);
    piola__tw_init(w, f.stream);
    for (int32_t v = 0; v < mesh->vertex_count; ++v) {
      piola__tw_int(w, (int64_t)v + 1);
      for (int k = 0; k < 3; ++k) {
        piola__tw_char(w, ' ');
        piola__tw_double(w, mesh->positions[3 * (size_t)v + (size_t)k]);
      }
      piola__tw_char(w, '\n');
    }
    piola__tw_str(w, "# written by piola\n");
    piola__tw_flush(w);
    s = piola_atomic_file_commit(&f);
  }
  if (s == PIOLA_OK) s = piola_atomic_file_open(&f, ele_path);
  if (s == PIOLA_OK) {
    int attr = mesh->tet_regions != NULL;
    fprintf(f.stream, "%d 4 %d\n", (int)mesh->tet_count, attr);
    piola__tw_init(w, f.stream);
    for (int32_t t = 0; t < mesh->tet_count; ++t) {
      const int32_t *q = mesh->tets + 4 * (size_t)t;
      piola__tw_int(w, (int64_t)t + 1);
      for (int k = 0; k < 4; ++k) {
        piola__tw_char(w, ' ');
        piola__tw_int(w, (int64_t)q[k] + 1);
      }
      if (attr) {
        piola__tw_char(w, ' ');
        piola__tw_int(w, mesh->tet_regions[t]);
      }
      piola__tw_char(w, '\n');
    }
    piola__tw_str(w, "# written by piola\n");
    piola__tw_flush(w);
    s = piola_atomic_file_commit(&f);
  }
  free(w);
  free(node_path);
  free(ele_path);
  return s;
}
