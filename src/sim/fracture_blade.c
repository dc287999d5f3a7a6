/* Moving blades: a scripted cut by a triangle surface that translates over time and cuts
 * the solid progressively (docs/fracture.md, "A moving blade").
 *
 * Before each step the blade cuts by its surface at the step's start time together with
 * the band its border swept since its last cut (each border edge joined to its position
 * then by two triangles): a blade that moves more than a tet per step still cuts every tet
 * it went through. All its cuts grow one crack: a vertex that crack reached keeps its value
 * there (piola__fracture_surface_cut), so neighbouring tets cut at different steps compute
 * the same crossing on their shared edges and the crack is one surface, as if it had been
 * cut at once. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "sim/fracture_internal.h"
#include "sim/world_internal.h"

int piola__fracture_cut_moves(const piola_fracture_cut *c) { return c->blade && c->end_time > c->time; }

piola_status piola__fracture_check_motion(const piola_fracture_cut *c, const char *name, int32_t index) {
  const double v[3] = {c->velocity.x, c->velocity.y, c->velocity.z};
  if (!isfinite(c->end_time) || !isfinite(v[0]) || !isfinite(v[1]) || !isfinite(v[2]))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "fracture of '%s': cut %d: end_time or velocity is not finite",
                      name, (int)index);
  if (c->end_time > c->time && !c->blade)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "fracture of '%s': cut %d: only a blade (a triangle surface) moves (end_time > time)", name,
                      (int)index);
  if (!(c->end_time > c->time) && (v[0] != 0 || v[1] != 0 || v[2] != 0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "fracture of '%s': cut %d: a velocity needs end_time > time",
                      name, (int)index);
  return PIOLA_OK;
}

typedef struct blade_edge {
  int32_t lo, hi; /* vertex ids, lo < hi */
  int32_t triangle, corner; /* the edge runs from corner to corner + 1 of triangle */
} blade_edge;

static int by_vertices(const void *pa, const void *pb) {
  const blade_edge *a = pa, *b = pb;
  if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
  return a->hi < b->hi ? -1 : a->hi > b->hi;
}

static void sub3(const double *a, const double *b, double out[3]) {
  for (int k = 0; k < 3; ++k) out[k] = a[k] - b[k];
}
static void cross3(const double *a, const double *b, double out[3]) {
  out[0] = a[1] * b[2] - a[2] * b[1], out[1] = a[2] * b[0] - a[0] * b[2], out[2] = a[0] * b[1] - a[1] * b[0];
}

/* The surface that blade c cuts by when it moves from its position at time `from` to the one
 * at `to` (s): the blade at `to` and, when it moved, the band its border edges swept, each
 * band triangle oriented like the blade triangle of its edge. Freed by the caller. */
