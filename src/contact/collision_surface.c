/* Collision surfaces: construction, detection passes, repulsion and impact impulses, and the
 * three-stage processing of BFA02 (see piola/collision_surface.h and contact_internal.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_internal.h"
#include "common/threads.h"
#include "contact/ccd.h"
#include "contact/contact_internal.h"
#include "contact/proximity.h"

enum { QUERY_BLOCK = 256, REBUILD_PERIOD = 8 };

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
  if (list->count == list->capacity) {
    int64_t capacity = list->capacity ? 2 * list->capacity : 32;
    piola__contact *items = realloc(list->items, sizeof(*items) * (size_t)capacity);
    if (!items) return -1;
    list->items = items, list->capacity = capacity;
  }
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
  if (!s->triangles || !s->edges || !s->vertex_body || !s->bodies || !s->inverse_mass ||
      !s->vertex_thickness || !s->vertex_boxes || !s->triangle_boxes || !s->edge_boxes ||
      !s->zone_parent || !s->in_zone || !s->zone_order || !s->dirty || !s->on_surface) {
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
  s->block_count = (nv + nt + unique) / QUERY_BLOCK + 3;
  s->queries = malloc(sizeof(int32_t) * ((size_t)nv + (size_t)nt + (size_t)unique + 1));
  s->blocks = calloc((size_t)(s->block_count > 0 ? s->block_count : 1), sizeof(*s->blocks));
  if (!s->blocks || !s->queries) {
    piola_collision_surface_destroy(s);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "collision surface: out of memory");
  }
  *out = s;
  return PIOLA_OK;
}

/* ------------------------------------------------------------------ detection */

typedef enum detect_mode { DETECT_PROXIMITY, DETECT_CCD } detect_mode;

/* What a query primitive is tested against: a vertex against triangles, a triangle against
 * vertices, an edge against edges. */
typedef enum query_kind { QUERY_VERTEX, QUERY_TRIANGLE, QUERY_EDGE } query_kind;

static double max3(double a, double b, double c) { return fmax(a, fmax(b, c)); }

static void box_of_vertex(piola__box *box, const double *x0, const double *v, double dt,
                          double pad) {
  for (int k = 0; k < 3; ++k) {
    double a = x0[k], b = v ? x0[k] + dt * v[k] : a;
    box->lo[k] = fmin(a, b) - pad;
    box->hi[k] = fmax(a, b) + pad;
  }
}

static void box_union_of(piola__box *out, const piola__box *a, const piola__box *b) {
  for (int k = 0; k < 3; ++k) {
    out->lo[k] = fmin(a->lo[k], b->lo[k]);
    out->hi[k] = fmax(a->hi[k], b->hi[k]);
  }
}

/* Vertex, triangle and edge boxes: at x0 padded by half the thickness (proximity), or swept
 * over the step padded by the detection tolerance (continuous detection); two primitives
 * within their pair's thickness (or tolerance) then always have overlapping boxes. */
static void compute_boxes(piola_collision_surface *s, const double *x0, const double *v, double dt,
                          detect_mode mode) {
#pragma omp parallel num_threads(piola__thread_count()) if (s->vertex_count + s->edge_count >= 4096)
  {
#pragma omp for schedule(static)
    for (int32_t i = 0; i < s->vertex_count; ++i) {
      double h = s->vertex_thickness[i];
      box_of_vertex(&s->vertex_boxes[i], x0 + 3 * i, mode == DETECT_CCD ? v + 3 * i : NULL, dt,
                    mode == DETECT_CCD ? PIOLA__CCD_TOLERANCE * h : 0.5 * h);
    }
#pragma omp for schedule(static)
    for (int32_t t = 0; t < s->triangle_count; ++t) {
      const int32_t *tri = s->triangles + 3 * t;
      box_union_of(&s->triangle_boxes[t], &s->vertex_boxes[tri[0]], &s->vertex_boxes[tri[1]]);
      box_union_of(&s->triangle_boxes[t], &s->triangle_boxes[t], &s->vertex_boxes[tri[2]]);
    }
#pragma omp for schedule(static)
    for (int32_t e = 0; e < s->edge_count; ++e)
      box_union_of(&s->edge_boxes[e], &s->vertex_boxes[s->edges[2 * e]],
                   &s->vertex_boxes[s->edges[2 * e + 1]]);
  }
}

