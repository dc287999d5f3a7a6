/* libFuzzer target: the .off surface reader on arbitrary bytes must return a status,
 * never crash, leak or read out of bounds; an accepted surface has indices in range. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "io/mesh_io_internal.h"
#include "piola/mesh_quality.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  piola_tri_mesh mesh;
  if (piola__read_off_mem("fuzz.off", (const char *)data, size, &mesh) == PIOLA_OK) {
    piola_surface_topology topo;
    if (piola_tri_mesh_topology(&mesh, &topo) != PIOLA_OK) abort();
    piola_tri_mesh_free(&mesh);
  }
  return 0;
}
