/* Detection of contacts and collisions for collision processing: candidate pairs from one
 * tree descent per call, the narrow phase, and the passes over the candidates (see
 * contact_internal.h for why it is organised this way). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/grow.h"
#include "contact/ccd.h"
#include "contact/contact_internal.h"
#include "contact/proximity.h"
#include "piola/threads.h"

enum {
  SCAN_CHUNK = 4096,   /* scans of fewer than 4 of these candidates run on one thread */
  REBUILD_PERIOD = 8,  /* calls between full tree builds (refits in between) */
  ESCAPE_FRACTION = 4, /* re-collect candidates when more than 1/4 of the vertices escaped */
  TARGET_TASKS = 512   /* independent node-pair tasks of a tree descent */
};

typedef piola__detect_mode detect_mode;
#define DETECT_PROXIMITY PIOLA__DETECT_PROXIMITY
#define DETECT_CCD PIOLA__DETECT_CCD

/* What a query primitive is tested against: a vertex against triangles, a triangle against
 * vertices, an edge against edges. */
typedef enum query_kind { QUERY_VERTEX, QUERY_TRIANGLE, QUERY_EDGE } query_kind;

/* The three kinds of vertex box. */
typedef enum box_kind {
  BOX_PROXIMITY, /* at x0, padded by half the vertex's thickness */
  BOX_SWEPT,     /* from x0 to x0 + dt v, padded by the detection tolerance */
  BOX_REACH      /* from x0 to x0 + dt v, padded by half the thickness: holds both others, with
                    room for the velocity to change by repulsion and impacts */
} box_kind;

/* Inputs are finite (checked on entry), so plain comparisons do (fmin and fmax are calls). */
static inline double dmin(double a, double b) { return a < b ? a : b; }
static inline double dmax(double a, double b) { return a > b ? a : b; }
static double max3(double a, double b, double c) { return dmax(a, dmax(b, c)); }

static void box_union_of(piola__box *out, const piola__box *a, const piola__box *b) {
  for (int k = 0; k < 3; ++k) {
    out->lo[k] = dmin(a->lo[k], b->lo[k]);
    out->hi[k] = dmax(a->hi[k], b->hi[k]);
  }
}

static int box_contains(const piola__box *outer, const piola__box *inner) {
  return outer->lo[0] <= inner->lo[0] && outer->lo[1] <= inner->lo[1] &&
         outer->lo[2] <= inner->lo[2] && inner->hi[0] <= outer->hi[0] &&
         inner->hi[1] <= outer->hi[1] && inner->hi[2] <= outer->hi[2];
}

/* How far a vertex at x0 can move over the step while its swept box stays in its reach box. */
static double reach_radius(const piola__box *reach, const double *x0) {
  double r2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    double far = dmax(x0[k] - reach->lo[k], reach->hi[k] - x0[k]);
    r2 += far * far;
  }
  return sqrt(r2);
}

/* Vertex boxes of one kind into s->vertex_boxes. For swept boxes, also marks in s->escaped
 * the vertices (of the surface) whose box left the reach box the candidates were collected
 * with, and returns how many; otherwise returns 0. Two primitives within their pair's
 * thickness (proximity) or tolerance (swept) always have overlapping boxes. */
static int32_t compute_vertex_boxes(piola_collision_surface *s, const double *x0, const double *v,
                                    double dt, box_kind kind) {
  int32_t escaped = 0;
  const int32_t n = s->vertex_count;
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) \
    reduction(+ : escaped) if (n >= 8192)
  for (int32_t i = 0; i < n; ++i) {
    const double h = s->vertex_thickness[i];
    const double pad = kind == BOX_SWEPT ? PIOLA__CCD_TOLERANCE * h : 0.5 * h;
    piola__box *box = &s->vertex_boxes[i];
    for (int k = 0; k < 3; ++k) {
      double a = x0[3 * i + k], b = kind == BOX_PROXIMITY ? a : a + dt * v[3 * i + k];
      box->lo[k] = dmin(a, b) - pad;
      box->hi[k] = dmax(a, b) + pad;
    }
    if (kind == BOX_SWEPT) {
      s->escaped[i] = s->on_surface[i] && !box_contains(&s->reach_boxes[i], box);
      escaped += s->escaped[i];
    } else if (kind == BOX_REACH) {
      s->reach_radius[i] = reach_radius(box, x0 + 3 * i);
    }
  }
  return escaped;
}