/* Each side of a pair keeps half its body's thickness: the pair keeps the sum, which within
 * one body is that body's thickness. */
static double pair_thickness(const piola_collision_surface *s, const int32_t v[4], int edge_edge) {
  const double *h = s->vertex_thickness;
  double side_a = edge_edge ? fmax(h[v[0]], h[v[1]]) : h[v[0]];
  double side_b = edge_edge ? fmax(h[v[2]], h[v[3]]) : max3(h[v[1]], h[v[2]], h[v[3]]);
  return 0.5 * (side_a + side_b);
}

static double pair_friction(const piola_collision_surface *s, const int32_t v[4]) {
  return 0.5 *
         (s->bodies[s->vertex_body[v[0]]].friction + s->bodies[s->vertex_body[v[3]]].friction);
}

static int all_pinned(const piola_collision_surface *s, const int32_t v[4]) {
  return s->inverse_mass[v[0]] == 0.0 && s->inverse_mass[v[1]] == 0.0 &&
         s->inverse_mass[v[2]] == 0.0 && s->inverse_mass[v[3]] == 0.0;
}

/* Pairs none of whose vertices changed velocity since the last pass were tested then. */
static int any_dirty(const uint8_t *dirty, const int32_t v[4]) {
  return !dirty || dirty[v[0]] || dirty[v[1]] || dirty[v[2]] || dirty[v[3]];
}

static vec3 unit(vec3 a) {
  double len = vec3_norm(a);
  return len > 0.0 ? vec3_scale(a, 1.0 / len) : a;
}

/* Narrow phase of one pair. Returns 1 and fills c when the pair is in contact (proximity) or
 * collides during the step (continuous detection). */
static int narrow_phase(const piola_collision_surface *s, const double *x0, const double *v,
                        double dt, detect_mode mode, int edge_edge, piola__contact *c) {
  vec3 x[4];
  for (int k = 0; k < 4; ++k) x[k] = vec3_load(x0 + 3 * c->v[k]);
  c->thickness = pair_thickness(s, c->v, edge_edge);
  c->friction = pair_friction(s, c->v);
  if (mode == DETECT_PROXIMITY) {
    double dist2;
    vec3 fallback;
    if (!edge_edge) {
      double b[3];
      dist2 = piola__point_triangle_closest(x[0], x[1], x[2], x[3], b);
      c->w[0] = 1.0, c->w[1] = -b[0], c->w[2] = -b[1], c->w[3] = -b[2];
      fallback = vec3_cross(vec3_sub(x[2], x[1]), vec3_sub(x[3], x[1]));
    } else {
      double a, b;
      dist2 = piola__segment_segment_closest(x[0], x[1], x[2], x[3], &a, &b);
      c->w[0] = 1.0 - a, c->w[1] = a, c->w[2] = -(1.0 - b), c->w[3] = -b;
      fallback = vec3_cross(vec3_sub(x[1], x[0]), vec3_sub(x[3], x[2]));
    }
    if (!(dist2 < c->thickness * c->thickness)) return 0;
    vec3 r = {0, 0, 0};
    for (int k = 0; k < 4; ++k) r = vec3_add(r, vec3_scale(x[k], c->w[k]));
    vec3 n = unit(r);
    if (vec3_norm2(n) == 0.0) n = unit(fallback);
    if (vec3_norm2(n) == 0.0) return 0;
    c->normal = n;
    c->gap = vec3_dot(r, n);
    return 1;
  }
  vec3 d[4];
  for (int k = 0; k < 4; ++k) d[k] = vec3_scale(vec3_load(v + 3 * c->v[k]), dt);
  piola__ccd_hit hit;
  double eps = PIOLA__CCD_TOLERANCE * c->thickness;
  /* Separation bound: any two points of the pair (fixed barycentric weights) move apart or
   * together by at most the largest relative displacement of a vertex of one side and a
   * vertex of the other, so a pair farther apart than that at the start cannot touch. */
  double start2, move2 = 0.0;
  if (!edge_edge) {
    double b[3];
    start2 = piola__point_triangle_closest(x[0], x[1], x[2], x[3], b);
    for (int k = 1; k < 4; ++k) move2 = fmax(move2, vec3_norm2(vec3_sub(d[0], d[k])));
  } else {
    double a, b;
    start2 = piola__segment_segment_closest(x[0], x[1], x[2], x[3], &a, &b);
    for (int i = 0; i < 2; ++i)
      for (int k = 2; k < 4; ++k) move2 = fmax(move2, vec3_norm2(vec3_sub(d[i], d[k])));
  }
  if (sqrt(start2) > sqrt(move2) + 2.0 * eps) return 0;
  int found = edge_edge ? piola__ccd_edge_edge(x, d, eps, &hit)
                        : piola__ccd_point_triangle(x, d, eps, &hit);
  if (!found) return 0;
  memcpy(c->w, hit.w, sizeof(c->w));
  c->normal = hit.normal;
  vec3 r = {0, 0, 0};
  for (int k = 0; k < 4; ++k) r = vec3_add(r, vec3_scale(x[k], c->w[k]));
  c->gap = vec3_dot(r, hit.normal);
  return 1;
}

