/* The surface of each fragment of a cut solid, at the current positions: the boundary
 * faces of the original mesh clipped to each copy's material, and each cut copy's crack
 * polygon, fanned into triangles. Faces between two tets are never drawn: material on the
 * other side of such a face either touches this copy's (then they are one fragment and
 * the face is inside it) or has zero area there.
 *
 * A point is the same vertex in every copy of a fragment that names it the same way: a
 * corner by its node, a crack crossing by the nodes of its edge and the cut that made it
 * (copies sharing both nodes were cut together, so they computed the same crossing). So
 * each fragment's surface is closed wherever its cuts meet the body's surface through tets
 * cut by the same plane. */
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "sim/fracture_internal.h"
#include "sim/world_internal.h"

typedef struct surface_point {
  int32_t fragment, a, b, event; /* corner: a == b, event -1 */
  double t;
  int32_t order;                 /* position in the emitted list */
} surface_point;

static int by_name(const void *pa, const void *pb) {
  const surface_point *p = pa, *q = pb;
  if (p->fragment != q->fragment) return p->fragment < q->fragment ? -1 : 1;
  if (p->a != q->a) return p->a < q->a ? -1 : 1;
  if (p->b != q->b) return p->b < q->b ? -1 : 1;
  if (p->event != q->event) return p->event < q->event ? -1 : 1;
  return p->order < q->order ? -1 : p->order > q->order;
}

void piola_fracture_surface_free(piola_fracture_surface *s) {
  if (!s) return;
  free(s->positions), free(s->triangles), free(s->fragment_start);
  memset(s, 0, sizeof *s);
}

/* Appends polygon poly of copy c (its points, named, and a record of it). */
static void emit(const solid_fracture *f, const int32_t *nodes, int32_t c, const cut_point *poly,
                 int32_t size, surface_point *points, int32_t *np, int32_t *polygon, int32_t *npoly) {
  if (size < 3) return;
  polygon[2 * *npoly] = *np, polygon[2 * *npoly + 1] = size, ++*npoly;
  for (int32_t i = 0; i < size; ++i) {
    surface_point *p = &points[(*np)++];
    p->fragment = f->fragment[c];
    p->a = nodes[4 * c + poly[i].lo];
    p->b = nodes[4 * c + poly[i].hi];
    p->event = poly[i].lo == poly[i].hi ? -1 : f->event[c];
    p->t = poly[i].t;
  }
}

static int by_edge_name(const void *pa, const void *pb) {
  const surface_point *p = pa, *q = pb;
  if (p->fragment != q->fragment) return p->fragment < q->fragment ? -1 : 1;
  int32_t pl = p->a < p->b ? p->a : p->b, ph = p->a < p->b ? p->b : p->a;
  int32_t ql = q->a < q->b ? q->a : q->b, qh = q->a < q->b ? q->b : q->a;
  if (pl != ql) return pl < ql ? -1 : 1;
  return ph < qh ? -1 : ph > qh;
}

piola_status piola_world_solid_fracture_surface(const piola_world *w, int32_t solid,
                                                piola_fracture_surface *out) {
  if (!out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "fracture surface: NULL argument");
  memset(out, 0, sizeof *out);
  const world_body *b = w ? piola__world_body_of(w, PIOLA_BODY_SOLID, solid) : NULL;
  if (!b || !b->fracture)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "fracture surface: solid %d has no fracture state", (int)solid);
  return piola__fracture_surface_build(b, 0, out, NULL);
}