/* Triangle and edge boxes: unions of their vertices' boxes. */
static void compute_primitive_boxes(piola_collision_surface *s) {
#pragma omp parallel num_threads(piola_thread_count()) if (s->edge_count >= 8192)
  {
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

/* Diagonal slabs: the extents of a primitive along the six directions x +- y, x +- z and
 * y +- z, taken from the corners of its vertices' boxes (so they hold everything the boxes
 * hold, padding included, and a pair within its thickness overlaps in them too). With the
 * box they make an 18-sided bounding volume (a k-DOP), which separates what boxes of
 * diagonal primitives cannot: in a triangulated sheet, the box of a diagonal edge holds the
 * corners of its quad, so without them every edge and vertex around those corners would be
 * a candidate. Six intervals, lo then hi, per primitive. */
enum { SLABS = 12 };

static void vertex_slabs(const piola__box *b, double *out) {
  static const int axes[3][2] = {{0, 1}, {0, 2}, {1, 2}};
  for (int k = 0; k < 3; ++k) {
    const int i = axes[k][0], j = axes[k][1];
    out[4 * k + 0] = b->lo[i] + b->lo[j], out[4 * k + 1] = b->hi[i] + b->hi[j]; /* i + j */
    out[4 * k + 2] = b->lo[i] - b->hi[j], out[4 * k + 3] = b->hi[i] - b->lo[j]; /* i - j */
  }
}

static void slabs_union(double *out, const double *a) {
  for (int k = 0; k < SLABS; k += 2) {
    out[k] = dmin(out[k], a[k]);
    out[k + 1] = dmax(out[k + 1], a[k + 1]);
  }
}

static int slabs_overlap(const double *a, const double *b) {
  for (int k = 0; k < SLABS; k += 2)
    if (a[k + 1] < b[k] || b[k + 1] < a[k]) return 0;
  return 1;
}

/* Slabs of every vertex, triangle and edge from the current vertex boxes. */
static void compute_slabs(piola_collision_surface *s) {
#pragma omp parallel num_threads(piola_thread_count()) if (s->edge_count >= 8192)
  {
#pragma omp for schedule(static)
    for (int32_t i = 0; i < s->vertex_count; ++i)
      vertex_slabs(&s->vertex_boxes[i], s->vertex_slabs + SLABS * (size_t)i);
#pragma omp for schedule(static)
    for (int32_t t = 0; t < s->triangle_count; ++t) {
      const int32_t *tri = s->triangles + 3 * t;
      double *out = s->triangle_slabs + SLABS * (size_t)t;
      memcpy(out, s->vertex_slabs + SLABS * (size_t)tri[0], sizeof(double) * SLABS);
      slabs_union(out, s->vertex_slabs + SLABS * (size_t)tri[1]);
      slabs_union(out, s->vertex_slabs + SLABS * (size_t)tri[2]);
    }
#pragma omp for schedule(static)
    for (int32_t e = 0; e < s->edge_count; ++e) {
      double *out = s->edge_slabs + SLABS * (size_t)e;
      memcpy(out, s->vertex_slabs + SLABS * (size_t)s->edges[2 * e], sizeof(double) * SLABS);
      slabs_union(out, s->vertex_slabs + SLABS * (size_t)s->edges[2 * e + 1]);
    }
  }
}

/* Fits the three trees to the current primitive boxes: a tree built in an earlier call is
 * refit as long as it is young (its shape came from positions close to these); every
 * REBUILD_PERIOD calls, and on the first use, it is built from scratch. Returns 0, or -1 out
 * of memory. */
static int fit_trees(piola_collision_surface *s, int *tree_built) {
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
  return 0;
}

/* Each side of a pair keeps half its body's thickness: the pair keeps the sum, which within
 * one body is that body's thickness. */
static double pair_thickness(const piola_collision_surface *s, const int32_t v[4], int edge_edge) {
  const double *h = s->vertex_thickness;
  double side_a = edge_edge ? dmax(h[v[0]], h[v[1]]) : h[v[0]];
  double side_b = edge_edge ? dmax(h[v[2]], h[v[3]]) : max3(h[v[1]], h[v[2]], h[v[3]]);
  return 0.5 * (side_a + side_b);
}

static double pair_friction(const piola_collision_surface *s, const int32_t v[4]) {
  return 0.5 *
         (s->bodies[s->vertex_body[v[0]]].friction + s->bodies[s->vertex_body[v[3]]].friction);
}

/* Pairs that take no part: all four vertices pinned, or (embedded surfaces) two vertices
 * sharing a node, the embedded form of a vertex in the triangle or edge it is tested with. */
static int left_out(const piola_collision_surface *s, const int32_t v[4], int edge_edge) {
  if (s->node_count > 0 && piola__pair_shares_node(s, v, edge_edge)) return 1;
  return s->inverse_mass[v[0]] == 0.0 && s->inverse_mass[v[1]] == 0.0 &&
         s->inverse_mass[v[2]] == 0.0 && s->inverse_mass[v[3]] == 0.0;
}

static vec3 unit(vec3 a) {
  double len = vec3_norm(a);
  return len > 0.0 ? vec3_scale(a, 1.0 / len) : a;
}

static void load_pair(const double *x0, const int32_t v[4], vec3 x[4]) {
  for (int k = 0; k < 4; ++k) x[k] = vec3_load(x0 + 3 * v[k]);
}

/* Squared distance of the pair at x (closest points), with their weights w (see
 * piola__contact). */
static double pair_distance2(const vec3 x[4], int edge_edge, double w[4]) {
  if (!edge_edge) {
    double b[3];
    double d2 = piola__point_triangle_closest(x[0], x[1], x[2], x[3], b);
    w[0] = 1.0, w[1] = -b[0], w[2] = -b[1], w[3] = -b[2];
    return d2;
  }
  double a, b;
  double d2 = piola__segment_segment_closest(x[0], x[1], x[2], x[3], &a, &b);
  w[0] = 1.0 - a, w[1] = a, w[2] = -(1.0 - b), w[3] = -b;
  return d2;
}

/* Proximity of a pair at x (x0) whose squared distance dist2 and weights c->w were just
 * computed: returns 1 and fills c when it is closer than its thickness. */
static int proximity_contact(const piola_collision_surface *s, const vec3 x[4], int edge_edge,
                             double dist2, piola__contact *c) {
  c->thickness = pair_thickness(s, c->v, edge_edge);
  if (!(dist2 < c->thickness * c->thickness)) return 0;
  c->friction = pair_friction(s, c->v);
  vec3 r = {0, 0, 0};
  for (int k = 0; k < 4; ++k) r = vec3_add(r, vec3_scale(x[k], c->w[k]));
  vec3 n = unit(r);
  if (vec3_norm2(n) == 0.0)
    n = unit(edge_edge ? vec3_cross(vec3_sub(x[1], x[0]), vec3_sub(x[3], x[2]))
                       : vec3_cross(vec3_sub(x[2], x[1]), vec3_sub(x[3], x[1])));
  if (vec3_norm2(n) == 0.0) return 0;
  c->normal = n;
  c->gap = vec3_dot(r, n);
  return 1;
}

/* How much farther apart than the tolerance allows a pair starts (m; negative when closer),
 * from its squared distance at x0: the separation bound of ccd_contact compares this with
 * how far the pair's vertices move relative to each other. */
static double ccd_separation(const piola_collision_surface *s, const int32_t v[4], int edge_edge,
                             double start2) {
  return sqrt(start2) - 2.0 * PIOLA__CCD_TOLERANCE * pair_thickness(s, v, edge_edge);
}

/* Continuous detection of a pair (c->v) with the given ccd_separation: returns 1 and fills c
 * when it collides during the step. */
static int ccd_contact(const piola_collision_surface *s, const double *x0, const double *v,
                       double dt, int edge_edge, double separation, piola__contact *c) {
  vec3 d[4];
  for (int k = 0; k < 4; ++k) d[k] = vec3_scale(vec3_load(v + 3 * c->v[k]), dt);
  /* Separation bound: any two points of the pair (fixed barycentric weights) move apart or
   * together by at most the largest relative displacement of a vertex of one side and a
   * vertex of the other, so a pair farther apart than that (and the tolerance) at the start
   * cannot touch. Tested first: it needs neither positions nor thickness. */
  double move2 = 0.0;
  const int first_b = edge_edge ? 2 : 1;
  for (int i = 0; i < first_b; ++i)
    for (int k = first_b; k < 4; ++k) {
      double m = vec3_norm2(vec3_sub(d[i], d[k]));
      move2 = m > move2 ? m : move2;
    }
  if (separation > 0.0 && separation * separation > move2) return 0;
  vec3 x[4];
  load_pair(x0, c->v, x);
  c->thickness = pair_thickness(s, c->v, edge_edge);
  double eps = PIOLA__CCD_TOLERANCE * c->thickness;
  piola__ccd_hit hit;
  int found = edge_edge ? piola__ccd_edge_edge(x, d, eps, &hit)
                        : piola__ccd_point_triangle(x, d, eps, &hit);
  if (!found) return 0;
  c->friction = pair_friction(s, c->v);
  memcpy(c->w, hit.w, sizeof(c->w));
  c->normal = hit.normal;
  vec3 r = {0, 0, 0};
  for (int k = 0; k < 4; ++k) r = vec3_add(r, vec3_scale(x[k], c->w[k]));
  c->gap = vec3_dot(r, hit.normal);
  return 1;
}

/* Narrow phase of one pair. Returns 1 and fills c when the pair is in contact (proximity) or
 * collides during the step (continuous detection). */
static int narrow_phase(const piola_collision_surface *s, const double *x0, const double *v,
                        double dt, detect_mode mode, int edge_edge, piola__contact *c) {
  c->edge_edge = edge_edge;
  vec3 x[4];
  load_pair(x0, c->v, x);
  double dist2 = pair_distance2(x, edge_edge, c->w);
  if (mode == DETECT_PROXIMITY) return proximity_contact(s, x, edge_edge, dist2, c);
  return ccd_contact(s, x0, v, dt, edge_edge, ccd_separation(s, c->v, edge_edge, dist2), c);
}

/* ---------------------------------------------------------- candidates: tree against tree
 * Candidate pairs are found by descending two trees together (a vertex tree against the
 * triangle tree, the edge tree against itself), which visits each overlapping node pair once
 * instead of descending from the root for every primitive. The top of the descent is done
 * sequentially, into a fixed number of independent tasks (node pairs), which then run in
 * parallel, each into its own list; lists are joined in task order, so the result does not
 * depend on the thread count. */

typedef struct node_pair {
  int32_t a, b; /* node indices; a == b means the pairs within one subtree (same tree) */
} node_pair;

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

static int pair_list_push(piola__pair_list *list, const piola__pair *p) {
  if ((size_t)list->count == list->capacity &&
      piola__grow((void **)&list->items, &list->capacity, (size_t)list->count + 1,
                  sizeof *list->items))
    return -1;
  list->items[list->count++] = *p;
  return 0;
}

/* What one tree task found: candidate pairs for continuous detection, contacts at x0. */
typedef struct task_output {
  piola__pair_list pairs;
  piola__contact_list near;
} task_output;

/* A pair whose reach boxes overlap: its distance at x0 decides whether it is in contact
 * (closer than its thickness) and whether it can collide during the step while its vertices
 * stay in their reach boxes (closer than their reach radii and the tolerance allow). Returns
 * 0, or -1 out of memory. */
static int classify_pair(const piola_collision_surface *s, const double *x0, const int32_t v[4],
                         int edge_edge, int with_near, task_output *out) {
  if (left_out(s, v, edge_edge)) return 0;
  vec3 x[4];
  load_pair(x0, v, x);
  piola__contact c = {.v = {v[0], v[1], v[2], v[3]}, .edge_edge = edge_edge};
  double dist2 = pair_distance2(x, edge_edge, c.w);
  if (with_near && proximity_contact(s, x, edge_edge, dist2, &c) &&
      piola__contact_list_push(&out->near, &c))
    return -1;
  const double *r = s->reach_radius;
  const int first_b = edge_edge ? 2 : 1;
  double ra = r[v[0]], rb = r[v[first_b]];
  if (edge_edge) ra = dmax(ra, r[v[1]]);
  for (int k = first_b + 1; k < 4; ++k) rb = dmax(rb, r[v[k]]);
  /* ccd_contact rejects pairs with sqrt(start2) > max |d_i - d_k| + 2 eps, and |d_i| stays
   * within the reach radius; the factor covers rounding. */
  double reach = (ra + rb + 2.0 * PIOLA__CCD_TOLERANCE * pair_thickness(s, v, edge_edge)) * 1.0001;
  if (dist2 > reach * reach) return 0;
  piola__pair p = {.v = {v[0], v[1], v[2], v[3]},
                   .edge_edge = edge_edge,
                   .separation = ccd_separation(s, v, edge_edge, dist2)};
  return pair_list_push(&out->pairs, &p);
}

static int emit_vertex_triangle(const piola_collision_surface *s, const double *x0, int32_t p,
                                int32_t t, int with_near, task_output *out) {
  const int32_t *tri = s->triangles + 3 * t;
  if (!s->on_surface[p] || tri[0] == p || tri[1] == p || tri[2] == p) return 0;
  const int32_t v[4] = {p, tri[0], tri[1], tri[2]};
  return classify_pair(s, x0, v, 0, with_near, out);
}

static int emit_edge_edge(const piola_collision_surface *s, const double *x0, int32_t a, int32_t b,
                          int with_near, task_output *out) {
  const int32_t a0 = s->edges[2 * a], a1 = s->edges[2 * a + 1];
  const int32_t b0 = s->edges[2 * b], b1 = s->edges[2 * b + 1];
  if (a0 == b0 || a0 == b1 || a1 == b0 || a1 == b1) return 0;
  const int32_t v[4] = {a0, a1, b0, b1};
  return classify_pair(s, x0, v, 1, with_near, out);
}

/* Runs one task to the end with an explicit stack. Returns 0, or -1 out of memory. */
static int run_task(const piola_collision_surface *s, const double *x0, const piola__bvh *ta,
                    const piola__bvh *tb, int same_tree, int with_near, node_pair task,
                    task_output *out) {
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
    const piola__box *boxes_a = ta->leaf_boxes + na->first, *boxes_b = tb->leaf_boxes + nb->first;
    for (int32_t i = 0; i < na->count; ++i) {
      const int32_t pa = ta->order[na->first + i];
      for (int32_t j = (same_tree && t.a == t.b) ? i + 1 : 0; j < nb->count; ++j) {
        if (!piola__boxes_overlap(&boxes_a[i], &boxes_b[j])) continue;
        const int32_t pb = tb->order[nb->first + j];
        const double *slabs_a =
            same_tree ? s->edge_slabs + SLABS * (size_t)pa : s->vertex_slabs + SLABS * (size_t)pa;
        const double *slabs_b =
            same_tree ? s->edge_slabs + SLABS * (size_t)pb : s->triangle_slabs + SLABS * (size_t)pb;
        if (!slabs_overlap(slabs_a, slabs_b)) continue;
        int failed =
            same_tree ? emit_edge_edge(s, x0, pa < pb ? pa : pb, pa < pb ? pb : pa, with_near, out)
                      : emit_vertex_triangle(s, x0, pa, pb, with_near, out);
        if (failed) return -1;
      }
    }
  }
  return 0;
}

static int append_contacts(piola__contact_list *dst, const piola__contact *src, int64_t n) {
  if (piola__grow((void **)&dst->items, &dst->capacity, (size_t)(dst->count + n),
                  sizeof *dst->items))
    return -1;
  if (n > 0) memcpy(dst->items + dst->count, src, sizeof(*src) * (size_t)n);
  dst->count += n;
  return 0;
}

/* Makes room for n tasks' lists (kept from call to call, so their memory is reused). */
static int reserve_tasks(piola_collision_surface *s, int32_t n) {
  if (n <= s->task_capacity) return 0;
  piola__pair_list *pairs = realloc(s->candidates, sizeof(*pairs) * (size_t)n);
  if (!pairs) return -1;
  s->candidates = pairs;
  piola__contact_list *near = realloc(s->near, sizeof(*near) * (size_t)n);
  if (!near) return -1;
  s->near = near;
  piola__contact_list *found = realloc(s->task_found, sizeof(*found) * (size_t)n);
  if (!found) return -1;
  s->task_found = found;
  const size_t added = (size_t)(n - s->task_capacity);
  memset(s->candidates + s->task_capacity, 0, sizeof(*pairs) * added);
  memset(s->near + s->task_capacity, 0, sizeof(*near) * added);
  memset(s->task_found + s->task_capacity, 0, sizeof(*found) * added);
  s->task_capacity = n;
  return 0;
}

/* The tree descent over reach boxes (with the contacts at x0), or, when tight, over the swept
 * boxes of the current velocities (no contacts: only the detection pass at hand uses them). */
static int collect(piola_collision_surface *s, const double *x0, const double *v, double dt,
                   int *tree_built, int tight) {
  ++s->profile.collections;
  s->task_count = 0, s->candidate_count = 0;
  s->near_valid = !tight;
  compute_vertex_boxes(s, x0, v, dt, tight ? BOX_SWEPT : BOX_REACH);
  if (tight)
    for (int32_t i = 0; i < s->vertex_count; ++i)
      s->reach_radius[i] = reach_radius(&s->vertex_boxes[i], x0 + 3 * i);
  memcpy(s->reach_boxes, s->vertex_boxes, sizeof(piola__box) * (size_t)s->vertex_count);
  compute_primitive_boxes(s);
  compute_slabs(s);
  if (fit_trees(s, tree_built)) return -1;
  int32_t nvt, nee;
  node_pair *vt = make_tasks(&s->vertex_tree, &s->triangle_tree, 0, &nvt);
  node_pair *ee = make_tasks(&s->edge_tree, &s->edge_tree, 1, &nee);
  int failed = !vt || !ee;
  const int32_t total = failed ? 0 : nvt + nee;
  if (!failed && reserve_tasks(s, total)) failed = 1;
  if (!failed) {
#pragma omp parallel for schedule(dynamic, 1) num_threads(piola_thread_count()) \
    reduction(|                                                                  \
              : failed) if (total >= 64 && s->triangle_count >= 2048)
    for (int32_t i = 0; i < total; ++i) {
      task_output out = {s->candidates[i], s->near[i]};
      out.pairs.count = 0, out.near.count = 0;
      if (!failed) {
        if (i < nvt)
          failed |= run_task(s, x0, &s->vertex_tree, &s->triangle_tree, 0, !tight, vt[i], &out);
        else
          failed |= run_task(s, x0, &s->edge_tree, &s->edge_tree, 1, !tight, ee[i - nvt], &out);
      }
      s->candidates[i] = out.pairs, s->near[i] = out.near;
    }
  }
  free(vt), free(ee);
  if (failed) return -1;
  s->task_count = total;
  for (int32_t i = 0; i < total; ++i) s->candidate_count += s->candidates[i].count;
  return 0;
}

int piola__collect_candidates(piola_collision_surface *s, const double *x0, const double *v,
                              double dt, int *tree_built) {
  return collect(s, x0, v, dt, tree_built, 0);
}

static int any_flag(const uint8_t *flags, const int32_t v[4]) {
  return flags[v[0]] || flags[v[1]] || flags[v[2]] || flags[v[3]];
}

/* Continuous detection of the candidates (skipping those with a vertex marked in skip, when
 * given), appended to s->found in candidate order. The lists of the tree tasks run in
 * parallel, each into its own list. Returns 0, or -1 out of memory. */
static int scan_candidates(piola_collision_surface *s, const double *x0, const double *v, double dt,
                           const uint8_t *skip) {
  const int32_t tasks = s->task_count;
  int failed = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(piola_thread_count()) \
    reduction(|                                                                  \
              : failed) if (s->candidate_count >= 4 * SCAN_CHUNK)
  for (int32_t t = 0; t < tasks; ++t) {
    piola__contact_list *list = &s->task_found[t];
    list->count = 0;
    if (failed) continue;
    const piola__pair *pairs = s->candidates[t].items;
    const int64_t n = s->candidates[t].count;
    for (int64_t i = 0; i < n; ++i) {
      const piola__pair *p = &pairs[i];
      if (skip && any_flag(skip, p->v)) continue;
      piola__contact contact = {.v = {p->v[0], p->v[1], p->v[2], p->v[3]},
                                .edge_edge = p->edge_edge};
      if (ccd_contact(s, x0, v, dt, p->edge_edge, p->separation, &contact) &&
          piola__contact_list_push(list, &contact)) {
        failed = 1;
        break;
      }
    }
  }
  for (int32_t t = 0; t < tasks && !failed; ++t)
    if (append_contacts(&s->found, s->task_found[t].items, s->task_found[t].count)) failed = 1;
  return failed ? -1 : 0;
}

/* Pairs of one query primitive with the candidates the tree returns for its box, each pair
 * with a vertex marked in `dirty` once, and (when filter is given) with a vertex marked in
 * filter; appends the contacts found to list. Returns 0, or -1 out of memory. */
static int query_pairs(const piola_collision_surface *s, const double *x0, const double *v,
                       double dt, detect_mode mode, const uint8_t *dirty, const uint8_t *filter,
                       query_kind kind, int32_t q, piola__index_list *candidates,
                       piola__contact_list *list) {
  candidates->count = 0;
  if (kind == QUERY_VERTEX) {
    if (piola__bvh_query(&s->triangle_tree, &s->vertex_boxes[q], candidates)) return -1;
    for (int64_t j = 0; j < candidates->count; ++j) {
      const int32_t *tri = s->triangles + 3 * candidates->items[j];
      if (tri[0] == q || tri[1] == q || tri[2] == q) continue;
      piola__contact c = {.v = {q, tri[0], tri[1], tri[2]}};
      if (left_out(s, c.v, 0) || (filter && !any_flag(filter, c.v))) continue;
      if (narrow_phase(s, x0, v, dt, mode, 0, &c) && piola__contact_list_push(list, &c)) return -1;
    }
  } else if (kind == QUERY_TRIANGLE) {
    /* Only with a dirty triangle, and only clean vertices: dirty ones query themselves. */
    if (piola__bvh_query(&s->vertex_tree, &s->triangle_boxes[q], candidates)) return -1;
    const int32_t *tri = s->triangles + 3 * q;
    for (int64_t j = 0; j < candidates->count; ++j) {
      const int32_t p = candidates->items[j];
      if (dirty[p] || !s->on_surface[p] || tri[0] == p || tri[1] == p || tri[2] == p) continue;
      piola__contact c = {.v = {p, tri[0], tri[1], tri[2]}};
      if (left_out(s, c.v, 0) || (filter && !any_flag(filter, c.v))) continue;
      if (narrow_phase(s, x0, v, dt, mode, 0, &c) && piola__contact_list_push(list, &c)) return -1;
    }
  } else {
    if (piola__bvh_query(&s->edge_tree, &s->edge_boxes[q], candidates)) return -1;
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
      if (left_out(s, c.v, 1) || (filter && !any_flag(filter, c.v))) continue;
      if (narrow_phase(s, x0, v, dt, mode, 1, &c) && piola__contact_list_push(list, &c)) return -1;
    }
  }
  return 0;
}

