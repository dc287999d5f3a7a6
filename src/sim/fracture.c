/* Fracture of solids by the virtual node algorithm (Molino, Bao and Fedkiw 2004) for plane
 * cuts: the cut event, the duplication of nodes, fragments and the public functions of
 * piola/world_fracture.h. docs/fracture.md says what is supported.
 *
 * A cut event, on a solid's current state:
 *  1. the signed distance of every node to the plane, pushed at least `snap` away from zero
 *     (so no crack runs through a node and no copy is an empty sliver);
 *  2. each whole copy whose corners have both signs becomes two copies (one per side) with
 *     the distances kept and the side's material fraction (fracture_geometry.c); copies cut
 *     before are left as they are;
 *  3. the nodes are rebuilt: a (copy, corner) pair is one item; two face neighbours whose
 *     material overlaps on their shared face (positive area, the cut polygons clipped on
 *     the face) share the items of the face's three corners (MBF04's rule). Nodes that no
 *     new copy touches keep all their items together. Each class of items is one node,
 *     with its old node's position, velocity and constraint: momentum is kept exactly,
 *     and every new node's mass is a share of its old node's;
 *  4. the body is rebuilt with the new mesh (body_rebuild.c), each copy taking its parent's
 *     material, fibre and plastic state, and its material fraction;
 *  5. fragments: copies joined through shared nodes. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "common/union_find.h"
#include "force/elastic_body_internal.h"
#include "piola/plasticity.h"
#include "sim/fracture_internal.h"
#include "sim/world_internal.h"

/* distances closer to the plane than this share of the smallest rest altitude are pushed
 * away from it: the crack moves by at most that much */
#define SNAP_SHARE 1e-4
/* shared face areas below this share of the face are no material contact */
#define OVERLAP_SHARE 1e-12
/* a cut through a copy cut before splits it only where each side keeps more than this
 * share of the tet's material (below it the fraction is rounding) */
#define MIN_PIECE 1e-13

static void free_blades(piola_tri_mesh *blades, int32_t count);

void piola__fracture_free(solid_fracture *f) {
  if (!f) return;
  free_blades(f->blades, f->cut_count);
  free(f->cuts), free(f->tets), free(f->neighbor), free(f->parent), free(f->event), free(f->dist);
  free(f->side), free(f->fraction), free(f->fragment), free(f->copies), free(f->vertex_crack), free(f->last_strain);
  free(f->vertex_value), free(f->vertex_time), free(f->sweep_crack), free(f->swept_to);
  free(f->more_event), free(f->more_dist), free(f->more_side);
  free(f);
}

static void number_fragments(int32_t copies, const int32_t *node_of, int32_t nodes, int32_t *up,
                             int32_t *fragment, int32_t *count);

/* ------------------------------------------------------------------ setup */

typedef struct face_key {
  int32_t v[3];
  int32_t tet, face;
} face_key;

static int by_face(const void *pa, const void *pb) {
  const face_key *a = pa, *b = pb;
  for (int i = 0; i < 3; ++i)
    if (a->v[i] != b->v[i]) return a->v[i] < b->v[i] ? -1 : 1;
  return a->tet < b->tet ? -1 : a->tet > b->tet;
}

static void sort3(int32_t v[3]) {
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2 - i; ++j)
      if (v[j] > v[j + 1]) {
        int32_t t = v[j];
        v[j] = v[j + 1], v[j + 1] = t;
      }
}

static piola_status fracture_create(const world_body *b, solid_fracture **out) {
  const int32_t nt = piola_elastic_body_tet_count(b->solid);
  solid_fracture *f = calloc(1, sizeof *f);
  face_key *keys = malloc(sizeof *keys * 4 * (size_t)nt);
  if (f) {
    f->tet_count = f->copy_count = nt;
    f->tets = malloc(4 * sizeof(int32_t) * (size_t)nt);
    f->neighbor = malloc(4 * sizeof(int32_t) * (size_t)nt);
    f->parent = malloc(sizeof(int32_t) * (size_t)nt);
    f->event = malloc(sizeof(int32_t) * (size_t)nt);
    f->dist = calloc(4 * (size_t)nt, sizeof(double));
    f->side = calloc((size_t)nt, 1);
    f->fraction = malloc(sizeof(double) * (size_t)nt);
    f->fragment = calloc((size_t)nt, sizeof(int32_t));
    f->copies = malloc(FRACTURE_MAX_COPIES * sizeof(int32_t) * (size_t)nt);
    f->more_event = malloc((FRACTURE_MAX_CUTS - 1) * sizeof(int32_t) * (size_t)nt);
    f->more_dist = calloc(4 * (FRACTURE_MAX_CUTS - 1) * (size_t)nt, sizeof(double));
    f->more_side = calloc((FRACTURE_MAX_CUTS - 1) * (size_t)nt, 1);
    f->vertex_count = b->n;
    f->vertex_crack = malloc(sizeof(int32_t) * (size_t)b->n);
    f->vertex_value = calloc((size_t)b->n, sizeof(double));
    f->vertex_time = calloc((size_t)b->n, sizeof(double));
  }
  if (!f || !keys || !f->tets || !f->neighbor || !f->parent || !f->event || !f->dist || !f->side ||
      !f->fraction || !f->fragment || !f->copies || !f->vertex_crack || !f->vertex_value ||
      !f->vertex_time || !f->more_event || !f->more_dist || !f->more_side) {
    free(keys);
    piola__fracture_free(f);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fracture of '%s': out of memory", b->name);
  }
  memcpy(f->tets, piola_elastic_body_tets(b->solid), 4 * sizeof(int32_t) * (size_t)nt);
  for (int32_t i = 0; i < b->n; ++i) f->vertex_crack[i] = -1;
  f->grown_crack = -1;
  for (int32_t t = 0; t < nt; ++t) {
    f->parent[t] = t, f->event[t] = -1, f->side[t] = 1, f->fraction[t] = 1.0;
    for (int j = 0; j < FRACTURE_MAX_COPIES; ++j) f->copies[FRACTURE_MAX_COPIES * t + j] = j == 0 ? t : -1;
    for (int j = 0; j < FRACTURE_MAX_CUTS - 1; ++j) f->more_event[(FRACTURE_MAX_CUTS - 1) * t + j] = -1;
    for (int k = 0; k < 4; ++k) {
      face_key *key = &keys[4 * t + k];
      for (int i = 0; i < 3; ++i) key->v[i] = f->tets[4 * t + piola__cut_tet_face[k][i]];
      sort3(key->v);
      key->tet = t, key->face = k;
      f->neighbor[4 * t + k] = -1;
    }
  }
  qsort(keys, 4 * (size_t)nt, sizeof *keys, by_face);
  for (int64_t i = 0; i + 1 < 4 * (int64_t)nt; ++i) {
    const face_key *a = &keys[i], *c = &keys[i + 1];
    if (a->v[0] == c->v[0] && a->v[1] == c->v[1] && a->v[2] == c->v[2]) {
      f->neighbor[4 * a->tet + a->face] = c->tet;
      f->neighbor[4 * c->tet + c->face] = a->tet;
    }
  }
  free(keys);
  int32_t *up = malloc(sizeof(int32_t) * (size_t)nt);
  if (!up) {
    piola__fracture_free(f);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fracture of '%s': out of memory", b->name);
  }
  number_fragments(nt, f->tets, b->n, up, f->fragment, &f->fragment_count);
  free(up);
  *out = f;
  return PIOLA_OK;
}

/* ------------------------------------------------------------------ face overlap */

/* Area (times a constant) of the part of triangle (e0, e1, e2) in barycentric coordinates
 * where each of the n linear functions (values at the three corners) is positive. */