piola_status piola__fracture_surface_build(const world_body *b, double inset, piola_fracture_surface *out,
                                           fracture_surface_point **where) {
  memset(out, 0, sizeof *out);
  if (where) *where = NULL;
  const solid_fracture *f = b->fracture;
  const int32_t *nodes = piola_elastic_body_tets(b->solid);
  /* at most 4 faces of 4 points and a crack of 4 per copy; a polygon's edge between two
   * corners gains at most one point, so the points at most double */
  const size_t cap = 20 * (size_t)f->copy_count + 1;
  surface_point *raw = malloc(sizeof *raw * cap), *points = malloc(2 * sizeof *points * cap);
  surface_point *crossings = malloc(sizeof *crossings * cap);
  int32_t *polygon = malloc(2 * sizeof(int32_t) * cap);
  int32_t *tri = malloc(3 * sizeof(int32_t) * 2 * cap), *index = malloc(2 * sizeof(int32_t) * cap);
  int32_t *triangle_fragment = malloc(2 * sizeof(int32_t) * cap);
  if (!raw || !points || !crossings || !polygon || !tri || !index || !triangle_fragment) {
    free(raw), free(points), free(crossings), free(polygon), free(tri), free(index), free(triangle_fragment);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fracture surface: out of memory");
  }
  int32_t nraw = 0, npoly = 0;
  for (int32_t c = 0; c < f->copy_count; ++c) {
    const int32_t t = f->parent[c];
    if (f->event[c] < 0) {
      for (int k = 0; k < 4; ++k) {
        if (f->neighbor[4 * t + k] >= 0) continue;
        cut_point face[3];
        for (int i = 0; i < 3; ++i) face[i] = (cut_point){piola__cut_tet_face[k][i], piola__cut_tet_face[k][i], 0};
        emit(f, nodes, c, face, 3, raw, &nraw, polygon, &npoly);
      }
    } else {
      copy_polygons poly;
      double dist[4]; /* inset: the level set side * inset instead of 0 (same edges crossed) */
      for (int k = 0; k < 4; ++k) dist[k] = f->dist[4 * c + k] - f->side[c] * inset;
      piola__fracture_copy_polygons(dist, f->side[c], f->tets + 4 * t, &poly);
      for (int k = 0; k < 4; ++k)
        if (f->neighbor[4 * t + k] < 0) emit(f, nodes, c, poly.face[k], poly.face_size[k], raw, &nraw, polygon, &npoly);
      emit(f, nodes, c, poly.crack, poly.crack_size, raw, &nraw, polygon, &npoly);
    }
  }
  /* A crack that ends inside the solid's surface (a crack front, a blade that does not reach
   * all the way) puts a point on an edge that a whole neighbour's boundary face has between
   * two corners: that face takes the point too, so the surface has no T-junction there. */
  int32_t ncross = 0;
  for (int32_t i = 0; i < nraw; ++i)
    if (raw[i].event >= 0) crossings[ncross++] = raw[i];
  qsort(crossings, (size_t)ncross, sizeof *crossings, by_edge_name);
  int32_t np = 0, nt = 0;
  for (int32_t g = 0; g < npoly; ++g) {
    const int32_t first = polygon[2 * g], size = polygon[2 * g + 1], base = np;
    int32_t apex = 0;
    for (int32_t i = 0; i < size; ++i) {
      const surface_point *p = &raw[first + i], *q = &raw[first + (i + 1) % size];
      points[np] = *p, points[np].order = np, ++np;
      if (p->event >= 0 || q->event >= 0 || ncross == 0) continue;
      const surface_point key = {p->fragment, p->a, q->a, -1, 0, 0};
      const surface_point *hit = bsearch(&key, crossings, (size_t)ncross, sizeof *crossings, by_edge_name);
      if (!hit) continue;
      if (apex == 0) apex = np - base;
      points[np] = *hit, points[np].order = np, ++np;
    }
    const int32_t n = np - base;
    for (int32_t i = 1; i + 1 < n; ++i) {
      int32_t *t3 = tri + 3 * (size_t)nt;
      t3[0] = base + apex, t3[1] = base + (apex + i) % n, t3[2] = base + (apex + i + 1) % n;
      triangle_fragment[nt++] = raw[first].fragment;
    }
  }
  free(raw), free(crossings), free(polygon);
  /* one vertex per distinct name, numbered in order of fragment */
  qsort(points, (size_t)np, sizeof *points, by_name);
  int32_t nv = 0;
  out->positions = malloc(3 * sizeof(double) * (size_t)(np > 0 ? np : 1));
  out->triangles = malloc(3 * sizeof(int32_t) * (size_t)(nt > 0 ? nt : 1));
  out->fragment_start = calloc((size_t)f->fragment_count + 1, sizeof(int32_t));
  int32_t *fill = calloc((size_t)f->fragment_count + 1, sizeof(int32_t));
  fracture_surface_point *at = where ? malloc(sizeof *at * (size_t)(np > 0 ? np : 1)) : NULL;
  if (!out->positions || !out->triangles || !out->fragment_start || !fill || (where && !at)) {
    free(points), free(tri), free(index), free(triangle_fragment), free(fill), free(at);
    piola_fracture_surface_free(out);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fracture surface: out of memory");
  }
  for (int32_t i = 0; i < np; ++i) {
    const surface_point *p = &points[i];
    if (i == 0 || by_name(&(surface_point){p->fragment, p->a, p->b, p->event, 0, -1}, &points[i - 1]) > 0) {
      const double *xa = b->x + 3 * (size_t)p->a, *xb = b->x + 3 * (size_t)p->b;
      for (int k = 0; k < 3; ++k) out->positions[3 * (size_t)nv + k] = xa[k] + p->t * (xb[k] - xa[k]);
      if (at) at[nv] = (fracture_surface_point){p->a, p->b, p->t};
      ++nv;
    }
    index[p->order] = nv - 1;
  }
  /* triangles grouped by fragment, in emission order within each */
  for (int32_t i = 0; i < nt; ++i) out->fragment_start[triangle_fragment[i] + 1]++;
  for (int32_t g = 0; g < f->fragment_count; ++g) out->fragment_start[g + 1] += out->fragment_start[g];
  for (int32_t i = 0; i < nt; ++i) {
    int32_t g = triangle_fragment[i];
    int32_t slot = out->fragment_start[g] + fill[g]++;
    for (int k = 0; k < 3; ++k) out->triangles[3 * (size_t)slot + k] = index[tri[3 * (size_t)i + k]];
  }
  out->fragment_count = f->fragment_count;
  out->vertex_count = nv;
  out->triangle_count = nt;
  free(points), free(tri), free(index), free(triangle_fragment), free(fill);
  if (where) *where = at;
  return PIOLA_OK;
}
