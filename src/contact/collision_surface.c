/* Collision surfaces: construction, repulsion and impact impulses, and the
 * three-stage processing of BFA02 (see piola/collision_surface.h and contact_internal.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "common/grow.h"
#include "common/status_report.h"
#include "common/union_find.h"
#include "contact/contact_internal.h"

piola_collision_body_def piola_default_collision_body_def(void) {
  return (piola_collision_body_def){.thickness = 1e-3, .friction = 0.3};
}

piola_collision_surface_def piola_default_collision_surface_def(void) {
  return (piola_collision_surface_def){0};
}

piola_collision_settings piola_default_collision_settings(void) {
  return (piola_collision_settings){.repulsion = 1,
                                    .repulsion_stiffness = INFINITY,
                                    .collision_iterations = 5,
                                    .max_zone_iterations = 200};
}

int piola__contact_list_push(piola__contact_list *list, const piola__contact *c) {
  if ((size_t)list->count == list->capacity &&
      piola__grow((void **)&list->items, &list->capacity, (size_t)list->count + 1,
                  sizeof *list->items))
    return -1;
  list->items[list->count++] = *c;
  return 0;
}

static int compare_edges(const void *a, const void *b) {
  const int32_t *x = a, *y = b;
  if (x[0] != y[0]) return (x[0] > y[0]) - (x[0] < y[0]);
  return (x[1] > y[1]) - (x[1] < y[1]);
}

void piola_collision_surface_destroy(piola_collision_surface *s) {
  if (!s) return;
  free(s->triangles);
  free(s->edges);
  free(s->vertex_body);
  free(s->bodies);
  free(s->inverse_mass);
  free(s->vertex_thickness);
  free(s->vertex_boxes);
  free(s->triangle_boxes);
  free(s->edge_boxes);
  piola__bvh_free(&s->triangle_tree);
  piola__bvh_free(&s->edge_tree);
  piola__bvh_free(&s->vertex_tree);
  free(s->queries);
  if (s->blocks)
    for (int32_t b = 0; b < s->block_count; ++b) free(s->blocks[b].items);
  free(s->blocks);
  free(s->found.items);
  free(s->zone_parent);
  free(s->in_zone);
  free(s->dirty);
  free(s->on_surface);
  free(s->zone_order);
  free(s->reach_boxes);
  free(s->escaped);
  for (int32_t t = 0; t < s->task_capacity; ++t)
    free(s->candidates[t].items), free(s->near[t].items), free(s->task_found[t].items);
  free(s->candidates), free(s->near), free(s->task_found);
  free(s->reach_radius);
  free(s->vertex_slabs);
  free(s->triangle_slabs);
  free(s->edge_slabs);
  piola__embedding_free(s);
  free(s);
}

int32_t piola_collision_surface_vertex_count(const piola_collision_surface *s) {
  return s ? s->vertex_count : 0;
}

int32_t piola_collision_surface_edge_count(const piola_collision_surface *s) {
  return s ? s->edge_count : 0;
}

piola_status piola_collision_surface_create(const piola_collision_surface_def *def,
                                            piola_collision_surface **out) {
  if (!out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "collision surface: out is NULL");
  *out = NULL;
  if (!def) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "collision surface: def is NULL");
  const int32_t nv = def->vertex_count, nt = def->triangle_count;
  if (nv < 0 || nt < 0 || (nt > 0 && !def->triangles))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "collision surface: vertex_count %d, triangle_count %d (triangles %s)", nv,
                      nt, def->triangles ? "given" : "NULL");
  if (nt > INT32_MAX / 3)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "collision surface: too many triangles (%d)",
                      nt);
  if (def->body_count < 1 || !def->bodies)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "collision surface: body_count must be >= 1 with bodies given, got %d",
                      def->body_count);
  for (int32_t b = 0; b < def->body_count; ++b) {
    const piola_collision_body_def *body = &def->bodies[b];
    if (!(body->thickness > 0.0) || !isfinite(body->thickness))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "collision surface: body %d thickness must be > 0 m and finite, got %g", b,
                        body->thickness);
    if (!(body->friction >= 0.0) || !isfinite(body->friction))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "collision surface: body %d friction must be >= 0 and finite, got %g", b,
                        body->friction);
  }
  for (int32_t t = 0; t < nt; ++t) {
    const int32_t *tri = def->triangles + 3 * t;
    for (int k = 0; k < 3; ++k)
      if (tri[k] < 0 || tri[k] >= nv)
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                          "collision surface: triangle %d vertex %d is %d, outside [0, %d)", t, k,
                          tri[k], nv);
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "collision surface: triangle %d repeats a vertex (%d %d %d)", t, tri[0],
                        tri[1], tri[2]);
  }
  if (def->vertex_body)
    for (int32_t i = 0; i < nv; ++i)
      if (def->vertex_body[i] < 0 || def->vertex_body[i] >= def->body_count)
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                          "collision surface: vertex %d body %d, outside [0, %d)", i,
                          def->vertex_body[i], def->body_count);

  piola_collision_surface *s = calloc(1, sizeof(*s));
  if (!s) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "collision surface: out of memory");
  s->vertex_count = nv, s->triangle_count = nt, s->body_count = def->body_count;
  const size_t nv1 = (size_t)(nv > 0 ? nv : 1), nt1 = (size_t)(nt > 0 ? nt : 1);
  s->triangles = malloc(sizeof(int32_t) * 3 * nt1);
  s->edges = malloc(sizeof(int32_t) * 6 * nt1);
  s->vertex_body = calloc(nv1, sizeof(int32_t));
  s->bodies = malloc(sizeof(*s->bodies) * (size_t)def->body_count);
  s->inverse_mass = malloc(sizeof(double) * nv1);
  s->vertex_thickness = malloc(sizeof(double) * nv1);
  s->vertex_boxes = malloc(sizeof(piola__box) * nv1);
  s->triangle_boxes = malloc(sizeof(piola__box) * nt1);
  s->edge_boxes = malloc(sizeof(piola__box) * 3 * nt1);
  s->zone_parent = malloc(sizeof(int32_t) * nv1);
  s->in_zone = malloc(nv1);
  s->dirty = calloc(nv1, 1);
  s->on_surface = calloc(nv1, 1);
  s->zone_order = malloc(sizeof(int32_t) * nv1);
  s->reach_boxes = malloc(sizeof(piola__box) * nv1);
  s->escaped = calloc(nv1, 1);
  s->reach_radius = malloc(sizeof(double) * nv1);
  s->vertex_slabs = malloc(sizeof(double) * 12 * nv1);
  s->triangle_slabs = malloc(sizeof(double) * 12 * nt1);
  s->edge_slabs = malloc(sizeof(double) * 36 * nt1);
  if (!s->reach_boxes || !s->escaped || !s->reach_radius || !s->vertex_slabs ||
      !s->triangle_slabs || !s->edge_slabs || !s->triangles || !s->edges || !s->vertex_body ||
      !s->bodies || !s->inverse_mass || !s->vertex_thickness || !s->vertex_boxes ||
      !s->triangle_boxes || !s->edge_boxes || !s->zone_parent || !s->in_zone || !s->zone_order ||
      !s->dirty || !s->on_surface) {
    piola_collision_surface_destroy(s);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "collision surface: out of memory");
  }
  if (nt > 0) memcpy(s->triangles, def->triangles, sizeof(int32_t) * 3 * (size_t)nt);
  /* Vertices in no triangle (e.g. interior nodes of a solid) take no part. */
  for (int32_t i = 0; i < 3 * nt; ++i) s->on_surface[s->triangles[i]] = 1;
  if (def->vertex_body && nv > 0)
    memcpy(s->vertex_body, def->vertex_body, sizeof(int32_t) * (size_t)nv);
  memcpy(s->bodies, def->bodies, sizeof(*s->bodies) * (size_t)def->body_count);
  for (int32_t i = 0; i < nv; ++i) s->vertex_thickness[i] = s->bodies[s->vertex_body[i]].thickness;

  /* Unique edges: every triangle side with the lower index first, sorted, duplicates dropped. */
  int32_t ne = 0;
  for (int32_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      int32_t a = s->triangles[3 * t + k], b = s->triangles[3 * t + (k + 1) % 3];
      s->edges[2 * ne] = a < b ? a : b;
      s->edges[2 * ne + 1] = a < b ? b : a;
      ++ne;
    }
  qsort(s->edges, (size_t)ne, 2 * sizeof(int32_t), compare_edges);
  int32_t unique = 0;
  for (int32_t e = 0; e < ne; ++e) {
    if (unique > 0 && s->edges[2 * e] == s->edges[2 * unique - 2] &&
        s->edges[2 * e + 1] == s->edges[2 * unique - 1])
      continue;
    s->edges[2 * unique] = s->edges[2 * e], s->edges[2 * unique + 1] = s->edges[2 * e + 1];
    ++unique;
  }
  s->edge_count = unique;
  s->block_count = (nv + nt + unique) / PIOLA__QUERY_BLOCK + 3;
  s->queries = malloc(sizeof(int32_t) * ((size_t)nv + (size_t)nt + (size_t)unique + 1));
  s->blocks = calloc((size_t)(s->block_count > 0 ? s->block_count : 1), sizeof(*s->blocks));
  if (!s->blocks || !s->queries) {
    piola_collision_surface_destroy(s);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "collision surface: out of memory");
  }
  if (def->node_count != 0 || def->embed_nodes || def->embed_weights) {
    const char *message = NULL;
    int made = piola__embedding_create(s, def, &message);
    if (made != 0) {
      piola_collision_surface_destroy(s);
      if (made == -1) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "collision surface: out of memory");
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "collision surface: %s", message);
    }
  }
  *out = s;
  return PIOLA_OK;
}

