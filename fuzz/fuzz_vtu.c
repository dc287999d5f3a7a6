/* libFuzzer target: the .vtu reader on arbitrary bytes must return a status, never crash,
 * leak or read out of bounds. What piola_vtu_read accepts must be consistent (indices in
 * range, cell indices increasing and below the cell count, fields allocated); an accepted
 * tet mesh must be valid and positively oriented. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "io/mesh_io_internal.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_cells(const int32_t *v, const int32_t *cells, int32_t count, int corners,
                        const piola_vtu_data *d) {
  for (int32_t i = 0; i < count; ++i) {
    for (int k = 0; k < corners; ++k)
      if (v[corners * (size_t)i + (size_t)k] < 0 ||
          v[corners * (size_t)i + (size_t)k] >= d->point_count)
        abort();
    if (cells[i] < 0 || cells[i] >= d->cell_count || (i > 0 && cells[i] <= cells[i - 1])) abort();
  }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  piola_tet_mesh mesh;
  if (piola__read_vtu_mem("fuzz.vtu", (const char *)data, size, &mesh) == PIOLA_OK) {
    if (piola_tet_mesh_validate(&mesh) != PIOLA_OK) abort();
    for (int32_t t = 0; t < mesh.tet_count; ++t)
      if (!(piola_tet_mesh_signed_volume(&mesh, t) > 0)) abort();
    piola_tet_mesh_free(&mesh);
  }
  piola_vtu_data d;
  if (piola__vtu_read_mem("fuzz.vtu", (const char *)data, size, &d) == PIOLA_OK) {
    check_cells(d.tets, d.tet_cells, d.tet_count, 4, &d);
    check_cells(d.triangles, d.triangle_cells, d.triangle_count, 3, &d);
    volatile double sum = 0;
    for (int32_t i = 0; i < d.point_field_count; ++i) /* the last value is there (ASan) */
      if (d.point_count > 0)
        sum += d.point_fields[i]
                   .values[(size_t)d.point_fields[i].components * (size_t)d.point_count - 1];
    for (int32_t i = 0; i < d.cell_field_count; ++i)
      if (d.cell_count > 0)
        sum +=
            d.cell_fields[i].values[(size_t)d.cell_fields[i].components * (size_t)d.cell_count - 1];
    (void)sum;
    piola_vtu_data_free(&d);
  }
  return 0;
}
