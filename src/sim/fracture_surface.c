/* The surface of each fragment of a cut solid, at the current positions: the boundary
 * faces of the original mesh clipped to each copy's material, and each cut copy's crack
 * polygon, fanned into triangles. Faces between two tets are never drawn: material on the
 * other side of such a face either touches this copy's (then they are one fragment and
 * the face is inside it) or has zero area there.
 *
 * A point is the same vertex in every copy of a fragment that names it the same way: a
 * corner by its node, a crack crossing by the nodes of its edge and the cut that made it
 * (copies sharing both nodes were cut together, so they computed the same crossing), a
 * point where two cracks meet on a face by the face's nodes and both cuts, one where three
 * meet inside a tet by its four nodes and the three cuts. So each fragment's surface is
 * closed wherever its cuts meet the body's surface through tets cut by the same plane.
 * Where a crack has not separated the nodes around it, both sides of the crack would name
 * their points alike: there a crossing also carries its side (surface_point.side), and the
 * edges left between two shared points are split (split_shared_edges). */
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "sim/fracture_internal.h"
#include "sim/world_internal.h"

/* A named point: its nodes in order of original vertex id (-1 after the last), the cuts
 * through it in order of event id (-1 after the last), its weights per node. */
typedef struct surface_point {
  int32_t fragment, node[4], event[FRACTURE_MAX_CUTS];
  double w[4];
  int32_t order;                 /* position in the emitted list */
  int32_t side;                  /* a crossing inside the criterion's crack sheet: 1 + the
                                    original id of the edge's end on the copy's side, so the
                                    crack's two sides do not share it; else 0 */
} surface_point;

/* Compares names: fragment, first node, second node (a corner's own node again), first
 * cut, then the rest, so a solid whose tets are cut once numbers its vertices as by
 * (fragment, a, b, cut). */
static int same_name(const surface_point *p, const surface_point *q) {
  if (p->fragment != q->fragment) return p->fragment < q->fragment ? -1 : 1;
  const int32_t pk[7] = {p->node[0], p->node[1] >= 0 ? p->node[1] : p->node[0], p->event[0], p->node[2],
                         p->node[3], p->event[1], p->event[2]};
  const int32_t qk[7] = {q->node[0], q->node[1] >= 0 ? q->node[1] : q->node[0], q->event[0], q->node[2],
                         q->node[3], q->event[1], q->event[2]};
  for (int k = 0; k < 7; ++k)
    if (pk[k] != qk[k]) return pk[k] < qk[k] ? -1 : 1;
  return p->side < q->side ? -1 : p->side > q->side;
}

static int by_name(const void *pa, const void *pb) {
  const surface_point *p = pa, *q = pb;
  const int c = same_name(p, q);
  if (c) return c;
  return p->order < q->order ? -1 : p->order > q->order;
}

static int is_corner(const surface_point *p) { return p->node[1] < 0; }
/* a crossing of an edge by one crack */
static int is_edge_crossing(const surface_point *p) { return p->node[2] < 0 && p->node[1] >= 0; }

void piola_fracture_surface_free(piola_fracture_surface *s) {
  if (!s) return;
  free(s->positions), free(s->triangles), free(s->fragment_start);
  memset(s, 0, sizeof *s);
}

/* Whether crack `event` cut every copy of original tet t (a copy it did not cut, one that
 * had three cuts already or one of a moving blade's earlier steps, is where it stops). */
static int tet_cut_by(const solid_fracture *f, int32_t t, int32_t event) {
  int any = 0;
  for (int i = 0; i < FRACTURE_MAX_COPIES; ++i) {
    const int32_t c = f->copies[FRACTURE_MAX_COPIES * (size_t)t + i];
    if (c < 0) break;
    copy_cut cuts[FRACTURE_MAX_CUTS];
    const int32_t n = piola__fracture_copy_cuts(f, c, cuts);
    int cut = 0;
    for (int32_t j = 0; j < n; ++j) cut |= cuts[j].event == event;
    if (!cut) return 0;
    any = 1;
  }
  return any;
}

