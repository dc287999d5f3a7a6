/* TetGen writer: path.node and path.ele (1-based; the region as one element attribute). */
#include <stdlib.h>
#include <string.h>

#include "common/status_internal.h"
#include "io/atomic_file.h"
#include "io/mesh_writers.h"

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
  atomic_file f;
  piola_status s = atomic_file_open(&f, node_path);
  if (s == PIOLA_OK) {
    char a[32], b[32], c[32];
    fprintf(f.stream, "%d 3 0 0\n", (int)mesh->vertex_count);
    for (int32_t v = 0; v < mesh->vertex_count; ++v) {
      piola__format_double(a, mesh->positions[3 * v]);
      piola__format_double(b, mesh->positions[3 * v + 1]);
      piola__format_double(c, mesh->positions[3 * v + 2]);
      fprintf(f.stream, "%d %s %s %s\n", (int)v + 1, a, b, c);
    }
    fprintf(f.stream, "# written by piola\n");
    s = atomic_file_commit(&f);
  }
  if (s == PIOLA_OK) s = atomic_file_open(&f, ele_path);
  if (s == PIOLA_OK) {
    int attr = mesh->tet_regions != NULL;
    fprintf(f.stream, "%d 4 %d\n", (int)mesh->tet_count, attr);
    for (int32_t t = 0; t < mesh->tet_count; ++t) {
      const int32_t *q = mesh->tets + 4 * (size_t)t;
      fprintf(f.stream, "%d %d %d %d %d", (int)t + 1, q[0] + 1, q[1] + 1, q[2] + 1, q[3] + 1);
      if (attr) fprintf(f.stream, " %d", (int)mesh->tet_regions[t]);
      fputc('\n', f.stream);
    }
    fprintf(f.stream, "# written by piola\n");
    s = atomic_file_commit(&f);
  }
  free(node_path);
  free(ele_path);
  return s;
}