/* ------------------------------------------------------------------ impulses */

/* Changes the pair's relative velocity by dn along the normal plus Coulomb friction, which
 * takes mu dn off the tangential relative velocity but never reverses it. */
static void apply_relative_change(piola_collision_surface *s, const piola__contact *c, double *v,
                                  double dn, double denom) {
  vec3 rel = {0, 0, 0};
  for (int k = 0; k < 4; ++k) rel = vec3_add(rel, vec3_scale(vec3_load(v + 3 * c->v[k]), c->w[k]));
  vec3 tangential = vec3_sub(rel, vec3_scale(c->normal, vec3_dot(rel, c->normal)));
  double vt = vec3_norm(tangential);
  vec3 change = vec3_scale(c->normal, dn);
  if (vt > 0.0 && c->friction > 0.0) {
    double fraction = fmin(1.0, c->friction * dn / vt);
    change = vec3_sub(change, vec3_scale(tangential, fraction));
  }
  vec3 impulse = vec3_scale(change, 1.0 / denom); /* kg m/s per unit weight */
  if (s->node_count > 0) {
    int32_t node[16];
    double weight[16], inverse_mass[16];
    const int n = piola__pair_nodes(s, c->v, c->w, node, weight, inverse_mass);
    piola__embedding_apply(s, n, node, weight, inverse_mass, impulse);
    return;
  }
  for (int k = 0; k < 4; ++k) {
    double f = c->w[k] * s->inverse_mass[c->v[k]];
    if (f == 0.0) continue;
    double *vk = v + 3 * c->v[k];
    vk[0] += f * impulse.x, vk[1] += f * impulse.y, vk[2] += f * impulse.z;
    s->dirty[c->v[k]] = 1;
  }
}