static double clipped_face_area(double value[][3], int n) {
  double poly[16][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  int size = 3;
  for (int c = 0; c < n && size > 0; ++c) {
    double next[16][3], g[16];
    int m = 0;
    for (int i = 0; i < size; ++i)
      g[i] = value[c][0] * poly[i][0] + value[c][1] * poly[i][1] + value[c][2] * poly[i][2];
    for (int i = 0; i < size; ++i) {
      int j = (i + 1) % size;
      if (g[i] > 0) memcpy(next[m++], poly[i], sizeof poly[i]);
      if ((g[i] > 0) != (g[j] > 0)) {
        double t = g[i] / (g[i] - g[j]);
        for (int k = 0; k < 3; ++k) next[m][k] = poly[i][k] + t * (poly[j][k] - poly[i][k]);
        ++m;
      }
    }
    size = m;
    memcpy(poly, next, sizeof next);
  }
  double area[3] = {0, 0, 0};
  for (int i = 1; i + 1 < size; ++i) {
    double a[3], b[3];
    for (int k = 0; k < 3; ++k) a[k] = poly[i][k] - poly[0][k], b[k] = poly[i + 1][k] - poly[0][k];
    area[0] += a[1] * b[2] - a[2] * b[1];
    area[1] += a[2] * b[0] - a[0] * b[2];
    area[2] += a[0] * b[1] - a[1] * b[0];
  }
  return sqrt(area[0] * area[0] + area[1] * area[1] + area[2] * area[2]);
}

static int local_corner(const int32_t *tet, int32_t vertex) {
  for (int k = 0; k < 4; ++k)
    if (tet[k] == vertex) return k;
  return -1;
}

/* Whether copies c (of tet t, face k) and d (of the neighbour u) hold material on a
 * common part of their shared face of positive area (f: the copies' cuts). */
static int faces_overlap(const solid_fracture *f, int32_t c, int32_t t, int k, int32_t d, int32_t u) {
  double value[2 * FRACTURE_MAX_CUTS][3];
  int n = 0;
  const int32_t copy[2] = {c, d}, tet[2] = {t, u};
  for (int s = 0; s < 2; ++s) {
    copy_cut cuts[FRACTURE_MAX_CUTS];
    const int32_t count = piola__fracture_copy_cuts(f, copy[s], cuts);
    for (int32_t j = 0; j < count; ++j, ++n)
      for (int i = 0; i < 3; ++i) {
        int32_t vertex = f->tets[4 * t + piola__cut_tet_face[k][i]];
        int corner = local_corner(f->tets + 4 * tet[s], vertex);
        value[n][i] = cuts[j].side * cuts[j].dist[corner];
      }
  }
  return clipped_face_area(value, n) > OVERLAP_SHARE * sqrt(3.0);
}

/* Whether a cut of crack `crack` with corner distances dist splits copy c: the tet's
 * corners are on both sides of it, c has room for one more cut and none of its cuts is of
 * this crack, and (for a copy cut before) each side holds more than MIN_PIECE of the
 * tet's material. */
static int cut_splits(const solid_fracture *f, int32_t c, int32_t crack, const double dist[4]) {
  int pos = 0, neg = 0;
  for (int k = 0; k < 4; ++k) {
    if (dist[k] > 0) pos = 1;
    else neg = 1;
  }
  if (!(pos && neg)) return 0;
  copy_cut cuts[FRACTURE_MAX_CUTS];
  const int32_t n = piola__fracture_copy_cuts(f, c, cuts);
  if (n == 0) return 1;
  if (n >= FRACTURE_MAX_CUTS) return 0;
  for (int32_t j = 0; j < n; ++j)
    if (cuts[j].event == crack) return 0;
  for (int side = -1; side <= 1; side += 2) {
    cuts[n] = (copy_cut){crack, (int8_t)side, {dist[0], dist[1], dist[2], dist[3]}};
    cell_polygons poly;
    piola__fracture_cell_polygons(cuts, n + 1, f->tets + 4 * f->parent[c], &poly);
    if (!(poly.fraction > MIN_PIECE)) return 0;
  }
  return 1;
}

/* ------------------------------------------------------------------ the cut event */

double piola__fracture_snap(const world_body *b) {
  const double altitude = piola_elastic_body_min_rest_altitude(b->solid);
  double snap = SNAP_SHARE * altitude;
  /* with self-collision, each crack face's collision surface lies up to half the thickness
   * inside its material (world_contact.c), which needs that much room on either side */
  if (b->self_collision.enabled)
    snap = fmax(snap, fmin(0.5 * b->self_collision.thickness, 0.05 * altitude));
  return snap;
}

/* One uncut copy to split: its corner distances (none zero, both signs) and the crack it
 * belongs to (copies of one crack name their crack points alike: fracture_surface.c). */
typedef struct tet_cut {
  int32_t copy, crack;
  double dist[4];
} tet_cut;

typedef struct new_mesh {
  int32_t copies, nodes;
  int32_t *parent, *event, *element_parent, *node_of, *node_parent, *up, *fragment, *more_event;
  int8_t *side, *fresh, *more_side;
  double *dist, *fraction, *more_dist;
} new_mesh;

static void new_mesh_free(new_mesh *m) {
  free(m->parent), free(m->event), free(m->element_parent), free(m->node_of), free(m->node_parent);
  free(m->up), free(m->fragment), free(m->side), free(m->fresh), free(m->dist), free(m->fraction);
  free(m->more_event), free(m->more_side), free(m->more_dist);
}

/* Numbers fragments: copies joined through nodes, in order of first copy. */
static void number_fragments(int32_t copies, const int32_t *node_of, int32_t nodes, int32_t *up,
                             int32_t *fragment, int32_t *count) {
  int32_t *first = malloc(sizeof(int32_t) * (size_t)(nodes > 0 ? nodes : 1));
  for (int32_t i = 0; i < copies; ++i) up[i] = i;
  if (first) {
    for (int32_t i = 0; i < nodes; ++i) first[i] = -1;
    for (int32_t c = 0; c < copies; ++c)
      for (int k = 0; k < 4; ++k) {
        int32_t node = node_of[4 * c + k];
        if (first[node] < 0) first[node] = c;
        else piola__union_find_join(up, first[node], c);
      }
  }
  free(first);
  int32_t n = 0;
  for (int32_t c = 0; c < copies; ++c) {
    int32_t r = piola__union_find_root(up, c);
    fragment[c] = r == c ? n++ : fragment[r];
  }
  *count = n;
}

/* Splits the copies cuts[i].copy (each once, where cut_splits says so: corner distances
 * none zero) into two copies each, rebuilding nodes, body and fragments (steps 2 to 5
 * above). */
static piola_status split_copies(piola_world *w, world_body *b, const tet_cut *cuts, int32_t count) {
  solid_fracture *f = b->fracture;
  const piola_elastic_body *old = b->solid;
  const int32_t *old_tets = piola_elastic_body_tets(old);
  if (count == 0) return PIOLA_OK;
  /* the cracks' values at the vertices they reach first (continued_crack reads them) */
  for (int32_t i = 0; i < count; ++i)
    for (int k = 0; k < 4; ++k) {
      const int32_t vertex = f->tets[4 * f->parent[cuts[i].copy] + k];
      if (f->vertex_crack[vertex] >= 0) continue;
      f->vertex_crack[vertex] = cuts[i].crack, f->vertex_value[vertex] = cuts[i].dist[k];
      f->vertex_time[vertex] = w->time;
    }
  int32_t *plan = malloc(sizeof(int32_t) * (size_t)f->copy_count);
  if (!plan) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "cut of '%s': out of memory", b->name);
  for (int32_t c = 0; c < f->copy_count; ++c) plan[c] = -1;
  for (int32_t i = 0; i < count; ++i) plan[cuts[i].copy] = i;
  new_mesh m = {0};
  const int32_t nc = f->copy_count + count;
  m.copies = nc;
  m.parent = malloc(sizeof(int32_t) * (size_t)nc);
  m.event = malloc(sizeof(int32_t) * (size_t)nc);
  m.element_parent = malloc(sizeof(int32_t) * (size_t)nc);
  m.node_of = malloc(4 * sizeof(int32_t) * (size_t)nc);
  m.node_parent = malloc(4 * sizeof(int32_t) * (size_t)nc);
  m.up = malloc(4 * sizeof(int32_t) * (size_t)nc);
  m.fragment = malloc(sizeof(int32_t) * (size_t)nc);
  m.side = malloc((size_t)nc);
  m.fresh = calloc((size_t)b->n, 1);
  m.dist = malloc(4 * sizeof(double) * (size_t)nc);
  m.fraction = malloc(sizeof(double) * (size_t)nc);
  m.more_event = malloc((FRACTURE_MAX_CUTS - 1) * sizeof(int32_t) * (size_t)nc);
  m.more_side = malloc((FRACTURE_MAX_CUTS - 1) * (size_t)nc);
  m.more_dist = malloc(4 * (FRACTURE_MAX_CUTS - 1) * sizeof(double) * (size_t)nc);
  int32_t *copies = malloc(FRACTURE_MAX_COPIES * sizeof(int32_t) * (size_t)f->tet_count);
  double *x = malloc(3 * sizeof(double) * 4 * (size_t)nc), *v = malloc(3 * sizeof(double) * 4 * (size_t)nc);
  double *rest = malloc(3 * sizeof(double) * 4 * (size_t)nc);
  piola_status st = PIOLA_OK;
  if (!m.parent || !m.event || !m.element_parent || !m.node_of || !m.node_parent || !m.up ||
      !m.fragment || !m.side || !m.fresh || !m.dist || !m.fraction || !m.more_event || !m.more_side ||
      !m.more_dist || !copies || !x || !v || !rest)
    st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "cut of '%s': out of memory", b->name);
  int32_t n = 0, newly_cut = 0;
  enum { MORE = FRACTURE_MAX_CUTS - 1 };
  for (int32_t c = 0; c < f->copy_count && st == PIOLA_OK; ++c) {
    const int32_t *corners = old_tets + 4 * c;
    const tet_cut *cut = plan[c] >= 0 ? &cuts[plan[c]] : NULL;
    copy_cut have[FRACTURE_MAX_CUTS];
    const int32_t had = piola__fracture_copy_cuts(f, c, have);
    newly_cut += cut && had == 0;
    for (int copy = 0; copy < (cut ? 2 : 1); ++copy) {
      const int8_t side = copy == 0 ? 1 : -1;
      m.parent[n] = f->parent[c];
      m.element_parent[n] = c;
      m.event[n] = cut && had == 0 ? cut->crack : f->event[c];
      m.side[n] = cut && had == 0 ? side : f->side[c];
      m.fraction[n] = f->fraction[c];
      memcpy(m.dist + 4 * n, f->dist + 4 * c, 4 * sizeof(double));
      memcpy(m.more_event + MORE * n, f->more_event + MORE * c, MORE * sizeof(int32_t));
      memcpy(m.more_side + MORE * n, f->more_side + MORE * c, MORE);
      memcpy(m.more_dist + 4 * MORE * n, f->more_dist + 4 * MORE * c, 4 * MORE * sizeof(double));
      if (cut) {
        for (int k = 0; k < 4; ++k) m.fresh[corners[k]] = 1;
        if (had == 0) {
          memcpy(m.dist + 4 * n, cut->dist, 4 * sizeof(double));
          copy_polygons poly;
          piola__fracture_copy_polygons(m.dist + 4 * n, m.side[n], f->tets + 4 * m.parent[n], &poly);
          m.fraction[n] = poly.fraction;
        } else {
          /* one more cut: the copy's cell clipped by it */
          const size_t slot = (size_t)(MORE * n + had - 1);
          m.more_event[slot] = cut->crack, m.more_side[slot] = side;
          memcpy(m.more_dist + 4 * slot, cut->dist, 4 * sizeof(double));
          have[had] = (copy_cut){cut->crack, side, {cut->dist[0], cut->dist[1], cut->dist[2], cut->dist[3]}};
          cell_polygons poly;
          piola__fracture_cell_polygons(have, had + 1, f->tets + 4 * m.parent[n], &poly);
          m.fraction[n] = poly.fraction;
        }
      }
      for (int k = 0; k < 4; ++k) m.node_parent[4 * n + k] = corners[k];
      ++n;
    }
  }
  free(plan);
  /* the new copies' cuts, for faces_overlap */
  solid_fracture cut_view = *f;
  cut_view.event = m.event, cut_view.dist = m.dist, cut_view.side = m.side;
  cut_view.more_event = m.more_event, cut_view.more_dist = m.more_dist, cut_view.more_side = m.more_side;
  /* 3: nodes. Items of nodes no new copy touches stay together; elsewhere MBF04's rule */
  if (st == PIOLA_OK) {
    for (int32_t i = 0; i < FRACTURE_MAX_COPIES * f->tet_count; ++i) copies[i] = -1;
    for (int32_t c = 0; c < nc; ++c) {
      int32_t *slot = copies + FRACTURE_MAX_COPIES * m.parent[c];
      while (*slot >= 0) ++slot; /* at most FRACTURE_MAX_COPIES: three cuts deep */
      *slot = c;
    }
    int32_t *first = malloc(sizeof(int32_t) * (size_t)b->n);
    if (!first) st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "cut of '%s': out of memory", b->name);
    for (int32_t i = 0; i < 4 * nc; ++i) m.up[i] = i;
    for (int32_t i = 0; first && i < b->n; ++i) first[i] = -1;
    for (int32_t i = 0; first && i < 4 * nc; ++i) {
      int32_t p = m.node_parent[i];
      if (m.fresh[p]) continue;
      if (first[p] < 0) first[p] = i;
      else piola__union_find_join(m.up, first[p], i);
    }
    free(first);
    for (int32_t c = 0; c < nc && st == PIOLA_OK; ++c) {
      const int32_t t = m.parent[c];
      for (int k = 0; k < 4; ++k) {
        const int32_t u = f->neighbor[4 * t + k];
        if (u < t) continue; /* each face once (and none on the boundary) */
        for (int j = 0; j < FRACTURE_MAX_COPIES; ++j) {
          const int32_t d = copies[FRACTURE_MAX_COPIES * u + j];
          if (d < 0 || !faces_overlap(&cut_view, c, t, k, d, u)) continue;
          for (int i = 0; i < 3; ++i) {
            int32_t vertex = f->tets[4 * t + piola__cut_tet_face[k][i]];
            int32_t a = 4 * c + local_corner(f->tets + 4 * t, vertex);
            int32_t e = 4 * d + local_corner(f->tets + 4 * u, vertex);
            if (m.node_parent[a] == m.node_parent[e]) piola__union_find_join(m.up, a, e);
          }
        }
      }
    }
    /* number the classes in item order */
    const double *old_rest = piola_elastic_body_rest_positions(old);
    for (int32_t i = 0; i < 4 * nc; ++i) {
      int32_t r = piola__union_find_root(m.up, i);
      if (r == i) {
        int32_t p = m.node_parent[i];
        m.node_of[i] = m.nodes;
        memcpy(x + 3 * (size_t)m.nodes, b->x + 3 * (size_t)p, 3 * sizeof(double));
        memcpy(v + 3 * (size_t)m.nodes, b->v + 3 * (size_t)p, 3 * sizeof(double));
        memcpy(rest + 3 * (size_t)m.nodes, old_rest + 3 * (size_t)p, 3 * sizeof(double));
        m.node_parent[i] = p;
        m.nodes++;
      } else m.node_of[i] = m.node_of[r];
    }
  }
  /* 4: the rebuild */
  if (st == PIOLA_OK) {
    int32_t *node_parent = malloc(sizeof(int32_t) * (size_t)m.nodes);
    if (!node_parent) st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "cut of '%s': out of memory", b->name);
    for (int32_t i = 0; node_parent && i < 4 * nc; ++i) node_parent[m.node_of[i]] = m.node_parent[i];
    piola_tet_mesh mesh = {.vertex_count = m.nodes, .positions = rest, .tet_count = nc, .tets = m.node_of};
    body_change change = {.solid_rest = &mesh, .x = x, .v = v, .node_parent = node_parent,
                          .element_parent = m.element_parent, .element_fraction = m.fraction};
    if (st == PIOLA_OK) st = piola__body_rebuild(w, b, &change);
    free(node_parent);
  }
  if (st == PIOLA_OK) {
    /* 5: the new per-copy state */
    f = b->fracture;
    free(f->parent), free(f->event), free(f->dist), free(f->side), free(f->fraction), free(f->fragment);
    free(f->copies), free(f->more_event), free(f->more_side), free(f->more_dist);
    f->parent = m.parent, f->event = m.event, f->dist = m.dist, f->side = m.side;
    f->fraction = m.fraction, f->fragment = m.fragment, f->copies = copies;
    f->more_event = m.more_event, f->more_side = m.more_side, f->more_dist = m.more_dist;
    m.parent = m.event = m.fragment = m.more_event = NULL, m.dist = m.fraction = m.more_dist = NULL;
    m.side = m.more_side = NULL, copies = NULL;
    if (f->last_strain) {
      double *last = malloc(sizeof(double) * (size_t)nc);
      if (!last) st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "cut of '%s': out of memory", b->name);
      for (int32_t i = 0; last && i < nc; ++i) last[i] = f->last_strain[m.element_parent[i]];
      free(f->last_strain);
      f->last_strain = last;
    }
    f->copy_count = nc;
    f->cut_tets += newly_cut;
    number_fragments(nc, piola_elastic_body_tets(b->solid), m.nodes, m.up, f->fragment,
                     &f->fragment_count);
  }
  new_mesh_free(&m);
  free(copies), free(x), free(v), free(rest);
  return st;
}