static piola_status swept_surface(const piola_fracture_cut *c, double from, double to, piola_tri_mesh *out) {
  const piola_tri_mesh *blade = c->blade;
  const int32_t nv = blade->vertex_count, nt = blade->triangle_count;
  const double v[3] = {c->velocity.x, c->velocity.y, c->velocity.z};
  const int moved = to > from && (v[0] != 0 || v[1] != 0 || v[2] != 0);
  blade_edge *edges = malloc(sizeof *edges * 3 * (size_t)nt);
  memset(out, 0, sizeof *out);
  out->positions = malloc(3 * sizeof(double) * 2 * (size_t)nv);
  out->triangles = malloc(3 * sizeof(int32_t) * 7 * (size_t)nt); /* nt + 2 per border edge (3 nt at most) */
  if (!edges || !out->positions || !out->triangles) {
    free(edges);
    piola_tri_mesh_free(out);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "moving blade: out of memory");
  }
  /* vertices 0 .. nv-1 at `to`, nv .. 2 nv - 1 at `from` */
  for (int32_t i = 0; i < nv; ++i)
    for (int k = 0; k < 3; ++k) {
      out->positions[3 * i + k] = blade->positions[3 * i + k] + v[k] * (to - c->time);
      out->positions[3 * (nv + i) + k] = blade->positions[3 * i + k] + v[k] * (from - c->time);
    }
  out->vertex_count = moved ? 2 * nv : nv;
  memcpy(out->triangles, blade->triangles, 3 * sizeof(int32_t) * (size_t)nt);
  out->triangle_count = nt;
  if (moved) {
    for (int32_t t = 0; t < nt; ++t)
      for (int k = 0; k < 3; ++k) {
        const int32_t a = blade->triangles[3 * t + k], b = blade->triangles[3 * t + (k + 1) % 3];
        edges[3 * t + k] = (blade_edge){a < b ? a : b, a < b ? b : a, t, k};
      }
    qsort(edges, 3 * (size_t)nt, sizeof *edges, by_vertices);
    for (int32_t i = 0; i < 3 * nt;) {
      int32_t j = i + 1;
      while (j < 3 * nt && !by_vertices(&edges[i], &edges[j])) ++j;
      if (j - i == 1) { /* a border edge: used by one triangle */
        const int32_t *tri = blade->triangles + 3 * edges[i].triangle;
        const int32_t a = tri[edges[i].corner], b = tri[(edges[i].corner + 1) % 3];
        int32_t quad[4] = {nv + a, nv + b, b, a};
        double e1[3], e2[3], n_blade[3], n_band[3];
        const double *p = out->positions;
        sub3(p + 3 * tri[1], p + 3 * tri[0], e1), sub3(p + 3 * tri[2], p + 3 * tri[0], e2), cross3(e1, e2, n_blade);
        sub3(p + 3 * quad[1], p + 3 * quad[0], e1), sub3(p + 3 * quad[2], p + 3 * quad[0], e2), cross3(e1, e2, n_band);
        if (n_blade[0] * n_band[0] + n_blade[1] * n_band[1] + n_blade[2] * n_band[2] < 0) {
          int32_t swap = quad[1];
          quad[1] = quad[3], quad[3] = swap;
        }
        int32_t *o = out->triangles + 3 * out->triangle_count;
        o[0] = quad[0], o[1] = quad[1], o[2] = quad[2], o[3] = quad[0], o[4] = quad[2], o[5] = quad[3];
        out->triangle_count += 2;
      }
      i = j;
    }
  }
  free(edges);
  return PIOLA_OK;
}

/* One cut of moving blade i: from its position at `from` to the one at the current step's
 * start (end_time at the latest). */
static piola_status blade_cut(piola_world *w, world_body *b, int32_t i, double from) {
  solid_fracture *f = b->fracture;
  const piola_fracture_cut *c = &f->cuts[i];
  const double to = fmin(w->time, c->end_time);
  piola_tri_mesh surface;
  PIOLA_TRY(swept_surface(c, from, to, &surface));
  int32_t count = 0;
  piola_status st = piola__fracture_surface_cut(w, b, &surface, f->sweep_crack[i], &count);
  piola_tri_mesh_free(&surface);
  b->fracture->swept_to[i] = to;
  return st;
}

piola_status piola__fracture_blade_start(piola_world *w, world_body *b, int32_t i) {
  solid_fracture *f = b->fracture;
  f->sweep_crack[i] = f->events++;
  /* from its start position: a blade started late still cuts all it went through */
  return blade_cut(w, b, i, f->cuts[i].time);
}

piola_status piola__fracture_blades_sweep(piola_world *w, world_body *b) {
  for (int32_t i = 0; i < b->fracture->next_cut; ++i) {
    const solid_fracture *f = b->fracture;
    if (f->sweep_crack[i] < 0 || !(f->swept_to[i] < f->cuts[i].end_time) || !(f->swept_to[i] < w->time)) continue;
    PIOLA_TRY(blade_cut(w, b, i, f->swept_to[i]));
  }
  return PIOLA_OK;
}