/* Every pair with a vertex marked in mask (and one marked in filter, when given), found by
 * querying the trees (fit to the current boxes) from the marked vertices and from the
 * triangles and edges that touch one; appended to s->found in block order. Returns 0, or -1
 * out of memory. */
static int query_marked(piola_collision_surface *s, const double *x0, const double *v, double dt,
                        detect_mode mode, const uint8_t *mask, const uint8_t *filter) {
  /* The queries: (kind, primitive) in three runs. */
  int32_t runs[3] = {0, 0, 0}, n = 0;
  for (int32_t i = 0; i < s->vertex_count; ++i)
    if (mask[i] && s->on_surface[i]) s->queries[n++] = i;
  runs[0] = n;
  for (int32_t t = 0; t < s->triangle_count; ++t) {
    const int32_t *tri = s->triangles + 3 * t;
    if (mask[tri[0]] || mask[tri[1]] || mask[tri[2]]) s->queries[n++] = t;
  }
  runs[1] = n;
  for (int32_t e = 0; e < s->edge_count; ++e)
    if (mask[s->edges[2 * e]] || mask[s->edges[2 * e + 1]]) s->queries[n++] = e;
  runs[2] = n;
  /* Blocks never straddle two runs, so each block has one kind. */
  int32_t block_start[3], blocks = 0;
  for (int r = 0; r < 3; ++r) {
    block_start[r] = blocks;
    int32_t len = runs[r] - (r ? runs[r - 1] : 0);
    blocks += (len + PIOLA__QUERY_BLOCK - 1) / PIOLA__QUERY_BLOCK;
  }
  int failed = 0;
#pragma omp parallel num_threads(piola_thread_count()) reduction(| : failed) if (blocks >= 16)
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
      const int32_t first = run_begin + (b - block_start[r]) * PIOLA__QUERY_BLOCK;
      const int32_t end =
          first + PIOLA__QUERY_BLOCK < runs[r] ? first + PIOLA__QUERY_BLOCK : runs[r];
      for (int32_t i = first; i < end; ++i)
        if (query_pairs(s, x0, v, dt, mode, mask, filter, kind, s->queries[i], &candidates, list)) {
          failed = 1;
          break;
        }
    }
    free(candidates.items);
  }
  /* Candidates of a query come out in tree order, which the deterministic build fixes. */
  for (int32_t b = 0; b < blocks && !failed; ++b)
    if (append_contacts(&s->found, s->blocks[b].items, s->blocks[b].count)) failed = 1;
  return failed ? -1 : 0;
}

