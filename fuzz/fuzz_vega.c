/* libFuzzer target: the .veg reader on arbitrary bytes must return a status, never crash,
 * leak or read out of bounds; an accepted mesh must be valid with regions in range. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "io/mesh_io_internal.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  piola_tet_mesh mesh;
  piola_vega_material *materials = NULL;
  int32_t count = 0;
  if (piola__read_vega_mem("fuzz.veg", (const char *)data, size, &mesh, &materials, &count) == PIOLA_OK) {
    if (piola_tet_mesh_validate(&mesh) != PIOLA_OK) abort();
    for (int32_t t = 0; t < mesh.tet_count; ++t)
      if (mesh.tet_regions[t] < -1 || mesh.tet_regions[t] >= count) abort();
    free(materials);
    piola_tet_mesh_free(&mesh);
  }
  return 0;
}
