/* libFuzzer target: TetGen .node + .ele. The input holds the .node text, a line "%%", then
 * the .ele text; without the marker it is tried as .node (with a fixed .ele) and as .ele
 * (with a fixed .node). Must return a status, never crash, leak or read out of bounds. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "io/mesh_io_internal.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check(piola_status s, piola_tet_mesh *mesh) {
  if (s != PIOLA_OK) return;
  if (piola_tet_mesh_validate(mesh) != PIOLA_OK) abort();
  for (int32_t t = 0; t < mesh->tet_count; ++t)
    if (!(piola_tet_mesh_signed_volume(mesh, t) > 0)) abort();
  piola_tet_mesh_free(mesh);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const char *text = (const char *)data;
  piola_tet_mesh mesh;
  for (size_t i = 0; i + 2 <= size; ++i) {
    if (text[i] == '%' && text[i + 1] == '%') {
      check(piola__read_tetgen_mem("fuzz.node", text, i, "fuzz.ele", text + i + 2, size - i - 2, &mesh), &mesh);
      return 0;
    }
  }
  static const char node[] = "5 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n";
  static const char ele[] = "2 4 1\n1 1 2 3 4 7\n2 2 3 4 5 8\n";
  check(piola__read_tetgen_mem("fuzz.node", text, size, "fixed.ele", ele, sizeof ele - 1, &mesh), &mesh);
  check(piola__read_tetgen_mem("fixed.node", node, sizeof node - 1, "fuzz.ele", text, size, &mesh), &mesh);
  return 0;
}
