#include "mesher/boundary_snap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "mesher/tet_topology.h"
#include "piola/threads.h"

typedef struct snap_context {
  piola_tet_mesh *mesh;
  piola__csr vertex_tets;
  double guard_cosine; /* cosine of the guard angle */
} snap_context;

/* Cosine of the worst (smallest) dihedral angle of the tets around v, with v placed at x:
 * larger is worse, 2 means a tet is inverted or flat. */
static double worst_cosine_around(const snap_context *c, int32_t v, vec3 x) {
  double worst = -1;
  const double *p = c->mesh->positions;
  for (int32_t i = c->vertex_tets.offsets[v]; i < c->vertex_tets.offsets[v + 1]; ++i) {
    const int32_t *tet = c->mesh->tets + 4 * (size_t)c->vertex_tets.items[i];
    vec3 y[4];
    for (int k = 0; k < 4; ++k) y[k] = tet[k] == v ? x : vec3_load(p + 3 * (size_t)tet[k]);
    double a = piola__tet_min_dihedral_cosine(y[0], y[1], y[2], y[3]);
    if (a > worst) worst = a;
    if (worst > 1) break;
  }
  return worst;
}

/* Moves v toward goal by the largest fraction in 1, 1/2, ..., 1/16 that keeps the tets
 * around it at or above the guard (or not worse than now). Returns 1 if it moved. */
static int guarded_move(snap_context *c, int32_t v, vec3 goal, int require_improvement) {
  vec3 x = vec3_load(c->mesh->positions + 3 * (size_t)v);
  double now = worst_cosine_around(c, v, x);
  double need = require_improvement ? now : fmax(now, c->guard_cosine);
  double fraction = 1.0;
  for (int attempt = 0; attempt < 5; ++attempt, fraction *= 0.5) {
    vec3 y = vec3_add(x, vec3_scale(vec3_sub(goal, x), fraction));
    double after = worst_cosine_around(c, v, y);
    if (after <= need && (!require_improvement || after < now - 1e-12)) {
      vec3_store(c->mesh->positions + 3 * (size_t)v, y);
      return 1;
    }
  }
  return 0;
}

/* Moves each listed node toward the mean of its neighbours (of class `ring`, or all when
 * ring is 0) when that raises the worst angle around it; on_surface re-projects the goal so
 * boundary nodes slide along the surface. */
static void smooth(snap_context *c, const int32_t *list, int32_t count, const uint8_t *ring_of,
                   int ring, const piola__shape_union *on_surface) {
  const double *p = c->mesh->positions;
  for (int32_t i = 0; i < count; ++i) {
    int32_t v = list[i];
    vec3 sum = {0, 0, 0};
    int n = 0;
    for (int32_t j = c->vertex_tets.offsets[v]; j < c->vertex_tets.offsets[v + 1]; ++j) {
      const int32_t *tet = c->mesh->tets + 4 * (size_t)c->vertex_tets.items[j];
      for (int k = 0; k < 4; ++k)
        if (tet[k] != v && (ring == 0 || ring_of[tet[k]] == ring)) {
          sum = vec3_add(sum, vec3_load(p + 3 * (size_t)tet[k]));
          n++;
        }
    }
    if (n == 0) continue;
    vec3 goal = vec3_scale(sum, 1.0 / n);
    if (on_surface) goal = piola__shape_union_project(on_surface, goal);
    guarded_move(c, v, goal, 1);
  }
}

piola_status piola__boundary_snap(piola_tet_mesh *mesh, const piola__shape_union *shapes,
                                  double h) {
  snap_context c = {.mesh = mesh, .guard_cosine = cos(PIOLA__SNAP_MIN_DIHEDRAL_DEG * M_PI / 180.0)};
  int32_t nv = mesh->vertex_count, nt = mesh->tet_count;
  PIOLA_TRY(piola__vertex_tets(nv, mesh->tets, nt, NULL, &c.vertex_tets));
  int32_t *neighbor = malloc((size_t)nt * 4 * sizeof(int32_t));
  uint8_t *ring = calloc((size_t)nv + 1, 1); /* 1 boundary, 2 next to the boundary */
  int32_t *boundary = malloc(((size_t)nv + 1) * sizeof(int32_t));
  int32_t *inner = malloc(((size_t)nv + 1) * sizeof(int32_t));
  vec3 *target = malloc(((size_t)nv + 1) * sizeof(vec3));
  if (!neighbor || !ring || !boundary || !inner || !target) {
    free(neighbor);
    free(ring);
    free(boundary);
    free(inner);
    free(target);
    piola__csr_free(&c.vertex_tets);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "mesher: snapping");
  }
  piola__face_neighbors(mesh->tets, nt, NULL, &c.vertex_tets, neighbor);
  for (int32_t t = 0; t < nt; ++t)
    for (int f = 0; f < 4; ++f)
      if (neighbor[4 * t + f] == -1)
        for (int k = 0; k < 3; ++k) ring[mesh->tets[4 * t + piola__tet_face[f][k]]] = 1;
  for (int32_t t = 0; t < nt; ++t) {
    int touches = 0;
    for (int k = 0; k < 4; ++k) touches |= ring[mesh->tets[4 * t + k]] == 1;
    if (touches)
      for (int k = 0; k < 4; ++k)
        if (ring[mesh->tets[4 * t + k]] == 0) ring[mesh->tets[4 * t + k]] = 2;
  }
  int32_t nb = 0, ni = 0;
  for (int32_t v = 0; v < nv; ++v) {
    if (ring[v] == 1) boundary[nb++] = v;
    if (ring[v] == 2) inner[ni++] = v;
  }
  const double remaining[] = {0.25, 1.0 / 3.0, 0.5, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0};
  for (size_t stage = 0; stage < sizeof(remaining) / sizeof(remaining[0]); ++stage) {
#pragma omp parallel for schedule(dynamic, 256) num_threads(piola_thread_count())
    for (int32_t i = 0; i < nb; ++i)
      target[i] = piola__shape_union_project(shapes, vec3_load(mesh->positions + 3 * (size_t)boundary[i]));
    for (int32_t i = 0; i < nb; ++i) {
      vec3 x = vec3_load(mesh->positions + 3 * (size_t)boundary[i]);
      if (vec3_norm2(vec3_sub(target[i], x)) < 1e-20 * h * h) continue; /* already there */
      guarded_move(&c, boundary[i], vec3_add(x, vec3_scale(vec3_sub(target[i], x), remaining[stage])), 0);
    }
    smooth(&c, inner, ni, ring, 0, NULL);
    if (stage >= 3) smooth(&c, boundary, nb, ring, 1, shapes);
  }
  free(neighbor);
  free(ring);
  free(boundary);
  free(inner);
  free(target);
  piola__csr_free(&c.vertex_tets);
  return PIOLA_OK;
}
