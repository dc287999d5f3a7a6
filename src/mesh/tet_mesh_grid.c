/* Structured box meshes of 6 tets per cell (see piola_tet_mesh_box_grid in mesh.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "piola/mesh.h"

piola_status piola_tet_mesh_box_grid(int32_t nx, int32_t ny, int32_t nz, piola_vec3 spacing,
                                     piola_tet_mesh *out) {
  if (!out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "box grid: out is NULL");
  memset(out, 0, sizeof *out);
  if (nx < 1 || ny < 1 || nz < 1)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "box grid: cell counts must be >= 1, got %d x %d x %d",
                      (int)nx, (int)ny, (int)nz);
  if (!(spacing.x > 0) || !(spacing.y > 0) || !(spacing.z > 0) || !isfinite(spacing.x) ||
      !isfinite(spacing.y) || !isfinite(spacing.z))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "box grid: spacing must be finite and > 0 m");
  int64_t cells = (int64_t)nx * ny * nz, vertices = (int64_t)(nx + 1) * (ny + 1) * (nz + 1);
  if (6 * cells > INT32_MAX / 4 || vertices > INT32_MAX / 3)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "box grid: %d x %d x %d cells is too many",
                      (int)nx, (int)ny, (int)nz);
  out->positions = malloc(sizeof(double) * 3 * (size_t)vertices);
  out->tets = malloc(sizeof(int32_t) * 4 * 6 * (size_t)cells);
  if (!out->positions || !out->tets) {
    piola_tet_mesh_free(out);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "box grid: out of memory");
  }
  out->vertex_count = (int32_t)vertices;
  out->tet_count = (int32_t)(6 * cells);
#define VERTEX(i, j, k) ((i) + (nx + 1) * ((j) + (ny + 1) * (k)))
  for (int32_t k = 0; k <= nz; ++k)
    for (int32_t j = 0; j <= ny; ++j)
      for (int32_t i = 0; i <= nx; ++i) {
        double *p = out->positions + 3 * VERTEX(i, j, k);
        p[0] = i * spacing.x, p[1] = j * spacing.y, p[2] = k * spacing.z;
      }
  /* The 6 monotone paths from a cell's corner (0,0,0) to (1,1,1), one axis step at a time:
   * each path's 4 corners are a tet, and together they fill the cell conformingly. */
  static const int paths[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  int32_t *tet = out->tets;
  for (int32_t k = 0; k < nz; ++k)
    for (int32_t j = 0; j < ny; ++j)
      for (int32_t i = 0; i < nx; ++i)
        for (int p = 0; p < 6; ++p, tet += 4) {
          int32_t c[3] = {i, j, k};
          tet[0] = VERTEX(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            c[paths[p][s]]++;
            tet[s + 1] = VERTEX(c[0], c[1], c[2]);
          }
        }
#undef VERTEX
  return PIOLA_OK;
}