/* Snaps a distance at least snap away from zero (0 counts as positive). */
static double snapped(double d, double snap) { return fabs(d) >= snap ? d : (d < 0 ? -snap : snap); }

/* The whole-solid cut by a plane: every uncut copy the plane crosses, one new crack. */
static piola_status cut_event(piola_world *w, world_body *b, const double point[3],
                              const double normal[3], int32_t *cut_count) {
  solid_fracture *f = b->fracture;
  const int32_t *tets = piola_elastic_body_tets(b->solid);
  const double nn = sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
  const double snap = piola__fracture_snap(b);
  double *s = malloc(sizeof(double) * (size_t)b->n);
  tet_cut *cuts = malloc(sizeof *cuts * (size_t)f->copy_count);
  if (!s || !cuts) {
    free(s), free(cuts);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "cut of '%s': out of memory", b->name);
  }
  for (int32_t i = 0; i < b->n; ++i) {
    double d = 0;
    for (int k = 0; k < 3; ++k) d += (b->x[3 * i + k] - point[k]) * normal[k] / nn;
    s[i] = snapped(d, snap);
  }
  int32_t count = 0;
  for (int32_t c = 0; c < f->copy_count; ++c) {
    cuts[count].copy = c, cuts[count].crack = f->events;
    for (int k = 0; k < 4; ++k) cuts[count].dist[k] = s[tets[4 * c + k]];
    count += cut_splits(f, c, f->events, cuts[count].dist);
  }
  piola_status st = split_copies(w, b, cuts, count);
  if (st == PIOLA_OK) b->fracture->events++;
  *cut_count = count;
  free(s), free(cuts);
  return st;
}