/* Whether the crossing of original edge (u, v) by crack `event` lies inside the crack's sheet:
 * every tet around the edge (from tet t, across the faces that hold the edge, both ways on
 * the solid's surface) is cut by that crack. Elsewhere the crossing is on the crack's front,
 * where its two sides meet, or on its end on the solid's surface. */
static int inside_sheet(const solid_fracture *f, int32_t t, int32_t u, int32_t v, int32_t event) {
  if (!tet_cut_by(f, t, event)) return 0;
  /* the faces of a tet that hold the edge are those opposite its two other corners */
  int32_t first[2] = {-1, -1}, ways = 0;
  for (int k = 0; k < 4; ++k) {
    const int32_t id = f->tets[4 * (size_t)t + k];
    if (id != u && id != v && ways < 2) first[ways++] = f->neighbor[4 * (size_t)t + k];
  }
  for (int way = 0; way < 2; ++way) {
    int32_t prev = t, at = first[way];
    for (int steps = 0; steps < 256 && at >= 0; ++steps) { /* a ring of 256: no real mesh */
      if (at == t) return 1;                               /* round the ring */
      if (!tet_cut_by(f, at, event)) return 0;
      int32_t next = -1;
      for (int k = 0; k < 4; ++k) {
        const int32_t id = f->tets[4 * (size_t)at + k];
        const int32_t across = f->neighbor[4 * (size_t)at + k];
        if (id != u && id != v && across != prev) next = across;
      }
      prev = at, at = next;
    }
  }
  return 1;
}

/* Appends polygon poly of copy c (its points, named, and a record of it); cuts: the
 * copy's cuts, ids: its original tet's vertex ids. */
static void emit(const solid_fracture *f, const int32_t *nodes, int32_t c, const copy_cut *cuts,
                 const int32_t ids[4], const cell_point *poly, int32_t size, surface_point *points,
                 int32_t *np, int32_t *polygon, int32_t *npoly) {
  if (size < 3) return;
  polygon[3 * *npoly] = *np, polygon[3 * *npoly + 1] = size, polygon[3 * *npoly + 2] = c, ++*npoly;
  for (int32_t i = 0; i < size; ++i) {
    surface_point *p = &points[(*np)++];
    p->fragment = f->fragment[c];
    int corner[4], n = 0, m = 0;
    for (int k = 0; k < 4; ++k)
      if (poly[i].corners >> k & 1) corner[n++] = k;
    for (int a = 1; a < n; ++a)
      for (int b = a; b > 0 && ids[corner[b]] < ids[corner[b - 1]]; --b) {
        int tmp = corner[b];
        corner[b] = corner[b - 1], corner[b - 1] = tmp;
      }
    for (int k = 0; k < 4; ++k) {
      p->node[k] = k < n ? nodes[4 * c + corner[k]] : -1;
      p->w[k] = k < n ? poly[i].w[corner[k]] : 0;
    }
    for (int j = 0; j < FRACTURE_MAX_CUTS; ++j)
      if (poly[i].cuts >> j & 1) {
        int b = m++;
        for (; b > 0 && p->event[b - 1] > cuts[j].event; --b) p->event[b] = p->event[b - 1];
        p->event[b] = cuts[j].event;
      }
    for (int j = m; j < FRACTURE_MAX_CUTS; ++j) p->event[j] = -1;
    p->side = 0;
    if (n == 2 && m == 1) {
      int32_t j = 0;
      while (!(poly[i].cuts >> j & 1)) ++j;
      /* the side: the end of the edge that holds this copy's material, which every tet
       * around the edge names alike. Scripted cuts separate the nodes they pass (a moving
       * blade's slit too: its earlier copies, cut at other positions, close it) */
      if (cuts[j].event == f->grown_crack &&
          inside_sheet(f, f->parent[c], ids[corner[0]], ids[corner[1]], cuts[j].event))
        p->side =
            1 + (cuts[j].dist[corner[0]] * cuts[j].side > 0 ? ids[corner[0]] : ids[corner[1]]);
    }
  }
}

