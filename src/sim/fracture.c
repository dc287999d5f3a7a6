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
#include "sim/fracture_internal.h"
#include "sim/world_internal.h"

/* distances closer to the plane than this share of the smallest rest altitude are pushed
 * away from it: the crack moves by at most that much */
#define SNAP_SHARE 1e-4
/* shared face areas below this share of the face are no material contact */
#define OVERLAP_SHARE 1e-12

void piola__fracture_free(solid_fracture *f) {
  if (!f) return;
  free(f->cuts), free(f->tets), free(f->neighbor), free(f->parent), free(f->event), free(f->dist);
  free(f->side), free(f->fraction), free(f->fragment), free(f->copies);
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
    f->copies = malloc(2 * sizeof(int32_t) * (size_t)nt);
  }
  if (!f || !keys || !f->tets || !f->neighbor || !f->parent || !f->event || !f->dist || !f->side ||
      !f->fraction || !f->fragment || !f->copies) {
    free(keys);
    piola__fracture_free(f);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fracture of '%s': out of memory", b->name);
  }
  memcpy(f->tets, piola_elastic_body_tets(b->solid), 4 * sizeof(int32_t) * (size_t)nt);
  for (int32_t t = 0; t < nt; ++t) {
    f->parent[t] = t, f->event[t] = -1, f->side[t] = 1, f->fraction[t] = 1.0;
    f->copies[2 * t] = t, f->copies[2 * t + 1] = -1;
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
  double poly[8][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  int size = 3;
  for (int c = 0; c < n && size > 0; ++c) {
    double next[8][3], g[8];
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
 * common part of their shared face of positive area. */
static int faces_overlap(const solid_fracture *f, const int32_t *event, const double *dist,
                         const int8_t *side, int32_t c, int32_t t, int k, int32_t d, int32_t u) {
  double value[2][3];
  int n = 0;
  const int32_t copy[2] = {c, d}, tet[2] = {t, u};
  for (int s = 0; s < 2; ++s) {
    if (event[copy[s]] < 0) continue;
    for (int i = 0; i < 3; ++i) {
      int32_t vertex = f->tets[4 * t + piola__cut_tet_face[k][i]];
      int corner = local_corner(f->tets + 4 * tet[s], vertex);
      value[n][i] = side[copy[s]] * dist[4 * copy[s] + corner];
    }
    ++n;
  }
  return clipped_face_area(value, n) > OVERLAP_SHARE * sqrt(3.0);
}

/* ------------------------------------------------------------------ the cut event */

typedef struct new_mesh {
  int32_t copies, nodes;
  int32_t *parent, *event, *element_parent, *node_of, *node_parent, *up, *fragment;
  int8_t *side, *fresh;
  double *dist, *fraction;
} new_mesh;

static void new_mesh_free(new_mesh *m) {
  free(m->parent), free(m->event), free(m->element_parent), free(m->node_of), free(m->node_parent);
  free(m->up), free(m->fragment), free(m->side), free(m->fresh), free(m->dist), free(m->fraction);
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

static piola_status cut_event(piola_world *w, world_body *b, const double point[3],
                              const double normal[3], int32_t *cut_count) {
  solid_fracture *f = b->fracture;
  const piola_elastic_body *old = b->solid;
  const int32_t *old_tets = piola_elastic_body_tets(old);
  const double nn = sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
  const double snap = SNAP_SHARE * piola_elastic_body_min_rest_altitude(old);
  double *s = malloc(sizeof(double) * (size_t)b->n);
  if (!s) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "cut of '%s': out of memory", b->name);
  for (int32_t i = 0; i < b->n; ++i) {
    double d = 0;
    for (int k = 0; k < 3; ++k) d += (b->x[3 * i + k] - point[k]) * normal[k] / nn;
    s[i] = fabs(d) >= snap ? d : (d < 0 ? -snap : snap);
  }
  /* 2: the new copies */
  int32_t split = 0;
  for (int32_t c = 0; c < f->copy_count; ++c) {
    if (f->event[c] >= 0) continue;
    int pos = 0, neg = 0;
    for (int k = 0; k < 4; ++k) {
      if (s[old_tets[4 * c + k]] > 0) pos = 1;
      else neg = 1;
    }
    split += pos && neg;
  }
  *cut_count = split;
  if (split == 0) {
    free(s);
    f->events++;
    return PIOLA_OK;
  }
  new_mesh m = {0};
  const int32_t nc = f->copy_count + split;
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
  int32_t *copies = malloc(2 * sizeof(int32_t) * (size_t)f->tet_count);
  double *x = malloc(3 * sizeof(double) * 4 * (size_t)nc), *v = malloc(3 * sizeof(double) * 4 * (size_t)nc);
  double *rest = malloc(3 * sizeof(double) * 4 * (size_t)nc);
  piola_status st = PIOLA_OK;
  if (!m.parent || !m.event || !m.element_parent || !m.node_of || !m.node_parent || !m.up ||
      !m.fragment || !m.side || !m.fresh || !m.dist || !m.fraction || !copies || !x || !v || !rest)
    st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "cut of '%s': out of memory", b->name);
  int32_t n = 0;
  for (int32_t c = 0; c < f->copy_count && st == PIOLA_OK; ++c) {
    const int32_t *corners = old_tets + 4 * c;
    int pos = 0, neg = 0;
    for (int k = 0; k < 4; ++k) {
      if (s[corners[k]] > 0) pos = 1;
      else neg = 1;
    }
    const int cut = f->event[c] < 0 && pos && neg;
    for (int copy = 0; copy < (cut ? 2 : 1); ++copy) {
      m.parent[n] = f->parent[c];
      m.element_parent[n] = c;
      m.event[n] = cut ? f->events : f->event[c];
      m.side[n] = cut ? (copy == 0 ? 1 : -1) : f->side[c];
      m.fraction[n] = f->fraction[c];
      memcpy(m.dist + 4 * n, f->dist + 4 * c, 4 * sizeof(double));
      if (cut) {
        for (int k = 0; k < 4; ++k) m.dist[4 * n + k] = s[corners[k]], m.fresh[corners[k]] = 1;
        copy_polygons poly;
        piola__fracture_copy_polygons(m.dist + 4 * n, m.side[n], f->tets + 4 * m.parent[n], &poly);
        m.fraction[n] = poly.fraction;
      }
      for (int k = 0; k < 4; ++k) m.node_parent[4 * n + k] = corners[k];
      ++n;
    }
  }
  /* 3: nodes. Items of nodes no new copy touches stay together; elsewhere MBF04's rule */
  if (st == PIOLA_OK) {
    for (int32_t t = 0; t < f->tet_count; ++t) copies[2 * t] = copies[2 * t + 1] = -1;
    for (int32_t c = 0; c < nc; ++c) copies[2 * m.parent[c] + (copies[2 * m.parent[c]] >= 0)] = c;
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
        for (int j = 0; j < 2; ++j) {
          const int32_t d = copies[2 * u + j];
          if (d < 0 || !faces_overlap(f, m.event, m.dist, m.side, c, t, k, d, u)) continue;
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
    free(f->copies);
    f->parent = m.parent, f->event = m.event, f->dist = m.dist, f->side = m.side;
    f->fraction = m.fraction, f->fragment = m.fragment, f->copies = copies;
    m.parent = m.event = m.fragment = NULL, m.dist = m.fraction = NULL, m.side = NULL, copies = NULL;
    f->copy_count = nc;
    f->cut_tets += split;
    f->events++;
    number_fragments(nc, piola_elastic_body_tets(b->solid), m.nodes, m.up, f->fragment,
                     &f->fragment_count);
  }
  new_mesh_free(&m);
  free(copies), free(x), free(v), free(rest), free(s);
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

static piola_status ensure_state(world_body *b) {
  if (b->fracture) return PIOLA_OK;
  if (b->self_collision.enabled)
    return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED,
                      "fracture of '%s': not with self_collision (the collision surface would be "
                      "the copies' whole tets, which overlap across every crack)", b->name);
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
    PIOLA_TRY(cut_event(w, b, point, normal, &count));
    f = b->fracture;
    f->next_cut++;
  }
  return PIOLA_OK;
}

/* The stress criterion: the uncut copy with the largest principal Cauchy stress of the last
 * update. With F = U Fhat V^T and P = U Phat V^T, sigma = P F^T / J = U diag(Phat Fhat / J)
 * U^T: its principal values are Phat_i Fhat_i / J, along the columns of U. */
static piola_status apply_criterion(piola_world *w, world_body *b) {
  solid_fracture *f = b->fracture;
  if (f->criterion != PIOLA_FRACTURE_STRESS) return PIOLA_OK;
  const piola_elastic_body *e = b->solid;
  const double *fhat = piola_elastic_body_fhat(e);
  const double scale = piola_track_eval(&b->stiffness_scale, w->time);
  double worst = f->threshold, normal[3] = {0, 0, 0};
  int32_t pick = -1;
  for (int32_t c = 0; c < f->copy_count; ++c) {
    if (f->event[c] >= 0) continue;
    const double *fc = fhat + 3 * c;
    const double j = fc[0] * fc[1] * fc[2];
    if (!(j > 0)) continue; /* inverted or flat: no tension to speak of */
    double phat[3];
    piola_material_stress(&e->materials[e->tet_material[c]], fc, phat);
    for (int i = 0; i < 3; ++i) {
      const double sigma = scale * phat[i] * fc[i] / j;
      if (sigma > worst) {
        worst = sigma, pick = c;
        for (int k = 0; k < 3; ++k) normal[k] = e->u[3 * k + i][c];
      }
    }
  }
  if (pick < 0) return PIOLA_OK;
  const int32_t *corner = piola_elastic_body_tets(e) + 4 * pick;
  double point[3] = {0, 0, 0};
  for (int k = 0; k < 4; ++k)
    for (int a = 0; a < 3; ++a) point[a] += 0.25 * b->x[3 * corner[k] + a];
  int32_t count;
  return cut_event(w, b, point, normal, &count);
}

piola_status piola__world_fracture_step(piola_world *w) {
  for (int32_t i = 0; i < w->body_count; ++i)
    if (w->bodies[i].kind == PIOLA_BODY_SOLID && w->bodies[i].fracture) {
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
  if (def->criterion != PIOLA_FRACTURE_SCRIPTED && def->criterion != PIOLA_FRACTURE_STRESS)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "fracture of '%s': unknown criterion %d", b->name,
                      (int)def->criterion);
  if (def->criterion == PIOLA_FRACTURE_STRESS && !(def->threshold > 0 && isfinite(def->threshold)))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "fracture of '%s': the stress threshold must be > 0 Pa, got %g", b->name, def->threshold);
  for (int32_t i = 0; i < def->cut_count; ++i) {
    const piola_fracture_cut *c = &def->cuts[i];
    const double point[3] = {c->point.x, c->point.y, c->point.z};
    const double normal[3] = {c->normal.x, c->normal.y, c->normal.z};
    PIOLA_TRY(check_plane(point, normal, b->name, i));
    if (!isfinite(c->time))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "fracture of '%s': cut %d time is not finite", b->name, (int)i);
  }
  piola_fracture_cut *cuts = malloc(sizeof *cuts * (size_t)(def->cut_count > 0 ? def->cut_count : 1));
  if (!cuts) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fracture of '%s': out of memory", b->name);
  if (def->cut_count > 0) memcpy(cuts, def->cuts, sizeof *cuts * (size_t)def->cut_count);
  /* insertion sort keeps cuts of equal time in the given order (qsort need not) */
  for (int32_t i = 1; i < def->cut_count; ++i)
    for (int32_t j = i; j > 0 && by_time(&cuts[j - 1], &cuts[j]) > 0; --j) {
      piola_fracture_cut tmp = cuts[j];
      cuts[j] = cuts[j - 1], cuts[j - 1] = tmp;
    }
  piola_status st = ensure_state(b);
  if (st != PIOLA_OK) {
    free(cuts);
    return st;
  }
  free(b->fracture->cuts);
  b->fracture->cuts = cuts;
  b->fracture->cut_count = def->cut_count;
  b->fracture->next_cut = 0;
  b->fracture->max_cuts_per_step = def->max_cuts_per_step;
  b->fracture->criterion = def->criterion;
  b->fracture->threshold = def->threshold;
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