/* Narrow phase of vertex p against triangle t, and of edges a and b; push on a hit. Return 0,
 * or -1 out of memory. */
static int emit_vertex_triangle(const piola_collision_surface *s, const double *x0, const double *v,
                                double dt, detect_mode mode, int32_t p, int32_t t,
                                piola__contact_list *list) {
  const int32_t *tri = s->triangles + 3 * t;
  if (!s->on_surface[p] || tri[0] == p || tri[1] == p || tri[2] == p) return 0;
  piola__contact c = {.v = {p, tri[0], tri[1], tri[2]}};
  if (all_pinned(s, c.v)) return 0;
  if (narrow_phase(s, x0, v, dt, mode, 0, &c) && piola__contact_list_push(list, &c)) return -1;
  return 0;
}

static int emit_edge_edge(const piola_collision_surface *s, const double *x0, const double *v,
                          double dt, detect_mode mode, int32_t a, int32_t b,
                          piola__contact_list *list) {
  const int32_t a0 = s->edges[2 * a], a1 = s->edges[2 * a + 1];
  const int32_t b0 = s->edges[2 * b], b1 = s->edges[2 * b + 1];
  if (a0 == b0 || a0 == b1 || a1 == b0 || a1 == b1) return 0;
  piola__contact c = {.v = {a0, a1, b0, b1}};
  if (all_pinned(s, c.v)) return 0;
  if (narrow_phase(s, x0, v, dt, mode, 1, &c) && piola__contact_list_push(list, &c)) return -1;
  return 0;
}

/* ---------------------------------------------------------- tree against tree (full passes)
 * A full pass finds all pairs by descending two trees together (a vertex tree against the
 * triangle tree, the edge tree against itself), which visits each overlapping node pair once
 * instead of descending from the root for every primitive. The top of the descent is done
 * sequentially, into a fixed number of independent tasks (node pairs), which then run in
 * parallel, each into its own list; lists are joined in task order, so the result does not
 * depend on the thread count. */

typedef struct node_pair {
  int32_t a, b; /* node indices; a == b means the pairs within one subtree (same tree) */
} node_pair;

enum { TARGET_TASKS = 512 };

/* Size of a node for deciding which side of a pair to descend: its box's half perimeter. */
static double node_size(const piola__bvh *t, int32_t n) {
  const piola__box *b = &t->nodes[n].box;
  return (b->hi[0] - b->lo[0]) + (b->hi[1] - b->lo[1]) + (b->hi[2] - b->lo[2]);
}

/* Splits one task into its children tasks (appended to out); returns how many, or -1 when
 * the task is a leaf-leaf pair that cannot be split. */
