#include "mesher/lattice_phi.h"

#include <math.h>
#include <stdlib.h>

#include "common/status_report.h"
#include "piola/threads.h"

static int32_t find_root(int32_t *parent, int32_t v) {
  while (parent[v] != v) {
    parent[v] = parent[parent[v]];
    v = parent[v];
  }
  return v;
}

piola_status piola__lattice_phi(const piola__shape_union *shapes, const double *positions,
                                int32_t vertex_count, const int32_t *tets, int32_t tet_count,
                                double band, double *phi) {
#pragma omp parallel for schedule(static) num_threads(piola_thread_count())
  for (int32_t v = 0; v < vertex_count; ++v)
    phi[v] = piola__shape_union_phi_analytic(shapes, vec3_load(positions + 3 * (size_t)v));
  int32_t *parent = NULL;
  double *value = NULL;
  for (int i = 0; i < shapes->count; ++i) {
    if (shapes->shapes[i].type != PIOLA_SHAPE_SURFACE) continue;
    const piola__surface_distance *s = shapes->surfaces[i];
    if (!parent) {
      parent = malloc((size_t)vertex_count * sizeof(int32_t));
      value = malloc((size_t)vertex_count * sizeof(double));
      if (!parent || !value) {
        free(parent);
        free(value);
        return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "mesher: level set of a surface");
      }
    }
    /* value = signed distance in the band, NAN beyond it (sign to be found). */
#pragma omp parallel for schedule(dynamic, 1024) num_threads(piola_thread_count())
    for (int32_t v = 0; v < vertex_count; ++v) {
      vec3 p = vec3_load(positions + 3 * (size_t)v);
      double d = piola__surface_closest_point_within(s, p, band, NULL, NULL);
      if (d < band)
        value[v] = piola__surface_winding_number(s, p) > 0.5 ? -d : d;
      else
        value[v] = NAN;
      parent[v] = v;
    }
    for (int32_t t = 0; t < tet_count; ++t) {
      const int32_t *tet = tets + 4 * (size_t)t;
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b) {
          if (!isnan(value[tet[a]]) || !isnan(value[tet[b]])) continue;
          int32_t ra = find_root(parent, tet[a]), rb = find_root(parent, tet[b]);
          if (ra != rb) parent[ra < rb ? rb : ra] = ra < rb ? ra : rb;
        }
    }
    /* One winding number per far component, at its root. */
#pragma omp parallel for schedule(dynamic, 64) num_threads(piola_thread_count())
    for (int32_t v = 0; v < vertex_count; ++v)
      if (isnan(value[v]) && parent[v] == v)
        value[v] = piola__surface_winding_number(s, vec3_load(positions + 3 * (size_t)v)) > 0.5 ? -band : band;
    for (int32_t v = 0; v < vertex_count; ++v) {
      if (isnan(value[v])) value[v] = value[find_root(parent, v)];
      if (value[v] < phi[v]) phi[v] = value[v];
    }
  }
  free(parent);
  free(value);
  return PIOLA_OK;
}