int piola__detect(piola_collision_surface *s, const double *x0, const double *v, double dt,
                  piola__detect_mode mode, const uint8_t *dirty, int *tree_built) {
  s->found.count = 0;
  if (mode == DETECT_PROXIMITY) {
    /* Reach boxes hold the proximity boxes, so every contact was found with the candidates
     * (unless a tight collection replaced them). */
    if (!s->near_valid && collect(s, x0, v, dt, tree_built, 0)) return -1;
    for (int32_t t = 0; t < s->task_count; ++t)
      for (int64_t i = 0; i < s->near[t].count; ++i)
        if ((!dirty || any_flag(dirty, s->near[t].items[i].v)) &&
            piola__contact_list_push(&s->found, &s->near[t].items[i]))
          return -1;
    return 0;
  }
  if (dirty) {
    /* A later pass: only pairs with a dirty vertex, and velocities that may have changed
     * much (impacts, rigid zones). Querying the trees, refit to the swept boxes, from the
     * dirty vertices and the triangles and edges touching them is cheaper than scanning
     * every candidate and following the escapes. */
    compute_vertex_boxes(s, x0, v, dt, BOX_SWEPT);
    compute_primitive_boxes(s);
    if (fit_trees(s, tree_built)) return -1;
    return query_marked(s, x0, v, dt, mode, dirty, NULL);
  }
  int32_t escaped = compute_vertex_boxes(s, x0, v, dt, BOX_SWEPT);
  s->profile.escaped += escaped;
  if (escaped > 0 && (int64_t)escaped * ESCAPE_FRACTION > s->vertex_count) {
    /* Too many velocities changed too much: collect the candidates again, for this pass only
     * (later passes query the trees), so with the swept boxes. */
    if (collect(s, x0, v, dt, tree_built, 1)) return -1;
    escaped = compute_vertex_boxes(s, x0, v, dt, BOX_SWEPT);
  }
  if (scan_candidates(s, x0, v, dt, escaped > 0 ? s->escaped : NULL)) return -1;
  if (escaped == 0) return 0;
  /* Pairs with an escaped vertex may be missing from the candidates: query the trees, refit
   * to the swept boxes, for them. */
  compute_primitive_boxes(s);
  if (fit_trees(s, tree_built)) return -1;
  return query_marked(s, x0, v, dt, mode, s->escaped, NULL);
}