static double weight_denominator(const piola_collision_surface *s, const piola__contact *c) {
  double denom = 0.0;
  if (s->node_count > 0) {
    int32_t node[16];
    double weight[16], inverse_mass[16];
    const int n = piola__pair_nodes(s, c->v, c->w, node, weight, inverse_mass);
    for (int j = 0; j < n; ++j) denom += weight[j] * weight[j] * inverse_mass[j];
    return denom;
  }
  for (int k = 0; k < 4; ++k) denom += c->w[k] * c->w[k] * s->inverse_mass[c->v[k]];
  return denom;
}

static double normal_velocity(const piola__contact *c, const double *v) {
  vec3 rel = {0, 0, 0};
  for (int k = 0; k < 4; ++k) rel = vec3_add(rel, vec3_scale(vec3_load(v + 3 * c->v[k]), c->w[k]));
  return vec3_dot(rel, c->normal);
}

/* BFA02 repulsion of a pair closer than its thickness: an inelastic impulse that stops the
 * approach, then a repulsion that brings the separating speed up to 0.1 d / dt (d the overlap
 * with the thickness), limited to the spring impulse dt k d. Returns 1 when it acted. */
static int apply_repulsion(piola_collision_surface *s, const piola__contact *c, double *v,
                           double dt, double stiffness) {
  double denom = weight_denominator(s, c);
  if (!(denom > 0.0)) return 0;
  double vn = normal_velocity(c, v);
  double overlap = c->thickness - c->gap;
  double dn = vn < 0.0 ? -vn : 0.0;
  double target = 0.1 * overlap / dt, after = vn + dn;
  if (after < target) {
    double push = target - after;
    if (isfinite(stiffness)) push = fmin(push, dt * stiffness * overlap * denom);
    dn += push;
  }
  if (!(dn > 0.0)) return 0;
  apply_relative_change(s, c, v, dn, denom);
  return 1;
}