/* ------------------------------------------------------------------ cuts by a surface */

static void sub3(const double *a, const double *b, double out[3]) {
  for (int k = 0; k < 3; ++k) out[k] = a[k] - b[k];
}
static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void cross3(const double *a, const double *b, double out[3]) {
  out[0] = a[1] * b[2] - a[2] * b[1], out[1] = a[2] * b[0] - a[0] * b[2], out[2] = a[0] * b[1] - a[1] * b[0];
}

/* The point of triangle (a, b, c) closest to p (by regions of the triangle's plane). */
static void closest_on_triangle(const double *p, const double *a, const double *b, const double *c,
                                double out[3]) {
  double ab[3], ac[3], ap[3], bp[3], cp[3];
  sub3(b, a, ab), sub3(c, a, ac), sub3(p, a, ap);
  const double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
  if (d1 <= 0 && d2 <= 0) { memcpy(out, a, 3 * sizeof(double)); return; }
  sub3(p, b, bp);
  const double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
  if (d3 >= 0 && d4 <= d3) { memcpy(out, b, 3 * sizeof(double)); return; }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    for (int k = 0; k < 3; ++k) out[k] = a[k] + v * ab[k];
    return;
  }
  sub3(p, c, cp);
  const double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
  if (d6 >= 0 && d5 <= d6) { memcpy(out, c, 3 * sizeof(double)); return; }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double v = d2 / (d2 - d6);
    for (int k = 0; k < 3; ++k) out[k] = a[k] + v * ac[k];
    return;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    const double v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    for (int k = 0; k < 3; ++k) out[k] = b[k] + v * (c[k] - b[k]);
    return;
  }
  const double denom = 1.0 / (va + vb + vc), v = vb * denom, u = vc * denom;
  for (int k = 0; k < 3; ++k) out[k] = a[k] + v * ab[k] + u * ac[k];
}

/* Signed distance of p to the surface: the distance to the nearest triangle, signed by
 * that triangle's normal (of two equally near, the one p lies more squarely in front of);
 * planar: the distance to that triangle's plane instead (no larger beyond its border). */
static double surface_distance(const piola_tri_mesh *s, const double *p, int planar) {
  double best = INFINITY, value = 0, best_dot = 0;
  for (int32_t i = 0; i < s->triangle_count; ++i) {
    const int32_t *t = s->triangles + 3 * i;
    const double *a = s->positions + 3 * t[0], *b = s->positions + 3 * t[1], *c = s->positions + 3 * t[2];
    double q[3], d[3], ab[3], ac[3], n[3];
    closest_on_triangle(p, a, b, c, q);
    sub3(p, q, d);
    const double dd = sqrt(dot3(d, d));
    sub3(b, a, ab), sub3(c, a, ac), cross3(ab, ac, n);
    const double nn = sqrt(dot3(n, n));
    if (!(nn > 0)) continue;
    const double along = dot3(d, n) / nn;
    if (dd < best * (1 - 1e-12) || (dd <= best * (1 + 1e-12) && fabs(along) > fabs(best_dot))) {
      best = dd, best_dot = along;
      value = planar ? along : along >= 0 ? dd : -dd;
    }
  }
  return value;
}

/* Whether segment p q crosses a triangle of the surface (edges and corners included, to a
 * relative 1e-9, so a segment through an edge between two triangles counts). */
static int segment_crosses(const piola_tri_mesh *s, const double *p, const double *q) {
  for (int32_t i = 0; i < s->triangle_count; ++i) {
    const int32_t *t = s->triangles + 3 * i;
    const double *a = s->positions + 3 * t[0], *b = s->positions + 3 * t[1], *c = s->positions + 3 * t[2];
    double ab[3], ac[3], n[3], ap[3], aq[3];
    sub3(b, a, ab), sub3(c, a, ac), cross3(ab, ac, n), sub3(p, a, ap), sub3(q, a, aq);
    const double sp = dot3(ap, n), sq = dot3(aq, n);
    if ((sp > 0 && sq > 0) || (sp < 0 && sq < 0) || sp == sq) continue;
    const double r = sp / (sp - sq);
    double x[3];
    for (int k = 0; k < 3; ++k) x[k] = p[k] + r * (q[k] - p[k]);
    const double nn = dot3(n, n), tol = -1e-9 * nn;
    const double *corner[3] = {a, b, c};
    int inside = 1;
    for (int e = 0; e < 3 && inside; ++e) {
      double edge[3], to[3], w[3];
      sub3(corner[(e + 1) % 3], corner[e], edge), sub3(x, corner[e], to), cross3(edge, to, w);
      inside = dot3(w, n) >= tol;
    }
    if (inside) return 1;
  }
  return 0;
}