static int split_task(const piola__bvh *ta, const piola__bvh *tb, int same_tree, node_pair task,
                      node_pair out[3]) {
  const piola__bvh_node *na = &ta->nodes[task.a], *nb = &tb->nodes[task.b];
  if (same_tree && task.a == task.b) {
    if (na->count > 0) return -1;
    int32_t l = task.a + 1, r = na->first;
    out[0] = (node_pair){l, l}, out[1] = (node_pair){r, r}, out[2] = (node_pair){l, r};
    return 3;
  }
  if (!piola__boxes_overlap(&na->box, &nb->box)) return 0;
  if (na->count > 0 && nb->count > 0) return -1;
  int split_a = nb->count > 0 || (na->count == 0 && node_size(ta, task.a) >= node_size(tb, task.b));
  if (split_a) {
    out[0] = (node_pair){task.a + 1, task.b}, out[1] = (node_pair){na->first, task.b};
  } else {
    out[0] = (node_pair){task.a, task.b + 1}, out[1] = (node_pair){task.a, nb->first};
  }
  return 2;
}

/* Breadth-first expansion of the root task into about TARGET_TASKS tasks. */
static node_pair *make_tasks(const piola__bvh *ta, const piola__bvh *tb, int same_tree,
                             int32_t *count) {
  *count = 0;
  if (ta->node_count == 0 || tb->node_count == 0) return malloc(sizeof(node_pair));
  int32_t cap = 4 * TARGET_TASKS + 16, n = 1;
  node_pair *tasks = malloc(sizeof(node_pair) * (size_t)cap);
  node_pair *next = malloc(sizeof(node_pair) * (size_t)cap);
  if (!tasks || !next) {
    free(tasks), free(next);
    return NULL;
  }
  tasks[0] = (node_pair){0, 0};
  for (int round = 0; round < 64 && n < TARGET_TASKS; ++round) {
    int32_t m = 0, split_any = 0;
    for (int32_t i = 0; i < n; ++i) {
      node_pair kids[3];
      int k = m + 3 * (n - i) < cap ? split_task(ta, tb, same_tree, tasks[i], kids) : -1;
      if (k < 0) {
        next[m++] = tasks[i];
        continue;
      }
      split_any = 1;
      for (int j = 0; j < k; ++j) next[m++] = kids[j];
    }
    node_pair *t = tasks;
    tasks = next, next = t, n = m;
    if (!split_any) break;
  }
  free(next);
  *count = n;
  return tasks;
}

/* Runs one task to the end with an explicit stack. Returns 0, or -1 out of memory. */
static int run_task(const piola_collision_surface *s, const double *x0, const double *v, double dt,
                    detect_mode mode, const piola__bvh *ta, const piola__bvh *tb, int same_tree,
                    node_pair task, piola__contact_list *list) {
  node_pair stack[256];
  int top = 0;
  stack[top++] = task;
  while (top > 0) {
    node_pair t = stack[--top];
    node_pair kids[3];
    int k = split_task(ta, tb, same_tree, t, kids);
    if (k == 0) continue;
    if (k > 0 && top + k <= 256) {
      /* Pushed in reverse so they are taken in order (the order is part of the result). */
      for (int j = k - 1; j >= 0; --j) stack[top++] = kids[j];
      continue;
    }
    if (k > 0) return -1; /* cannot happen: depth is bounded by the two trees' depths */
    const piola__bvh_node *na = &ta->nodes[t.a], *nb = &tb->nodes[t.b];
    for (int32_t i = 0; i < na->count; ++i) {
      const int32_t pa = ta->order[na->first + i];
      for (int32_t j = (same_tree && t.a == t.b) ? i + 1 : 0; j < nb->count; ++j) {
        const int32_t pb = tb->order[nb->first + j];
        int failed;
        if (same_tree) {
          if (!piola__boxes_overlap(&s->edge_boxes[pa], &s->edge_boxes[pb])) continue;
          failed = emit_edge_edge(s, x0, v, dt, mode, pa < pb ? pa : pb, pa < pb ? pb : pa, list);
        } else {
          if (!piola__boxes_overlap(&s->vertex_boxes[pa], &s->triangle_boxes[pb])) continue;
          failed = emit_vertex_triangle(s, x0, v, dt, mode, pa, pb, list);
        }
        if (failed) return -1;
      }
    }
  }
  return 0;
}

