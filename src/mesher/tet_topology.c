#include "mesher/tet_topology.h"

#include <math.h>
#include <stdlib.h>

#include "common/status_report.h"
#include "piola/threads.h"

const int piola__tet_face[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};

void piola__csr_free(piola__csr *csr) {
  free(csr->offsets);
  free(csr->items);
  csr->offsets = NULL;
  csr->items = NULL;
  csr->rows = 0;
}

piola_status piola__vertex_tets(int32_t vertex_count, const int32_t *tets, int32_t tet_count,
                                const uint8_t *keep, piola__csr *out) {
  out->rows = vertex_count;
  out->offsets = calloc((size_t)vertex_count + 1, sizeof(int32_t));
  if (!out->offsets) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "mesher: vertex-tet table");
  for (int32_t t = 0; t < tet_count; ++t) {
    if (keep && !keep[t]) continue;
    for (int k = 0; k < 4; ++k) out->offsets[tets[4 * t + k] + 1]++;
  }
  for (int32_t v = 0; v < vertex_count; ++v) out->offsets[v + 1] += out->offsets[v];
  out->items = malloc(((size_t)out->offsets[vertex_count] + 1) * sizeof(int32_t));
  int32_t *fill = malloc(((size_t)vertex_count + 1) * sizeof(int32_t));
  if (!out->items || !fill) {
    free(fill);
    piola__csr_free(out);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "mesher: vertex-tet table");
  }
  for (int32_t v = 0; v < vertex_count; ++v) fill[v] = out->offsets[v];
  for (int32_t t = 0; t < tet_count; ++t) {
    if (keep && !keep[t]) continue;
    for (int k = 0; k < 4; ++k) out->items[fill[tets[4 * t + k]]++] = t;
  }
  free(fill);
  return PIOLA_OK;
}

static int tet_has(const int32_t *tet, int32_t v) {
  return tet[0] == v || tet[1] == v || tet[2] == v || tet[3] == v;
}

void piola__face_neighbors(const int32_t *tets, int32_t tet_count, const uint8_t *keep,
                           const piola__csr *vertex_tets, int32_t *neighbor) {
#pragma omp parallel for schedule(static) num_threads(piola_thread_count())
  for (int32_t t = 0; t < tet_count; ++t) {
    for (int f = 0; f < 4; ++f) {
      neighbor[4 * t + f] = -1;
      if (keep && !keep[t]) continue;
      int32_t a = tets[4 * t + piola__tet_face[f][0]];
      int32_t b = tets[4 * t + piola__tet_face[f][1]];
      int32_t c = tets[4 * t + piola__tet_face[f][2]];
      int found = -1;
      for (int32_t i = vertex_tets->offsets[a]; i < vertex_tets->offsets[a + 1]; ++i) {
        int32_t u = vertex_tets->items[i];
        if (u == t) continue;
        const int32_t *tu = tets + 4 * (size_t)u;
        if (tet_has(tu, b) && tet_has(tu, c)) {
          found = found == -1 ? u : -2;
        }
      }
      neighbor[4 * t + f] = found;
    }
  }
}

double piola__tet_min_dihedral_cosine(vec3 a, vec3 b, vec3 c, vec3 d) {
  vec3 x[4] = {a, b, c, d};
  if (piola__tet_volume(a, b, c, d) <= 0) return 2.0;
  vec3 n[4];
  for (int f = 0; f < 4; ++f) {
    vec3 p = x[piola__tet_face[f][0]], q = x[piola__tet_face[f][1]], r = x[piola__tet_face[f][2]];
    vec3 m = vec3_cross(vec3_sub(q, p), vec3_sub(r, p));
    double len2 = vec3_norm2(m);
    if (!(len2 > 0)) return 2.0;
    n[f] = vec3_scale(m, 1.0 / sqrt(len2));
  }
  double worst = -1;
  for (int f = 0; f < 4; ++f)
    for (int g = f + 1; g < 4; ++g) {
      double cosine = -vec3_dot(n[f], n[g]);
      worst = cosine > worst ? cosine : worst;
    }
  return worst;
}