static const int8_t tet_edge[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

/* The cut by a surface: every uncut copy it passes all the way through, one new crack or
 * (crack >= 0, a moving blade: fracture_blade.c) more of that crack, from its values at the
 * vertices that hold them, so neighbouring copies cut at different times cross their shared
 * edges at the same points. As those values are kept for the later cuts, a continued crack
 * takes distances to the nearest triangle's plane: a corner beyond the surface's border now
 * does not get a larger value than the surface will give it once it is there. */
piola_status piola__fracture_surface_cut(piola_world *w, world_body *b, const piola_tri_mesh *surface,
                                         int32_t crack, int32_t *cut_count) {
  solid_fracture *f = b->fracture;
  const int32_t *tets = piola_elastic_body_tets(b->solid);
  const double snap = piola__fracture_snap(b);
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int32_t i = 0; i < surface->vertex_count; ++i)
    for (int k = 0; k < 3; ++k)
      lo[k] = fmin(lo[k], surface->positions[3 * i + k]), hi[k] = fmax(hi[k], surface->positions[3 * i + k]);
  double *s = malloc(sizeof(double) * (size_t)b->n);
  tet_cut *cuts = malloc(sizeof *cuts * (size_t)f->copy_count);
  if (!s || !cuts) {
    free(s), free(cuts);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "cut of '%s': out of memory", b->name);
  }
  for (int32_t i = 0; i < b->n; ++i) s[i] = NAN; /* computed on demand */
  int32_t count = 0;
  for (int32_t c = 0; c < f->copy_count; ++c) {
    const int32_t *corner = tets + 4 * c;
    int apart = 0; /* the copy's box misses the surface's */
    for (int k = 0; k < 3 && !apart; ++k) {
      double a = INFINITY, z = -INFINITY;
      for (int j = 0; j < 4; ++j) a = fmin(a, b->x[3 * corner[j] + k]), z = fmax(z, b->x[3 * corner[j] + k]);
      apart = z < lo[k] || a > hi[k];
    }
    if (apart) continue;
    int pos = 0, neg = 0;
    for (int j = 0; j < 4; ++j) {
      if (isnan(s[corner[j]])) s[corner[j]] = snapped(surface_distance(surface, b->x + 3 * corner[j], crack >= 0), snap);
      if (s[corner[j]] > 0) pos = 1;
      else neg = 1;
    }
    if (!(pos && neg)) continue;
    int through = 1;
    for (int e = 0; e < 6 && through; ++e) {
      const int32_t p = corner[tet_edge[e][0]], q = corner[tet_edge[e][1]];
      if ((s[p] > 0) != (s[q] > 0)) through = segment_crosses(surface, b->x + 3 * p, b->x + 3 * q);
    }
    if (!through) continue;
    cuts[count].copy = c, cuts[count].crack = crack >= 0 ? crack : f->events;
    /* a continued crack keeps its values at the vertices it reached before; where they
     * leave the copy on one side (the body moved across the surface since), the vertices
     * now on the other side take their new distances */
    int kept_pos = 0, kept_neg = 0;
    for (int k = 0; k < 4; ++k) {
      const int32_t vertex = f->tets[4 * f->parent[c] + k];
      const int kept = crack >= 0 && f->vertex_crack[vertex] == crack;
      cuts[count].dist[k] = kept ? f->vertex_value[vertex] : s[corner[k]];
      if (cuts[count].dist[k] > 0) kept_pos = 1;
      else kept_neg = 1;
    }
    for (int k = 0; k < 4 && !(kept_pos && kept_neg); ++k)
      if ((cuts[count].dist[k] > 0) != (s[corner[k]] > 0)) cuts[count].dist[k] = s[corner[k]];
    count += cut_splits(f, c, cuts[count].crack, cuts[count].dist);
  }
  piola_status st = split_copies(w, b, cuts, count);
  if (st == PIOLA_OK && crack < 0) b->fracture->events++;
  *cut_count = count;
  free(s), free(cuts);
  return st;
}

/* ------------------------------------------------------------------ scripted cuts */

static int by_time(const void *pa, const void *pb) {
  const piola_fracture_cut *a = pa, *b = pb;
  return a->time < b->time ? -1 : a->time > b->time;
}

static piola_status check_plane(const double point[3], const double normal[3], const char *name,
                                int32_t index) {
  for (int k = 0; k < 3; ++k)
    if (!isfinite(point[k]) || !isfinite(normal[k]))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "fracture of '%s': cut %d is not finite",
                        name, (int)index);
  if (!(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2] > 0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "fracture of '%s': cut %d has a zero normal",
                      name, (int)index);
  return PIOLA_OK;
}

static piola_status check_blade(const piola_tri_mesh *s, const char *name, int32_t index) {
  if (!s || s->triangle_count < 1 || s->vertex_count < 3 || !s->positions || !s->triangles)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "fracture of '%s': cut %d has no triangles", name,
                      (int)index);
  for (int32_t i = 0; i < 3 * s->vertex_count; ++i)
    if (!isfinite(s->positions[i]))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "fracture of '%s': cut %d: vertex %d is not finite",
                        name, (int)index, (int)(i / 3));
  for (int32_t i = 0; i < 3 * s->triangle_count; ++i)
    if (s->triangles[i] < 0 || s->triangles[i] >= s->vertex_count)
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "fracture of '%s': cut %d: triangle %d names vertex %d of %d", name, (int)index,
                        (int)(i / 3), (int)s->triangles[i], (int)s->vertex_count);
  return PIOLA_OK;
}

static piola_status copy_blade(const piola_tri_mesh *s, piola_tri_mesh *out) {
  out->vertex_count = s->vertex_count, out->triangle_count = s->triangle_count;
  out->positions = malloc(3 * sizeof(double) * (size_t)s->vertex_count);
  out->triangles = malloc(3 * sizeof(int32_t) * (size_t)s->triangle_count);
  if (!out->positions || !out->triangles)
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fracture: out of memory");
  memcpy(out->positions, s->positions, 3 * sizeof(double) * (size_t)s->vertex_count);
  memcpy(out->triangles, s->triangles, 3 * sizeof(int32_t) * (size_t)s->triangle_count);
  return PIOLA_OK;
}

static void free_blades(piola_tri_mesh *blades, int32_t count) {
  for (int32_t i = 0; blades && i < count; ++i) piola_tri_mesh_free(&blades[i]);
  free(blades);
}

static piola_status ensure_state(world_body *b) {
  if (b->fracture) return PIOLA_OK;
  return fracture_create(b, &b->fracture);
}

static piola_status apply_due(piola_world *w, world_body *b) {
  solid_fracture *f = b->fracture;
  for (int32_t applied = 0; f->next_cut < f->cut_count; ++applied) {
    const piola_fracture_cut *c = &f->cuts[f->next_cut];
    if (c->time > w->time || (f->max_cuts_per_step > 0 && applied >= f->max_cuts_per_step)) break;
    const double point[3] = {c->point.x, c->point.y, c->point.z};
    const double normal[3] = {c->normal.x, c->normal.y, c->normal.z};
    int32_t count;
    if (piola__fracture_cut_moves(c)) PIOLA_TRY(piola__fracture_blade_start(w, b, f->next_cut));
    else if (c->blade) PIOLA_TRY(piola__fracture_surface_cut(w, b, c->blade, -1, &count));
    else PIOLA_TRY(cut_event(w, b, point, normal, &count));
    f = b->fracture;
    f->next_cut++;
  }
  return PIOLA_OK;
}

/* ------------------------------------------------------------------ the criteria */

/* The largest principal Cauchy stress of copy c from the last update (Pa) and its direction.
 * With F = U Fhat V^T and P = U Phat V^T, sigma = P F^T / J = U diag(Phat Fhat / J) U^T: its
 * principal values are Phat_i Fhat_i / J, along the columns of U. -inf for an inverted or
 * flat copy (no tension to speak of). */
static double principal_stress(const piola_elastic_body *e, int32_t c, double scale, double dir[3]) {
  const double *fc = piola_elastic_body_fhat(e) + 3 * c;
  const double j = fc[0] * fc[1] * fc[2];
  if (!(j > 0)) return -INFINITY;
  double phat[3], worst = -INFINITY;
  piola_material_stress(&e->materials[e->tet_material[c]], fc, phat);
  for (int i = 0; i < 3; ++i) {
    const double sigma = scale * phat[i] * fc[i] / j;
    if (sigma > worst) {
      worst = sigma;
      for (int k = 0; k < 3; ++k) dir[k] = e->u[3 * k + i][c];
    }
  }
  return worst;
}