/* Full pass by tree descents into s->found. Returns 0, or -1 out of memory. */
static int detect_all(piola_collision_surface *s, const double *x0, const double *v, double dt,
                      detect_mode mode) {
  int32_t nvt, nee;
  node_pair *vt = make_tasks(&s->vertex_tree, &s->triangle_tree, 0, &nvt);
  node_pair *ee = make_tasks(&s->edge_tree, &s->edge_tree, 1, &nee);
  int failed = !vt || !ee;
  const int32_t total = failed ? 0 : nvt + nee;
  piola__contact_list *lists = failed ? NULL : calloc((size_t)total + 1, sizeof(*lists));
  if (!failed && !lists) failed = 1;
  if (!failed) {
#pragma omp parallel for schedule(dynamic, 1) num_threads(piola__thread_count()) \
    reduction(|                               \
              : failed) if (total >= 64 && s->triangle_count >= 2048)
    for (int32_t i = 0; i < total; ++i) {
      if (failed) continue;
      if (i < nvt)
        failed |= run_task(s, x0, v, dt, mode, &s->vertex_tree, &s->triangle_tree, 0, vt[i],
                           &lists[i]) != 0;
      else
        failed |= run_task(s, x0, v, dt, mode, &s->edge_tree, &s->edge_tree, 1, ee[i - nvt],
                           &lists[i]) != 0;
    }
  }
  s->found.count = 0;
  for (int32_t i = 0; i < total && !failed; ++i)
    for (int64_t j = 0; j < lists[i].count; ++j)
      if (piola__contact_list_push(&s->found, &lists[i].items[j])) failed = 1;
  if (lists)
    for (int32_t i = 0; i < total; ++i) free(lists[i].items);
  free(lists), free(vt), free(ee);
  return failed ? -1 : 0;
}

/* Pairs of one query primitive with the candidates the tree returns for its box; appends
 * the contacts found to list. Returns 0, or -1 out of memory. */
static int query_pairs(piola_collision_surface *s, const double *x0, const double *v, double dt,
                       detect_mode mode, const uint8_t *dirty, query_kind kind, int32_t q,
                       piola__index_list *candidates, piola__contact_list *list) {
  candidates->count = 0;
  if (kind == QUERY_VERTEX) {
    if (piola__bvh_query(&s->triangle_tree, s->triangle_boxes, &s->vertex_boxes[q], candidates))
      return -1;
    for (int64_t j = 0; j < candidates->count; ++j) {
      const int32_t *tri = s->triangles + 3 * candidates->items[j];
      if (tri[0] == q || tri[1] == q || tri[2] == q) continue;
      piola__contact c = {.v = {q, tri[0], tri[1], tri[2]}};
      if (all_pinned(s, c.v) || !any_dirty(dirty, c.v)) continue;
      if (narrow_phase(s, x0, v, dt, mode, 0, &c) && piola__contact_list_push(list, &c)) return -1;
    }
  } else if (kind == QUERY_TRIANGLE) {
    /* Only with a dirty triangle, and only clean vertices: dirty ones query themselves. */
    if (piola__bvh_query(&s->vertex_tree, s->vertex_boxes, &s->triangle_boxes[q], candidates))
      return -1;
    const int32_t *tri = s->triangles + 3 * q;
    for (int64_t j = 0; j < candidates->count; ++j) {
      const int32_t p = candidates->items[j];
      if (dirty[p] || !s->on_surface[p] || tri[0] == p || tri[1] == p || tri[2] == p) continue;
      piola__contact c = {.v = {p, tri[0], tri[1], tri[2]}};
      if (all_pinned(s, c.v)) continue;
      if (narrow_phase(s, x0, v, dt, mode, 0, &c) && piola__contact_list_push(list, &c)) return -1;
    }
  } else {
    if (piola__bvh_query(&s->edge_tree, s->edge_boxes, &s->edge_boxes[q], candidates)) return -1;
    const int32_t a0 = s->edges[2 * q], a1 = s->edges[2 * q + 1];
    for (int64_t j = 0; j < candidates->count; ++j) {
      const int32_t e = candidates->items[j];
      const int32_t b0 = s->edges[2 * e], b1 = s->edges[2 * e + 1];
      /* Each pair once: from the lower index, or from the dirty edge when only one is. */
      if (e == q) continue;
      if (!dirty && e < q) continue;
      if (dirty && e < q && (dirty[b0] || dirty[b1])) continue;
      if (a0 == b0 || a0 == b1 || a1 == b0 || a1 == b1) continue;
      piola__contact c = {.v = {a0, a1, b0, b1}};
      if (all_pinned(s, c.v)) continue;
      if (narrow_phase(s, x0, v, dt, mode, 1, &c) && piola__contact_list_push(list, &c)) return -1;
    }
  }
  return 0;
}