int piola__detect_all_pairs(const piola_collision_surface *s, const double *x0, const double *v,
                            double dt, piola__detect_mode mode, piola__contact_list *out) {
  out->count = 0;
  for (int32_t p = 0; p < s->vertex_count; ++p) {
    if (!s->on_surface[p]) continue;
    for (int32_t t = 0; t < s->triangle_count; ++t) {
      const int32_t *tri = s->triangles + 3 * t;
      if (tri[0] == p || tri[1] == p || tri[2] == p) continue;
      piola__contact c = {.v = {p, tri[0], tri[1], tri[2]}};
      if (left_out(s, c.v, 0)) continue;
      if (narrow_phase(s, x0, v, dt, mode, 0, &c) && piola__contact_list_push(out, &c)) return -1;
    }
  }
  for (int32_t a = 0; a < s->edge_count; ++a)
    for (int32_t b = a + 1; b < s->edge_count; ++b) {
      const int32_t a0 = s->edges[2 * a], a1 = s->edges[2 * a + 1];
      const int32_t b0 = s->edges[2 * b], b1 = s->edges[2 * b + 1];
      if (a0 == b0 || a0 == b1 || a1 == b0 || a1 == b1) continue;
      piola__contact c = {.v = {a0, a1, b0, b1}};
      if (left_out(s, c.v, 1)) continue;
      if (narrow_phase(s, x0, v, dt, mode, 1, &c) && piola__contact_list_push(out, &c)) return -1;
    }
  return 0;
}