/* Impact of a pair found by continuous detection: the smallest change of normal velocity
 * that ends the step with the pair's contact points a small gap apart along the normal
 * (no bounce), with friction. Returns 1 when it acted. */
static int apply_impact(piola_collision_surface *s, const piola__contact *c, double *v, double dt) {
  double denom = weight_denominator(s, c);
  if (!(denom > 0.0)) return 0;
  double vn = normal_velocity(c, v);
  double target = (PIOLA__CCD_TARGET_GAP * c->thickness - c->gap) / dt;
  if (!(vn < target)) return 0;
  apply_relative_change(s, c, v, target - vn, denom);
  return 1;
}

/* ------------------------------------------------------------------ processing */

static double thread_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Seconds since *clock, which moves on to now. */
static double lap(double *clock) {
  double now = thread_seconds(), elapsed = now - *clock;
  *clock = now;
  return elapsed;
}

static int same_zone(piola_collision_surface *s, const piola__contact *c) {
  if (s->node_count > 0) return piola__embedded_same_zone(s, c);
  if (!s->in_zone[c->v[0]]) return 0;
  int32_t root = piola__union_find_root(s->zone_parent, c->v[0]);
  for (int k = 1; k < 4; ++k)
    if (!s->in_zone[c->v[k]] || piola__union_find_root(s->zone_parent, c->v[k]) != root) return 0;
  return 1;
}

