#include "mesher/bcc_lattice.h"

#include <math.h>
#include <stdlib.h>

#include "common/status_report.h"
#include "mesher/tet_topology.h"

void piola__bcc_lattice_free(piola__bcc_lattice *lattice) {
  free(lattice->positions);
  free(lattice->tets);
  lattice->positions = NULL;
  lattice->tets = NULL;
  lattice->vertex_count = lattice->tet_count = 0;
}

piola_status piola__bcc_lattice_build(vec3 lo, vec3 hi, double cell_size, int64_t max_tets,
                                      piola__bcc_lattice *out) {
  *out = (piola__bcc_lattice){0};
  if (!(cell_size > 0) || !isfinite(cell_size))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "mesher: cell_size must be > 0 m, got %g",
                      cell_size);
  double span[3] = {hi.x - lo.x, hi.y - lo.y, hi.z - lo.z};
  int64_t n[3];
  for (int d = 0; d < 3; ++d) {
    double cells = ceil(span[d] / cell_size);
    if (!(cells >= 1)) cells = 1;
    if (cells > 1e6)
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "mesher: cell_size %g m is too small for a shape %g m wide", cell_size,
                        span[d]);
    n[d] = (int64_t)cells;
  }
  int64_t faces = (n[0] - 1) * n[1] * n[2] + n[0] * (n[1] - 1) * n[2] + n[0] * n[1] * (n[2] - 1);
  int64_t tets = 4 * faces;
  int64_t corners = (n[0] + 1) * (n[1] + 1) * (n[2] + 1), centres = n[0] * n[1] * n[2];
  if (tets > max_tets || corners + centres > INT32_MAX / 4)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "mesher: a lattice of %lld x %lld x %lld cells (%lld tets) at cell_size "
                      "%g m exceeds the limit of %lld tets",
                      (long long)n[0], (long long)n[1], (long long)n[2], (long long)tets,
                      cell_size, (long long)max_tets);
  for (int d = 0; d < 3; ++d) out->cells[d] = (int32_t)n[d];
  out->cell_size = cell_size;
  /* Centre the lattice on the box so the margin is the same on both sides. */
  vec3 mid = vec3_scale(vec3_add(lo, hi), 0.5);
  out->origin = vec3_make(mid.x - 0.5 * (double)n[0] * cell_size,
                          mid.y - 0.5 * (double)n[1] * cell_size,
                          mid.z - 0.5 * (double)n[2] * cell_size);
  out->vertex_count = (int32_t)(corners + centres);
  out->tet_count = (int32_t)tets;
  out->positions = malloc((size_t)out->vertex_count * 3 * sizeof(double));
  out->tets = malloc((size_t)tets * 4 * sizeof(int32_t));
  if (!out->positions || !out->tets) {
    piola__bcc_lattice_free(out);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "mesher: lattice of %lld tets", (long long)tets);
  }
  const int64_t nx = n[0], ny = n[1], nz = n[2];
#define CORNER(i, j, k) ((int32_t)((i) + (nx + 1) * ((j) + (ny + 1) * (k))))
#define CENTRE(i, j, k) ((int32_t)(corners + (i) + nx * ((j) + ny * (k))))
  for (int64_t k = 0; k <= nz; ++k)
    for (int64_t j = 0; j <= ny; ++j)
      for (int64_t i = 0; i <= nx; ++i)
        vec3_store(out->positions + 3 * (size_t)CORNER(i, j, k),
                   vec3_make(out->origin.x + (double)i * cell_size,
                             out->origin.y + (double)j * cell_size,
                             out->origin.z + (double)k * cell_size));
  for (int64_t k = 0; k < nz; ++k)
    for (int64_t j = 0; j < ny; ++j)
      for (int64_t i = 0; i < nx; ++i)
        vec3_store(out->positions + 3 * (size_t)CENTRE(i, j, k),
                   vec3_make(out->origin.x + ((double)i + 0.5) * cell_size,
                             out->origin.y + ((double)j + 0.5) * cell_size,
                             out->origin.z + ((double)k + 0.5) * cell_size));
  int64_t t = 0;
  for (int64_t k = 0; k < nz; ++k)
    for (int64_t j = 0; j < ny; ++j)
      for (int64_t i = 0; i < nx; ++i)
        for (int d = 0; d < 3; ++d) {
          int64_t c[3] = {i, j, k};
          if (c[d] + 1 >= n[d]) continue;
          int32_t c1 = CENTRE(i, j, k);
          c[d] += 1;
          int32_t c2 = CENTRE(c[0], c[1], c[2]);
          /* The shared face lies at corner index c[d] along d; walk its 4 corners. */
          int e1 = (d + 1) % 3, e2 = (d + 2) % 3;
          int64_t q[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
          int32_t face[4];
          for (int m = 0; m < 4; ++m) {
            int64_t p[3];
            p[d] = c[d];
            p[e1] = (e1 == 0 ? i : e1 == 1 ? j : k) + q[m][0];
            p[e2] = (e2 == 0 ? i : e2 == 1 ? j : k) + q[m][1];
            face[m] = CORNER(p[0], p[1], p[2]);
          }
          for (int m = 0; m < 4; ++m) {
            int32_t *tet = out->tets + 4 * (size_t)t++;
            tet[0] = c1;
            tet[1] = c2;
            tet[2] = face[m];
            tet[3] = face[(m + 1) % 4];
            vec3 x0 = vec3_load(out->positions + 3 * (size_t)tet[0]);
            vec3 x1 = vec3_load(out->positions + 3 * (size_t)tet[1]);
            vec3 x2 = vec3_load(out->positions + 3 * (size_t)tet[2]);
            vec3 x3 = vec3_load(out->positions + 3 * (size_t)tet[3]);
            if (piola__tet_volume(x0, x1, x2, x3) < 0) {
              tet[2] = face[(m + 1) % 4];
              tet[3] = face[m];
            }
          }
        }
#undef CORNER
#undef CENTRE
  return PIOLA_OK;
}