/* Gradients (world space, current positions x) of the four barycentric coordinates of a
 * tet with corners p[4]; 0 when the tet is flat. */
static int barycentric_gradients(const double *x, const int32_t p[4], double g[4][3]) {
  double d[3][3];
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) d[r][k] = x[3 * p[r + 1] + k] - x[3 * p[0] + k];
  /* rows of d are the edges; the gradients of lambda_1..3 are the columns of d^-1 */
  const double c0[3] = {d[1][1] * d[2][2] - d[1][2] * d[2][1], d[1][2] * d[2][0] - d[1][0] * d[2][2],
                        d[1][0] * d[2][1] - d[1][1] * d[2][0]};
  const double det = d[0][0] * c0[0] + d[0][1] * c0[1] + d[0][2] * c0[2];
  if (!(fabs(det) > 0) || !isfinite(det)) return 0;
  const double c1[3] = {d[2][1] * d[0][2] - d[2][2] * d[0][1], d[2][2] * d[0][0] - d[2][0] * d[0][2],
                        d[2][0] * d[0][1] - d[2][1] * d[0][0]};
  const double c2[3] = {d[0][1] * d[1][2] - d[0][2] * d[1][1], d[0][2] * d[1][0] - d[0][0] * d[1][2],
                        d[0][0] * d[1][1] - d[0][1] * d[1][0]};
  for (int k = 0; k < 3; ++k) {
    g[1][k] = c0[k] / det, g[2][k] = c1[k] / det, g[3][k] = c2[k] / det;
    g[0][k] = -(g[1][k] + g[2][k] + g[3][k]);
  }
  return 1;
}

/* Snaps v (a new corner value) away from zero and keeps it as crack's value at vertex,
 * reached at time now (s). */
static double keep_value(solid_fracture *f, int32_t vertex, int32_t crack, double v, double snap, double now) {
  v = snapped(v, snap);
  f->vertex_crack[vertex] = crack, f->vertex_value[vertex] = v, f->vertex_time[vertex] = now;
  return v;
}

/* When a crack front reached original tet t (s), or +inf when t is not on a front. A
 * front runs along the faces t shares with cut neighbours: an edge of such a face whose
 * corners hold values of one crack with opposite signs is crossed by that neighbour's crack
 * polygon (crossings elsewhere, where values continued from different tets happen to differ
 * in sign, are no crack). The edge was reached when the later of its corners got its value;
 * the front reached t at its earliest crossed edge. */
static double front_reached(const solid_fracture *f, int32_t t) {
  const int32_t *ids = f->tets + 4 * t;
  double when = INFINITY;
  for (int k = 0; k < 4; ++k) {
    const int32_t nb = f->neighbor[4 * t + k];
    if (nb < 0 || f->copies[FRACTURE_MAX_COPIES * nb + 1] < 0) continue;
    for (int e = 0; e < 3; ++e) {
      const int32_t a = ids[piola__cut_tet_face[k][e]], c = ids[piola__cut_tet_face[k][(e + 1) % 3]];
      if (f->vertex_crack[a] < 0 || f->vertex_crack[a] != f->vertex_crack[c] ||
          (f->vertex_value[a] > 0) == (f->vertex_value[c] > 0))
        continue;
      when = fmin(when, fmax(f->vertex_time[a], f->vertex_time[c]));
    }
  }
  return when;
}

/* The length a crack crosses in copy c (m): the mean of its six rest edges. */
static double rest_span(const piola_elastic_body *e, int32_t c) {
  const double *rest = piola_elastic_body_rest_positions(e);
  const int32_t *p = piola_elastic_body_tets(e) + 4 * c;
  double sum = 0;
  for (int k = 0; k < 6; ++k) {
    const double *a = rest + 3 * p[tet_edge[k][0]], *q = rest + 3 * p[tet_edge[k][1]];
    sum += sqrt((a[0] - q[0]) * (a[0] - q[0]) + (a[1] - q[1]) * (a[1] - q[1]) + (a[2] - q[2]) * (a[2] - q[2]));
  }
  return sum / 6;
}

/* The crack of copy c (original tet t, uncut, corners `nodes`) continued from the crack values
 * its corners hold (a crack is the zero set of one value per original vertex, so its pieces
 * meet edge to edge). It continues where two corners of an edge hold values of opposite sign
 * (the crack crosses that edge): with three known corners the fourth takes the value that
 * turns the crack closest to normal to dir (the direction of the largest principal stress);
 * with two, the crack is the plane through their crossing normal to dir. Returns 0 when no
 * edge is crossed, 1 with dist and crack filled in (the new corner values kept), -1 when it
 * cannot continue (corners of different cracks, a degenerate tet or direction). */
static int continued_crack(solid_fracture *f, const double *x, const int32_t *nodes, int32_t t,
                           const double dir[3], double snap, double now, double dist[4], int32_t *crack) {
  const int32_t *ids = f->tets + 4 * t;
  int known[4], count = 0, pos = 0, neg = 0;
  *crack = -1;
  for (int k = 0; k < 4; ++k) {
    const int32_t owner = f->vertex_crack[ids[k]];
    known[k] = owner >= 0;
    if (!known[k]) continue;
    if (*crack >= 0 && owner != *crack) return -1;
    *crack = owner, dist[k] = f->vertex_value[ids[k]], ++count;
    if (dist[k] > 0) pos = 1;
    else neg = 1;
  }
  if (!(pos && neg)) return 0;
  if (count == 3) {
    /* maximize (g . n)^2 / |g|^2 over d, g = g0 + d g1: d = (a e - b c) / (b e - a h) */
    double g[4][3], g0[3] = {0, 0, 0};
    if (!barycentric_gradients(x, nodes, g)) return -1;
    int free_corner = 0;
    for (int k = 0; k < 4; ++k) {
      if (!known[k]) free_corner = k;
      else
        for (int i = 0; i < 3; ++i) g0[i] += dist[k] * g[k][i];
    }
    const double *g1 = g[free_corner];
    double a = 0, bb = 0, c = 0, e = 0, h = 0;
    for (int i = 0; i < 3; ++i)
      a += g0[i] * dir[i], bb += g1[i] * dir[i], c += g0[i] * g0[i], e += g0[i] * g1[i], h += g1[i] * g1[i];
    const double d = (a * e - bb * c) / (bb * e - a * h);
    if (!isfinite(d)) return -1;
    dist[free_corner] = keep_value(f, ids[free_corner], *crack, d, snap, now);
  } else if (count == 2) {
    /* the plane through the crossing X of the known edge p q, normal to dir, scaled to p's
     * value (q's matches: X divides p q in the ratio of their values) */
    int p = -1, q = -1;
    for (int k = 0; k < 4; ++k)
      if (known[k]) {
        if (p < 0) p = k;
        else q = k;
      }
    const double r = dist[p] / (dist[p] - dist[q]);
    double cross[3], along_p = 0;
    for (int i = 0; i < 3; ++i) cross[i] = x[3 * nodes[p] + i] + r * (x[3 * nodes[q] + i] - x[3 * nodes[p] + i]);
    for (int i = 0; i < 3; ++i) along_p += (x[3 * nodes[p] + i] - cross[i]) * dir[i];
    const double scale = dist[p] / along_p;
    if (!isfinite(scale) || !(fabs(along_p) > 1e-6 * snap)) return -1;
    for (int k = 0; k < 4; ++k) {
      if (known[k]) continue;
      double along = 0;
      for (int i = 0; i < 3; ++i) along += (x[3 * nodes[k] + i] - cross[i]) * dir[i];
      dist[k] = keep_value(f, ids[k], *crack, scale * along, snap, now);
    }
  }
  return 1;
}

/* The mean unit normal (current positions) of the cracks in the cut face neighbours of
 * original tet t; 0 when none is cut. A crack front continues along it. */