/* All contacts (proximity) or collisions (continuous detection) into s->found, in an order
 * that does not depend on the thread count. With dirty given, only pairs with a vertex whose
 * velocity changed are tested: they are found from the dirty vertices, from the triangles
 * and edges that touch one, against the trees of the other primitives. Returns 0, or -1 out
 * of memory. */
static int detect(piola_collision_surface *s, const double *x0, const double *v, double dt,
                  detect_mode mode, int *tree_built, const uint8_t *dirty) {
  compute_boxes(s, x0, v, dt, mode);
  /* A tree built in an earlier call is refit as long as it is young: its shape came from
   * positions close to these; every REBUILD_PERIOD calls it is rebuilt from scratch. */
  if (!*tree_built && s->tree_age > 0 && s->tree_age < REBUILD_PERIOD) *tree_built = 1;
  if (!*tree_built) {
    s->tree_age = 0;
    if (piola__bvh_build(&s->triangle_tree, s->triangle_boxes, s->triangle_count) ||
        piola__bvh_build(&s->edge_tree, s->edge_boxes, s->edge_count) ||
        piola__bvh_build(&s->vertex_tree, s->vertex_boxes, s->vertex_count))
      return -1;
    *tree_built = 1;
  } else {
    piola__bvh_refit(&s->triangle_tree, s->triangle_boxes);
    piola__bvh_refit(&s->edge_tree, s->edge_boxes);
    piola__bvh_refit(&s->vertex_tree, s->vertex_boxes);
  }
  if (!dirty) return detect_all(s, x0, v, dt, mode);
  /* The queries: (kind, primitive) in three runs. */
  int32_t runs[3] = {0, 0, 0}, n = 0;
  if (!dirty) {
    for (int32_t i = 0; i < s->vertex_count; ++i)
      if (s->on_surface[i]) s->queries[n++] = i;
    runs[0] = n;
    runs[1] = n;
    for (int32_t e = 0; e < s->edge_count; ++e) s->queries[n++] = e;
    runs[2] = n;
  } else {
    for (int32_t i = 0; i < s->vertex_count; ++i)
      if (dirty[i] && s->on_surface[i]) s->queries[n++] = i;
    runs[0] = n;
    for (int32_t t = 0; t < s->triangle_count; ++t) {
      const int32_t *tri = s->triangles + 3 * t;
      if (dirty[tri[0]] || dirty[tri[1]] || dirty[tri[2]]) s->queries[n++] = t;
    }
    runs[1] = n;
    for (int32_t e = 0; e < s->edge_count; ++e)
      if (dirty[s->edges[2 * e]] || dirty[s->edges[2 * e + 1]]) s->queries[n++] = e;
    runs[2] = n;
  }
  /* Blocks never straddle two runs, so each block has one kind. */
  int32_t block_start[3], blocks = 0;
  for (int r = 0; r < 3; ++r) {
    block_start[r] = blocks;
    int32_t len = runs[r] - (r ? runs[r - 1] : 0);
    blocks += (len + QUERY_BLOCK - 1) / QUERY_BLOCK;
  }
  int failed = 0;
#pragma omp parallel num_threads(piola__thread_count()) reduction(| : failed) if (blocks >= 16)
  {
    piola__index_list candidates = {0};
#pragma omp for schedule(dynamic, 1)
    for (int32_t b = 0; b < blocks; ++b) {
      piola__contact_list *list = &s->blocks[b];
      list->count = 0;
      if (failed) continue;
      int r = b >= block_start[2] ? 2 : (b >= block_start[1] ? 1 : 0);
      const query_kind kind = r == 0 ? QUERY_VERTEX : (r == 1 ? QUERY_TRIANGLE : QUERY_EDGE);
      const int32_t run_begin = r ? runs[r - 1] : 0;
      const int32_t first = run_begin + (b - block_start[r]) * QUERY_BLOCK;
      const int32_t end = first + QUERY_BLOCK < runs[r] ? first + QUERY_BLOCK : runs[r];
      for (int32_t i = first; i < end; ++i)
        if (query_pairs(s, x0, v, dt, mode, dirty, kind, s->queries[i], &candidates, list)) {
          failed = 1;
          break;
        }
    }
    free(candidates.items);
  }
  if (failed) return -1;
  s->found.count = 0;
  for (int32_t b = 0; b < blocks; ++b) {
    /* Candidates of a query come out in tree order; that order is fixed by the build, which
     * is itself deterministic, so no sort is needed. */
    for (int64_t i = 0; i < s->blocks[b].count; ++i)
      if (piola__contact_list_push(&s->found, &s->blocks[b].items[i])) return -1;
  }
  return 0;
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

static int same_zone(piola_collision_surface *s, const piola__contact *c) {
  if (!s->in_zone[c->v[0]]) return 0;
  int32_t root = piola__zone_root(s->zone_parent, c->v[0]);
  for (int k = 1; k < 4; ++k)
    if (!s->in_zone[c->v[k]] || piola__zone_root(s->zone_parent, c->v[k]) != root) return 0;
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
  for (int32_t i = 0; i < s->vertex_count; ++i) {
    for (int k = 0; k < 3; ++k)
      if (!isfinite(x0[3 * i + k]) || !isfinite(v[3 * i + k]))
        return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE,
                          "collision processing: vertex %d has a non-finite position or velocity",
                          i);
    if (!(mass[i] > 0.0))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "collision processing: vertex %d mass must be > 0 kg or INFINITY, got %g",
                        i, mass[i]);
    s->inverse_mass[i] = isinf(mass[i]) ? 0.0 : 1.0 / mass[i];
  }
  piola_collision_stats st = {0};
  int tree_built = 0;

  /* Stage 1: repulsion of pairs closer than their thickness at x0. */
  if (set.repulsion) {
    if (detect(s, x0, v, dt, DETECT_PROXIMITY, &tree_built, NULL)) goto out_of_memory;
    for (int64_t i = 0; i < s->found.count; ++i)
      st.contacts += apply_repulsion(s, &s->found.items[i], v, dt, set.repulsion_stiffness);
  }

  /* Stage 2: continuous detection and impacts, a few passes. After the first pass only pairs
   * with a vertex whose velocity changed (or that collided without being fixed) can have
   * changed their answer, so only those are tested again. */
  int clean = 0, first_pass = 1;
  for (int pass = 0; pass < set.collision_iterations; ++pass) {
    if (detect(s, x0, v, dt, DETECT_CCD, &tree_built, first_pass ? NULL : s->dirty))
      goto out_of_memory;
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
  }

  /* Stage 3: rigid impact zones until no collision is left. */
  s->zone_misfit = 0;
  if (!clean) {
    for (int32_t i = 0; i < s->vertex_count; ++i) s->zone_parent[i] = i, s->in_zone[i] = 0;
    for (int pass = 0; pass < set.max_zone_iterations; ++pass) {
      if (detect(s, x0, v, dt, DETECT_CCD, &tree_built, first_pass ? NULL : s->dirty))
        goto out_of_memory;
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
      int32_t zones = piola__impact_zones_apply(s, &s->found, x0, v, &st.zone_vertices);
      if (zones < 0) goto out_of_memory;
      st.impact_zones = zones;
    }
  }
  st.resolved = clean && !s->zone_misfit;
  ++s->tree_age;
  if (stats) *stats = st;
  return PIOLA_OK;

out_of_memory:
  return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "collision processing: out of memory");
}