piola_status piola_collision_surface_process(piola_collision_surface *s, const double *x0,
                                             double *v, const double *mass, double dt,
                                             const piola_collision_settings *settings,
                                             piola_collision_stats *stats) {
  if (!s || !x0 || !v || !mass)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "collision processing: surface, x0, v and mass must not be NULL");
  piola_collision_settings set = settings ? *settings : piola_default_collision_settings();
  if (!(dt > 0.0) || !isfinite(dt))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "collision processing: dt must be > 0 s, got %g", dt);
  if (set.collision_iterations < 0 || set.max_zone_iterations < 1 ||
      !(set.repulsion_stiffness > 0.0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "collision processing: settings need collision_iterations >= 0 (got %d), "
                      "max_zone_iterations >= 1 (got %d), repulsion_stiffness > 0 N/m (got %g)",
                      set.collision_iterations, set.max_zone_iterations, set.repulsion_stiffness);
  /* the moving points: the vertices, or an embedded surface's nodes */
  const int embedded = s->node_count > 0;
  const int32_t points = embedded ? s->node_count : s->vertex_count;
  double *inverse_mass = embedded ? s->node_inverse_mass : s->inverse_mass;
  for (int32_t i = 0; i < points; ++i) {
    for (int k = 0; k < 3; ++k)
      if (!isfinite(x0[3 * i + k]) || !isfinite(v[3 * i + k]))
        return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE,
                          "collision processing: %s %d has a non-finite position or velocity",
                          embedded ? "node" : "vertex", i);
    if (!(mass[i] > 0.0))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "collision processing: %s %d mass must be > 0 kg or INFINITY, got %g",
                        embedded ? "node" : "vertex", i, mass[i]);
    inverse_mass[i] = isinf(mass[i]) ? 0.0 : 1.0 / mass[i];
  }
  if (embedded) {
    /* the stages below work on the vertices; impulses reach the nodes (embedding.c) */
    piola__embedding_gather(s, x0, v, mass);
    x0 = s->vertex_x0, v = s->vertex_v;
  }
  piola_collision_stats st = {0};
  int tree_built = 0;
  s->profile = (piola__contact_profile){0};
  double clock = thread_seconds();
  if (piola__collect_candidates(s, x0, v, dt, &tree_built)) goto out_of_memory;
  s->profile.candidates = s->candidate_count;
  s->profile.collect = lap(&clock);

  /* Stage 1: repulsion of pairs closer than their thickness at x0. */
  if (set.repulsion) {
    if (piola__detect(s, x0, v, dt, PIOLA__DETECT_PROXIMITY, NULL, &tree_built)) goto out_of_memory;
    for (int64_t i = 0; i < s->found.count; ++i)
      st.contacts += apply_repulsion(s, &s->found.items[i], v, dt, set.repulsion_stiffness);
    s->profile.repulsion = lap(&clock);
  }

  /* Stage 2: continuous detection and impacts, a few passes. After the first pass only pairs
   * with a vertex whose velocity changed (or that collided without being fixed) can have
   * changed their answer, so only those are tested again. */
  int clean = 0, first_pass = 1;
  for (int pass = 0; pass < set.collision_iterations; ++pass) {
    if (piola__detect(s, x0, v, dt, PIOLA__DETECT_CCD, first_pass ? NULL : s->dirty, &tree_built))
      goto out_of_memory;
    s->profile.detection += lap(&clock);
    first_pass = 0;
    ++st.collision_passes;
    if (s->found.count == 0) {
      clean = 1;
      break;
    }
    memset(s->dirty, 0, (size_t)s->vertex_count);
    for (int64_t i = 0; i < s->found.count; ++i) {
      const piola__contact *c = &s->found.items[i];
      if (apply_impact(s, c, v, dt))
        ++st.impacts;
      else
        for (int k = 0; k < 4; ++k) s->dirty[c->v[k]] = 1;
    }
    s->profile.impulses += lap(&clock);
  }

  /* Stage 3: rigid impact zones until no collision is left. */
  s->zone_misfit = 0;
  if (!clean) {
    for (int32_t i = 0; i < s->vertex_count; ++i) s->zone_parent[i] = i, s->in_zone[i] = 0;
    for (int32_t i = 0; i < s->node_count; ++i) s->node_zone_parent[i] = i, s->node_in_zone[i] = 0;
    for (int pass = 0; pass < set.max_zone_iterations; ++pass) {
      if (piola__detect(s, x0, v, dt, PIOLA__DETECT_CCD, first_pass ? NULL : s->dirty, &tree_built))
        goto out_of_memory;
      s->profile.detection += lap(&clock);
      first_pass = 0;
      ++st.zone_passes;
      /* Collisions inside one zone cannot be fixed by making it rigid again (and the rigid
         motion cannot bring its own pairs closer), so only the rest count. */
      int64_t kept = 0;
      for (int64_t i = 0; i < s->found.count; ++i)
        if (!same_zone(s, &s->found.items[i])) s->found.items[kept++] = s->found.items[i];
      s->found.count = kept;
      if (kept == 0) {
        clean = 1;
        break;
      }
      memset(s->dirty, 0, (size_t)s->vertex_count);
      int32_t zones = embedded ? piola__embedded_zones_apply(s, &s->found, &st.zone_vertices)
                               : piola__impact_zones_apply(s, &s->found, x0, v, &st.zone_vertices);
      if (zones < 0) goto out_of_memory;
      st.impact_zones = zones;
      s->profile.zones += lap(&clock);
    }
  }
  st.resolved = clean && !s->zone_misfit;
  ++s->tree_age;
  if (stats) *stats = st;
  return PIOLA_OK;

out_of_memory:
  return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "collision processing: out of memory");
}