static int neighbour_crack_normal(const solid_fracture *f, const double *x, const int32_t *nodes, int32_t t,
                                  double normal[3]) {
  int found = 0;
  normal[0] = normal[1] = normal[2] = 0;
  for (int k = 0; k < 4; ++k) {
    const int32_t nb = f->neighbor[4 * t + k];
    if (nb < 0 || f->copies[FRACTURE_MAX_COPIES * nb + 1] < 0) continue;
    const int32_t c = f->copies[FRACTURE_MAX_COPIES * nb];
    double g[4][3], n[3] = {0, 0, 0};
    if (!barycentric_gradients(x, nodes + 4 * c, g)) continue;
    for (int i = 0; i < 4; ++i)
      for (int a = 0; a < 3; ++a) n[a] += f->dist[4 * c + i] * g[i][a];
    const double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0) || !isfinite(len)) continue;
    const double sign = n[0] * normal[0] + n[1] * normal[1] + n[2] * normal[2] < 0 ? -1 : 1;
    for (int a = 0; a < 3; ++a) normal[a] += sign * n[a] / len;
    found = 1;
  }
  const double len = sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
  if (!found || !(len > 0)) return 0;
  for (int a = 0; a < 3; ++a) normal[a] /= len;
  return 1;
}

typedef struct candidate {
  double measure, dir[3];
  int32_t copy;
} candidate;

/* decreasing measure, then copy order: a deterministic pass */
static int by_measure(const void *pa, const void *pb) {
  const candidate *a = pa, *b = pb;
  if (a->measure != b->measure) return a->measure > b->measure ? -1 : 1;
  return a->copy < b->copy ? -1 : a->copy > b->copy;
}

/* The breaking criteria (stress, plastic strain): before each step, every uncut copy on a
 * crack's front (front_reached) whose measure passes growth_threshold is cut so that the
 * crack runs on into it (continued_crack), in order of decreasing measure, at most
 * max_tets_per_step (0: no limit), once the crack has had the time to cross it at
 * max_crack_speed. If none grows or waits, the one with the largest measure past threshold
 * starts a new crack unless a crack touches it (a corner holds a crack's value): the plane
 * through its centroid normal to its largest principal stress, in that copy only. */
static piola_status apply_criterion(piola_world *w, world_body *b) {
  solid_fracture *f = b->fracture;
  if (f->criterion == PIOLA_FRACTURE_SCRIPTED) return PIOLA_OK;
  const piola_elastic_body *e = b->solid;
  const int32_t *nodes = piola_elastic_body_tets(e);
  const double scale = piola_track_eval(&b->stiffness_scale, w->time);
  const double *strain = f->criterion == PIOLA_FRACTURE_PLASTIC_STRAIN && b->plastic
                             ? piola_plastic_state_plastic_strain(b->plastic) : NULL;
  if (f->criterion == PIOLA_FRACTURE_PLASTIC_STRAIN && !strain) return PIOLA_OK;
  if (strain && !f->last_strain) {
    f->last_strain = malloc(sizeof(double) * (size_t)f->copy_count);
    if (!f->last_strain) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fracture of '%s': out of memory", b->name);
    memcpy(f->last_strain, strain, sizeof(double) * (size_t)f->copy_count);
  }
  /* a front grows past growth_threshold, a new crack starts past threshold */
  const double grow = f->growth_threshold > 0 ? f->growth_threshold : f->threshold;
  const double lowest = fmin(grow, f->threshold);
  candidate *list = malloc(sizeof *list * (size_t)f->copy_count);
  if (!list) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fracture of '%s': out of memory", b->name);
  int32_t n = 0;
  for (int32_t c = 0; c < f->copy_count; ++c) {
    /* ductile: only while the tet still flows (a piece that unloaded tears no further) */
    const int flowing = strain && strain[c] > f->last_strain[c];
    if (strain) f->last_strain[c] = strain[c];
    if (f->event[c] >= 0 || (strain && !(flowing && strain[c] > lowest))) continue;
    candidate k;
    const double stress = principal_stress(e, c, scale, k.dir);
    k.measure = strain ? strain[c] : stress;
    k.copy = c;
    if (k.measure > lowest && isfinite(stress)) list[n++] = k;
  }
  if (n == 0) {
    free(list);
    return PIOLA_OK;
  }
  tet_cut *cuts = malloc(sizeof *cuts * (size_t)n);
  if (!cuts) {
    free(list);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fracture of '%s': out of memory", b->name);
  }
  qsort(list, (size_t)n, sizeof *list, by_measure);
  const double snap = piola__fracture_snap(b);
  const int32_t most = f->max_tets_per_step > 0 ? f->max_tets_per_step : INT32_MAX;
  int32_t count = 0;
  int waiting = 0; /* a crack front that may not advance yet (max_crack_speed) */
  for (int32_t i = 0; i < n && count < most; ++i) {
    const int32_t c = list[i].copy, t = f->parent[c];
    if (!(list[i].measure > grow)) continue;
    /* only a front grows, and it crosses a tet in no less than the tet's span over the
     * speed limit */
    const double reached = front_reached(f, t);
    if (!isfinite(reached)) continue;
    if (f->max_crack_speed > 0 && w->time < reached + rest_span(e, c) / f->max_crack_speed) {
      waiting = 1;
      continue;
    }
    tet_cut *cut = &cuts[count];
    cut->copy = c;
    /* a brittle crack runs on along its plane in the cut neighbours (a front that turned
     * with each tet's own stress direction would crumple where the stress is noisy); a
     * ductile one follows the stress across the band where the flow localized */
    double dir[3];
    if (f->criterion != PIOLA_FRACTURE_STRESS || !neighbour_crack_normal(f, b->x, nodes, t, dir))
      memcpy(dir, list[i].dir, sizeof dir);
    if (continued_crack(f, b->x, nodes + 4 * c, t, dir, snap, w->time, cut->dist, &cut->crack) != 1)
      continue;
    ++count;
  }
  /* when no crack grew or waits to (cracks relieve the stress by growing first): a new
   * crack at the candidate with the largest measure that no crack touches */
  int started = 0, touched = 1;
  int32_t pick = -1;
  while (count == 0 && !waiting && touched && ++pick < n && list[pick].measure > f->threshold) {
    const int32_t *ids = f->tets + 4 * f->parent[list[pick].copy];
    touched = 0;
    for (int k = 0; k < 4; ++k) touched |= f->vertex_crack[ids[k]] >= 0;
  }
  const int32_t c = pick >= 0 && pick < n ? list[pick].copy : -1;
  if (count == 0 && !waiting && !touched && c >= 0 && list[pick].measure > f->threshold) {
    double point[3] = {0, 0, 0};
    for (int k = 0; k < 4; ++k)
      for (int a = 0; a < 3; ++a) point[a] += 0.25 * b->x[3 * nodes[4 * c + k] + a];
    int pos = 0, neg = 0;
    for (int k = 0; k < 4; ++k) {
      double d = 0;
      for (int a = 0; a < 3; ++a) d += (b->x[3 * nodes[4 * c + k] + a] - point[a]) * list[pick].dir[a];
      cuts[0].dist[k] = snapped(d, snap);
      if (cuts[0].dist[k] > 0) pos = 1;
      else neg = 1;
    }
    cuts[0].copy = c, cuts[0].crack = f->grown_crack >= 0 ? f->grown_crack : f->events;
    started = count = pos && neg;
  }
  piola_status st = split_copies(w, b, cuts, count);
  if (st == PIOLA_OK && started && b->fracture->grown_crack < 0) b->fracture->grown_crack = b->fracture->events++;
  free(list), free(cuts);
  return st;
}

piola_status piola__world_fracture_step(piola_world *w) {
  for (int32_t i = 0; i < w->body_count; ++i)
    if (w->bodies[i].kind == PIOLA_BODY_SOLID && w->bodies[i].fracture) {
      PIOLA_TRY(piola__fracture_blades_sweep(w, &w->bodies[i]));
      PIOLA_TRY(apply_due(w, &w->bodies[i]));
      PIOLA_TRY(apply_criterion(w, &w->bodies[i]));
    }
  return PIOLA_OK;
}