/* edge crossings by fragment and the unordered pair of their nodes */
static int by_edge_name(const void *pa, const void *pb) {
  const surface_point *p = pa, *q = pb;
  if (p->fragment != q->fragment) return p->fragment < q->fragment ? -1 : 1;
  int32_t pl = p->node[0] < p->node[1] ? p->node[0] : p->node[1], ph = p->node[0] < p->node[1] ? p->node[1] : p->node[0];
  int32_t ql = q->node[0] < q->node[1] ? q->node[0] : q->node[1], qh = q->node[0] < q->node[1] ? q->node[1] : q->node[0];
  if (pl != ql) return pl < ql ? -1 : 1;
  return ph < qh ? -1 : ph > qh;
}

/* One use of an edge by a triangle: its ends in order, the sheet the triangle is on (below),
 * and whether the triangle runs from lo to hi. */
typedef struct edge_use {
  int32_t lo, hi, sheet, triangle, forward;
} edge_use;

/* The sheet of a triangle of copy c at an edge: where both ends cross one crack, the copy's
 * side of that crack (-2 or -4, apart from copy numbers), else the copy itself. */
static int32_t sheet_of(const solid_fracture *f, int32_t c, int32_t event) {
  if (event < 0) return c;
  copy_cut cuts[FRACTURE_MAX_CUTS];
  const int32_t n = piola__fracture_copy_cuts(f, c, cuts);
  for (int32_t j = 0; j < n; ++j)
    if (cuts[j].event == event) return cuts[j].side > 0 ? -2 : -4;
  return c;
}

static int by_edge_then_sheet(const void *pa, const void *pb) {
  const edge_use *p = pa, *q = pb;
  if (p->lo != q->lo) return p->lo < q->lo ? -1 : 1;
  if (p->hi != q->hi) return p->hi < q->hi ? -1 : 1;
  if (p->sheet != q->sheet) return p->sheet < q->sheet ? -1 : 1;
  return p->triangle < q->triangle ? -1 : p->triangle > q->triangle;
}

/* Whether triangle t has the edge {u, v}; if so *at is the corner it starts from. */
static int has_edge(const int32_t *t, int32_t u, int32_t v, int *at) {
  for (int k = 0; k < 3; ++k) {
    const int32_t a = t[k], b = t[(k + 1) % 3];
    if ((a == u && b == v) || (a == v && b == u)) {
      *at = k;
      return 1;
    }
  }
  return 0;
}

/* Where a crack has not separated the nodes around it (the first tet a crack cuts, the tets
 * along its front), the two copies of a cut tet have the same nodes. Inside the crack's
 * sheet its crossings are told apart by side (surface_point.side); on its front the two
 * sides meet and share them. An edge between two such shared points carries four triangles,
 * two on each side of the crack: where the crack ends on the solid's surface between two
 * front points (each side's boundary piece and crack polygon), and where the sheet spans a
 * face between them. Each side's pair is made an edge of its own: for every sheet but the
 * first, the edge's midpoint becomes a new vertex of the fragment and the sheet's two
 * triangles are split there, so every edge has exactly two triangles (docs/fracture.md,
 * "Output"). An edge whose triangles do not pair up sheet by sheet, one each way, is left as
 * it is. copy_of: each triangle's copy; crack_of: each vertex's crack where it is a shared
 * crossing, else -1. */
