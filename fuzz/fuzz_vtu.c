/* libFuzzer target: the .vtu reader on arbitrary bytes must return a status, never crash,
 * leak or read out of bounds; an accepted mesh must be valid and positively oriented. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "io/mesh_io_internal.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  piola_tet_mesh mesh;
  if (piola__read_vtu_mem("fuzz.vtu", (const char *)data, size, &mesh) == PIOLA_OK) {
    if (piola_tet_mesh_validate(&mesh) != PIOLA_OK) abort();
    for (int32_t t = 0; t < mesh.tet_count; ++t)
      if (!(piola_tet_mesh_signed_volume(&mesh, t) > 0)) abort();
    piola_tet_mesh_free(&mesh);
  }
  return 0;
}