/* ------------------------------------------------------------------ public */

piola_fracture_def piola_default_fracture_def(void) {
  piola_fracture_def def;
  memset(&def, 0, sizeof def);
  return def;
}

static world_body *solid_of(const piola_world *w, int32_t solid) {
  return w ? piola__world_body_of(w, PIOLA_BODY_SOLID, solid) : NULL;
}

piola_status piola_world_solid_set_fracture(piola_world *w, int32_t solid, const piola_fracture_def *def) {
  world_body *b = solid_of(w, solid);
  if (!b || !def) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "set_fracture: no solid %d", (int)solid);
  if (def->cut_count < 0 || (def->cut_count > 0 && !def->cuts) || def->max_cuts_per_step < 0)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "fracture of '%s': bad cut list", b->name);
  if (piola__local_split(b->solid)) /* its criteria read every tet's state */
    return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED,
                      "fracture of '%s': the solid is split in the local mode (it holds only its "
                      "part of the tets' state); set fracture before splitting it",
                      b->name);
  if (def->criterion != PIOLA_FRACTURE_SCRIPTED && def->criterion != PIOLA_FRACTURE_STRESS &&
      def->criterion != PIOLA_FRACTURE_PLASTIC_STRAIN)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "fracture of '%s': unknown criterion %d", b->name,
                      (int)def->criterion);
  if (def->criterion != PIOLA_FRACTURE_SCRIPTED && !(def->threshold > 0 && isfinite(def->threshold)))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "fracture of '%s': the threshold must be > 0 (%s), got %g", b->name,
                      def->criterion == PIOLA_FRACTURE_STRESS ? "Pa" : "plastic log strain", def->threshold);
  if (def->criterion == PIOLA_FRACTURE_PLASTIC_STRAIN && !b->plastic)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "fracture of '%s': the plastic_strain criterion needs the solid's plasticity", b->name);
  if (def->max_tets_per_step < 0)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "fracture of '%s': max_tets_per_step must be >= 0", b->name);
  if (!(def->growth_threshold >= 0 && isfinite(def->growth_threshold)))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "fracture of '%s': growth_threshold must be >= 0, got %g",
                      b->name, def->growth_threshold);
  if (!(def->max_crack_speed >= 0 && isfinite(def->max_crack_speed)))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "fracture of '%s': max_crack_speed must be >= 0 (m/s), got %g",
                      b->name, def->max_crack_speed);
  for (int32_t i = 0; i < def->cut_count; ++i) {
    const piola_fracture_cut *c = &def->cuts[i];
    const double point[3] = {c->point.x, c->point.y, c->point.z};
    const double normal[3] = {c->normal.x, c->normal.y, c->normal.z};
    if (c->blade) PIOLA_TRY(check_blade(c->blade, b->name, i));
    else PIOLA_TRY(check_plane(point, normal, b->name, i));
    if (!isfinite(c->time))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "fracture of '%s': cut %d time is not finite", b->name, (int)i);
    PIOLA_TRY(piola__fracture_check_motion(c, b->name, i));
  }
  const size_t slots = (size_t)(def->cut_count > 0 ? def->cut_count : 1);
  piola_fracture_cut *cuts = malloc(sizeof *cuts * slots);
  piola_tri_mesh *blades = calloc(slots, sizeof *blades);
  int32_t *sweep_crack = malloc(sizeof(int32_t) * slots);
  double *swept_to = malloc(sizeof(double) * slots);
  if (!cuts || !blades || !sweep_crack || !swept_to) {
    free(cuts), free(blades), free(sweep_crack), free(swept_to);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fracture of '%s': out of memory", b->name);
  }
  if (def->cut_count > 0) memcpy(cuts, def->cuts, sizeof *cuts * (size_t)def->cut_count);
  /* insertion sort keeps cuts of equal time in the given order (qsort need not) */
  for (int32_t i = 1; i < def->cut_count; ++i)
    for (int32_t j = i; j > 0 && by_time(&cuts[j - 1], &cuts[j]) > 0; --j) {
      piola_fracture_cut tmp = cuts[j];
      cuts[j] = cuts[j - 1], cuts[j - 1] = tmp;
    }
  piola_status st = PIOLA_OK;
  for (int32_t i = 0; i < def->cut_count && st == PIOLA_OK; ++i)
    if (cuts[i].blade) {
      st = copy_blade(cuts[i].blade, &blades[i]);
      cuts[i].blade = &blades[i];
    }
  if (st == PIOLA_OK) st = ensure_state(b);
  if (st != PIOLA_OK) {
    free_blades(blades, def->cut_count);
    free(cuts), free(sweep_crack), free(swept_to);
    return st;
  }
  free_blades(b->fracture->blades, b->fracture->cut_count);
  free(b->fracture->cuts), free(b->fracture->sweep_crack), free(b->fracture->swept_to);
  for (int32_t i = 0; i < def->cut_count; ++i) sweep_crack[i] = -1, swept_to[i] = -INFINITY;
  b->fracture->sweep_crack = sweep_crack, b->fracture->swept_to = swept_to;
  b->fracture->cuts = cuts;
  b->fracture->blades = blades;
  b->fracture->cut_count = def->cut_count;
  b->fracture->next_cut = 0;
  b->fracture->max_cuts_per_step = def->max_cuts_per_step;
  b->fracture->max_tets_per_step = def->max_tets_per_step;
  b->fracture->criterion = def->criterion;
  b->fracture->threshold = def->threshold;
  b->fracture->max_crack_speed = def->max_crack_speed;
  b->fracture->growth_threshold = def->growth_threshold;
  return apply_due(w, b);
}

piola_status piola_world_solid_cut(piola_world *w, int32_t solid, const double point[3],
                                   const double normal[3], int32_t *cut_tets) {
  world_body *b = solid_of(w, solid);
  if (!b || !point || !normal) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "cut: no solid %d", (int)solid);
  PIOLA_TRY(check_plane(point, normal, b->name, 0));
  PIOLA_TRY(ensure_state(b));
  int32_t count = 0;
  PIOLA_TRY(cut_event(w, b, point, normal, &count));
  if (cut_tets) *cut_tets = count;
  return PIOLA_OK;
}

piola_status piola_world_solid_cut_by_surface(piola_world *w, int32_t solid, const piola_tri_mesh *surface,
                                              int32_t *cut_tets) {
  world_body *b = solid_of(w, solid);
  if (!b) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "cut: no solid %d", (int)solid);
  PIOLA_TRY(check_blade(surface, b->name, 0));
  PIOLA_TRY(ensure_state(b));
  int32_t count = 0;
  PIOLA_TRY(piola__fracture_surface_cut(w, b, surface, -1, &count));
  if (cut_tets) *cut_tets = count;
  return PIOLA_OK;
}

int piola_world_solid_has_fracture(const piola_world *w, int32_t solid) {
  const world_body *b = solid_of(w, solid);
  return b && b->fracture;
}

int32_t piola_world_solid_fragment_count(const piola_world *w, int32_t solid) {
  const world_body *b = solid_of(w, solid);
  return !b ? 0 : b->fracture ? b->fracture->fragment_count : 1;
}

int32_t piola_world_solid_cut_tet_count(const piola_world *w, int32_t solid) {
  const world_body *b = solid_of(w, solid);
  return b && b->fracture ? b->fracture->cut_tets : 0;
}

const int32_t *piola_world_solid_fragments(const piola_world *w, int32_t solid) {
  const world_body *b = solid_of(w, solid);
  return b && b->fracture ? b->fracture->fragment : NULL;
}

const double *piola_world_solid_material_fractions(const piola_world *w, int32_t solid) {
  const world_body *b = solid_of(w, solid);
  return b && b->fracture ? b->fracture->fraction : NULL;
}

const int32_t *piola_world_solid_parent_tets(const piola_world *w, int32_t solid) {
  const world_body *b = solid_of(w, solid);
  return b && b->fracture ? b->fracture->parent : NULL;
}