static piola_status split_shared_edges(const solid_fracture *f, piola_fracture_surface *out,
                                       const int32_t *copy_of, const int32_t *crack_of) {
  const int32_t nt = out->triangle_count, nv = out->vertex_count;
  edge_use *uses = malloc(sizeof *uses * 3 * (size_t)(nt > 0 ? nt : 1));
  if (!uses) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fracture surface: out of memory");
  for (int32_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      const int32_t a = out->triangles[3 * (size_t)t + k],
                    b = out->triangles[3 * (size_t)t + (k + 1) % 3];
      const int32_t crack = crack_of[a] == crack_of[b] ? crack_of[a] : -1;
      uses[3 * (size_t)t + k] =
          (edge_use){a < b ? a : b, a < b ? b : a, sheet_of(f, copy_of[t], crack), t, a < b};
    }
  const size_t nu = 3 * (size_t)nt;
  qsort(uses, nu, sizeof *uses, by_edge_then_sheet);
  /* the splits, in place of the uses: the edge, and the two triangles of a copy */
  size_t nsplit = 0;
  for (size_t i = 0; i < nu;) {
    size_t j = i;
    while (j < nu && uses[j].lo == uses[i].lo && uses[j].hi == uses[i].hi) ++j;
    int pairs = j - i > 2 && (j - i) % 2 == 0;
    for (size_t k = i; k < j && pairs; k += 2)
      pairs = uses[k + 1].sheet == uses[k].sheet && uses[k + 1].forward != uses[k].forward &&
              (k + 2 == j || uses[k + 2].sheet != uses[k].sheet);
    for (size_t k = i + 2; k < j && pairs; k += 2)
      uses[nsplit++] = uses[k], uses[nsplit++] = uses[k + 1];
    i = j;
  }
  nsplit /= 2;
  if (nsplit == 0) {
    free(uses);
    return PIOLA_OK;
  }
  const size_t mt = (size_t)nt + 2 * nsplit, mv = (size_t)nv + nsplit;
  int32_t *tris = malloc(3 * sizeof(int32_t) * mt), *next = malloc(sizeof(int32_t) * mt);
  int32_t *fragment = malloc(sizeof(int32_t) * mt), *vertex_fragment = malloc(sizeof(int32_t) * mv);
  int32_t *renumber = malloc(sizeof(int32_t) * mv),
          *start = calloc((size_t)out->fragment_count + 1, sizeof(int32_t));
  double *positions = malloc(3 * sizeof(double) * mv);
  int32_t *triangles = malloc(3 * sizeof(int32_t) * mt);
  piola_status st = PIOLA_OK;
  if (!tris || !next || !fragment || !vertex_fragment || !renumber || !start || !positions ||
      !triangles) {
    st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fracture surface: out of memory");
    goto done;
  }
  for (size_t i = 0; i < mv; ++i) vertex_fragment[i] = -1;
  memcpy(tris, out->triangles, 3 * sizeof(int32_t) * (size_t)nt);
  memcpy(positions, out->positions, 3 * sizeof(double) * (size_t)nv);
  for (int32_t g = 0; g < out->fragment_count; ++g)
    for (int32_t t = out->fragment_start[g]; t < out->fragment_start[g + 1]; ++t) {
      fragment[t] = g, next[t] = -1;
      for (int k = 0; k < 3; ++k) vertex_fragment[tris[3 * (size_t)t + k]] = g;
    }
  for (int32_t i = 1; i < nv; ++i) /* a vertex no triangle uses (none expected): its neighbour's */
    if (vertex_fragment[i] < 0) vertex_fragment[i] = vertex_fragment[i - 1];
  if (nv > 0 && vertex_fragment[0] < 0) vertex_fragment[0] = 0;
  /* split: a triangle split before along another edge is followed to the piece that has
   * this one (next[] chains each triangle's pieces) */
  size_t count = (size_t)nt;
  for (size_t s = 0; s < nsplit; ++s) {
    const int32_t u = uses[2 * s].lo, v = uses[2 * s].hi, m = nv + (int32_t)s;
    for (int k = 0; k < 3; ++k)
      positions[3 * (size_t)m + k] =
          0.5 * (positions[3 * (size_t)u + k] + positions[3 * (size_t)v + k]);
    vertex_fragment[m] = fragment[uses[2 * s].triangle];
    for (int side = 0; side < 2; ++side) {
      int32_t t = uses[2 * s + side].triangle;
      int at = 0;
      while (t >= 0 && !has_edge(tris + 3 * (size_t)t, u, v, &at)) t = next[t];
      if (t < 0) continue; /* cannot happen: a piece keeps every edge but the one split */
      int32_t *a = tris + 3 * (size_t)t, *b = tris + 3 * count;
      const int32_t p = a[at], q = a[(at + 1) % 3], r = a[(at + 2) % 3];
      a[0] = p, a[1] = m, a[2] = r; /* (p, q, r) -> (p, m, r) and (m, q, r) */
      b[0] = m, b[1] = q, b[2] = r;
      fragment[count] = fragment[t], next[count] = next[t], next[t] = (int32_t)count;
      ++count;
    }
  }
  /* vertices and triangles grouped by fragment again, in their order within each */
  int32_t nvn = 0;
  for (int32_t g = 0; g < out->fragment_count; ++g)
    for (size_t i = 0; i < mv; ++i)
      if (vertex_fragment[i] == g) renumber[i] = nvn++;
  double *moved = malloc(3 * sizeof(double) * mv);
  if (!moved) {
    st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fracture surface: out of memory");
    goto done;
  }
  for (size_t i = 0; i < mv; ++i)
    for (int k = 0; k < 3; ++k) moved[3 * (size_t)renumber[i] + k] = positions[3 * i + k];
  for (size_t t = 0; t < count; ++t) start[fragment[t] + 1]++;
  for (int32_t g = 0; g < out->fragment_count; ++g) start[g + 1] += start[g];
  memcpy(out->fragment_start, start, sizeof(int32_t) * ((size_t)out->fragment_count + 1));
  for (size_t t = 0; t < count; ++t) {
    const int32_t slot = start[fragment[t]]++;
    for (int k = 0; k < 3; ++k) triangles[3 * (size_t)slot + k] = renumber[tris[3 * t + k]];
  }
  free(out->positions), free(out->triangles);
  out->positions = moved, out->triangles = triangles, triangles = NULL;
  out->vertex_count = nvn, out->triangle_count = (int32_t)count;
done:
  free(uses), free(tris), free(next), free(fragment), free(vertex_fragment), free(renumber),
      free(start);
  free(positions), free(triangles);
  return st;
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
  /* at most 4 faces and 3 cracks of CELL_POLYGON_MAX points per copy; a polygon's edge
   * between two corners gains at most one point, so the points at most double */
  const size_t cap = (4 + FRACTURE_MAX_CUTS) * CELL_POLYGON_MAX * (size_t)f->copy_count + 1;
  surface_point *raw = malloc(sizeof *raw * cap), *points = malloc(2 * sizeof *points * cap);
  surface_point *crossings = malloc(sizeof *crossings * cap);
  int32_t *polygon = malloc(3 * sizeof(int32_t) * cap); /* first point, size, copy */
  int32_t *tri = malloc(3 * sizeof(int32_t) * 2 * cap), *index = malloc(2 * sizeof(int32_t) * cap);
  int32_t *triangle_fragment = malloc(2 * sizeof(int32_t) * cap);
  int32_t *triangle_copy = malloc(2 * sizeof(int32_t) * cap);
  if (!raw || !points || !crossings || !polygon || !tri || !index || !triangle_fragment ||
      !triangle_copy) {
    free(raw), free(points), free(crossings), free(polygon), free(tri), free(index), free(triangle_fragment);
    free(triangle_copy);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fracture surface: out of memory");
  }
  int32_t nraw = 0, npoly = 0;
  for (int32_t c = 0; c < f->copy_count; ++c) {
    const int32_t t = f->parent[c], *ids = f->tets + 4 * t;
    copy_cut cuts[FRACTURE_MAX_CUTS];
    const int32_t n = piola__fracture_copy_cuts(f, c, cuts);
    if (n == 0) {
      for (int k = 0; k < 4; ++k) {
        if (f->neighbor[4 * t + k] >= 0) continue;
        cell_point face[3];
        for (int i = 0; i < 3; ++i) {
          const int corner = piola__cut_tet_face[k][i];
          face[i] = (cell_point){(uint8_t)(1u << corner), 0, {0, 0, 0, 0}};
          face[i].w[corner] = 1;
        }
        emit(f, nodes, c, cuts, ids, face, 3, raw, &nraw, polygon, &npoly);
      }
    } else {
      /* inset: the level sets side * inset instead of 0 (the same edges are crossed) */
      for (int32_t j = 0; j < n; ++j)
        for (int k = 0; k < 4; ++k) cuts[j].dist[k] -= cuts[j].side * inset;
      cell_polygons poly;
      piola__fracture_cell_polygons(cuts, n, ids, &poly);
      for (int k = 0; k < 4; ++k)
        if (f->neighbor[4 * t + k] < 0)
          emit(f, nodes, c, cuts, ids, poly.face[k], poly.face_size[k], raw, &nraw, polygon, &npoly);
      for (int32_t j = 0; j < n; ++j)
        emit(f, nodes, c, cuts, ids, poly.crack[j], poly.crack_size[j], raw, &nraw, polygon, &npoly);
    }
  }
  /* A crack that ends inside the solid's surface (a crack front, a blade that does not reach
   * all the way) puts a point on an edge that a whole neighbour's boundary face has between
   * two corners: that face takes the point too, so the surface has no T-junction there. */
  int32_t ncross = 0;
  for (int32_t i = 0; i < nraw; ++i)
    if (is_edge_crossing(&raw[i])) crossings[ncross++] = raw[i];
  qsort(crossings, (size_t)ncross, sizeof *crossings, by_edge_name);
  int32_t np = 0, nt = 0;
  for (int32_t g = 0; g < npoly; ++g) {
    const int32_t first = polygon[3 * g], size = polygon[3 * g + 1], base = np;
    int32_t apex = 0;
    for (int32_t i = 0; i < size; ++i) {
      const surface_point *p = &raw[first + i], *q = &raw[first + (i + 1) % size];
      points[np] = *p, points[np].order = np, ++np;
      if (!is_corner(p) || !is_corner(q) || ncross == 0) continue;
      const surface_point key = {
          p->fragment, {p->node[0], q->node[0], -1, -1}, {-1, -1, -1}, {0, 0, 0, 0}, 0, 0};
      const surface_point *hit = bsearch(&key, crossings, (size_t)ncross, sizeof *crossings, by_edge_name);
      if (!hit) continue;
      if (apex == 0) apex = np - base;
      points[np] = *hit, points[np].order = np, ++np;
    }
    const int32_t n = np - base;
    for (int32_t i = 1; i + 1 < n; ++i) {
      int32_t *t3 = tri + 3 * (size_t)nt;
      t3[0] = base + apex, t3[1] = base + (apex + i) % n, t3[2] = base + (apex + i + 1) % n;
      triangle_copy[nt] = polygon[3 * g + 2];
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
  int32_t *crack_of = malloc(sizeof(int32_t) * (size_t)(np > 0 ? np : 1));
  fracture_surface_point *at = where ? malloc(sizeof *at * (size_t)(np > 0 ? np : 1)) : NULL;
  if (!out->positions || !out->triangles || !out->fragment_start || !fill || !crack_of ||
      (where && !at)) {
    free(points), free(tri), free(index), free(triangle_fragment), free(triangle_copy), free(fill),
        free(at);
    free(crack_of);
    piola_fracture_surface_free(out);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fracture surface: out of memory");
  }
  for (int32_t i = 0; i < np; ++i) {
    const surface_point *p = &points[i];
    if (i == 0 || same_name(p, &points[i - 1]) != 0) {
      if (is_edge_crossing(p)) { /* as a + t (b - a), the form a single cut always had */
        const double *xa = b->x + 3 * (size_t)p->node[0], *xb = b->x + 3 * (size_t)p->node[1];
        for (int k = 0; k < 3; ++k) out->positions[3 * (size_t)nv + k] = xa[k] + p->w[1] * (xb[k] - xa[k]);
      } else {
        for (int k = 0; k < 3; ++k) {
          double sum = 0;
          for (int j = 0; j < 4 && p->node[j] >= 0; ++j) sum += p->w[j] * b->x[3 * (size_t)p->node[j] + k];
          out->positions[3 * (size_t)nv + k] = sum;
        }
      }
      crack_of[nv] = is_edge_crossing(p) && p->side == 0 ? p->event[0] : -1;
      if (at) {
        fracture_surface_point *q = &at[nv];
        for (int j = 0; j < 4; ++j) q->node[j] = p->node[j], q->w[j] = p->w[j];
      }
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
    triangle_fragment[i] = slot; /* now: where triangle i went */
  }
  for (int32_t i = 0; i < nt; ++i) index[triangle_fragment[i]] = triangle_copy[i]; /* per slot */
  out->fragment_count = f->fragment_count;
  out->vertex_count = nv;
  out->triangle_count = nt;
  piola_status st = PIOLA_OK;
  if (!where) st = split_shared_edges(f, out, index, crack_of);
  free(points), free(tri), free(index), free(triangle_fragment), free(triangle_copy), free(fill);
  free(crack_of);
  if (st != PIOLA_OK) {
    piola_fracture_surface_free(out);
    return st;
  }
  if (where) *where = at;
  return PIOLA_OK;
}
