#include "geometry/surface_distance.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"

#define LEAF_SIZE 4
#define FAR_FIELD_RATIO 2.0
#define STACK_DEPTH 128

typedef struct bvh_node {
  vec3 lo, hi;
  vec3 area_normal;   /* sum of area-weighted normals (m^2) */
  vec3 centroid;      /* area-weighted centroid (m) */
  double radius;      /* of a ball around centroid holding the node's box (m) */
  int32_t left;       /* child index, or -1 for a leaf */
  int32_t right;
  int32_t first, count; /* leaf: order[first .. first+count) */
} bvh_node;

struct piola__surface_distance {
  int32_t vertex_count, triangle_count;
  vec3 *x;
  int32_t *tri;
  int32_t *order;
  bvh_node *nodes;
  int32_t node_count;
  vec3 lo, hi;
};

typedef struct directed_edge {
  int32_t lo, hi;  /* sorted vertex ids */
  int32_t from;    /* the tail of the edge as the triangle winds it */
  int32_t triangle;
} directed_edge;

static int compare_edges(const void *pa, const void *pb) {
  const directed_edge *a = pa, *b = pb;
  if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
  if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
  return a->triangle < b->triangle ? -1 : (a->triangle > b->triangle);
}

piola_status piola__surface_check_closed(const piola_tri_mesh *mesh) {
  if (!mesh || mesh->triangle_count <= 0 || mesh->vertex_count <= 0 || !mesh->triangles ||
      !mesh->positions)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "surface: empty triangle mesh");
  int32_t n = mesh->triangle_count;
  for (int32_t v = 0; v < mesh->vertex_count; ++v)
    for (int k = 0; k < 3; ++k)
      if (!isfinite(mesh->positions[3 * (size_t)v + k]))
        return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "surface: vertex %d has a non-finite position",
                          (int)v);
  for (int32_t t = 0; t < n; ++t) {
    const int32_t *f = mesh->triangles + 3 * (size_t)t;
    for (int k = 0; k < 3; ++k)
      if (f[k] < 0 || f[k] >= mesh->vertex_count)
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                          "surface: triangle %d uses vertex %d, out of range [0, %d)", (int)t,
                          (int)f[k], (int)mesh->vertex_count);
    if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2])
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "surface: triangle %d (%d, %d, %d) repeats a vertex", (int)t, (int)f[0],
                        (int)f[1], (int)f[2]);
  }
  directed_edge *edges = malloc((size_t)n * 3 * sizeof(directed_edge));
  if (!edges) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "surface: edge table");
  for (int32_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k) {
      int32_t a = mesh->triangles[3 * (size_t)t + k], b = mesh->triangles[3 * (size_t)t + (k + 1) % 3];
      edges[3 * (size_t)t + k] = (directed_edge){a < b ? a : b, a < b ? b : a, a, t};
    }
  qsort(edges, (size_t)n * 3, sizeof(directed_edge), compare_edges);
  piola_status status = PIOLA_OK;
  for (size_t i = 0; i < (size_t)n * 3;) {
    size_t j = i;
    while (j < (size_t)n * 3 && edges[j].lo == edges[i].lo && edges[j].hi == edges[i].hi) ++j;
    size_t uses = j - i;
    if (uses == 1) {
      status = PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                          "surface is open: edge (%d, %d) is used by 1 triangle (%d); a closed "
                          "surface uses every edge twice",
                          (int)edges[i].lo, (int)edges[i].hi, (int)edges[i].triangle);
      break;
    }
    if (uses > 2) {
      status = PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                          "surface is not manifold: edge (%d, %d) is used by %d triangles",
                          (int)edges[i].lo, (int)edges[i].hi, (int)uses);
      break;
    }
    if (edges[i].from == edges[i + 1].from) {
      status = PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                          "surface is not consistently oriented: edge (%d, %d) runs the same "
                          "way in triangles %d and %d",
                          (int)edges[i].lo, (int)edges[i].hi, (int)edges[i].triangle,
                          (int)edges[i + 1].triangle);
      break;
    }
    i = j;
  }
  free(edges);
  return status;
}

/* ------------------------------------------------------------------ tree construction */

static vec3 vmin(vec3 a, vec3 b) { return vec3_make(fmin(a.x, b.x), fmin(a.y, b.y), fmin(a.z, b.z)); }
static vec3 vmax(vec3 a, vec3 b) { return vec3_make(fmax(a.x, b.x), fmax(a.y, b.y), fmax(a.z, b.z)); }

static vec3 tri_centroid(const piola__surface_distance *s, int32_t t) {
  const int32_t *f = s->tri + 3 * (size_t)t;
  return vec3_scale(vec3_add(vec3_add(s->x[f[0]], s->x[f[1]]), s->x[f[2]]), 1.0 / 3.0);
}


/* Partial sort by centroid along an axis (nth_element by quickselect). */
static void select_median(const piola__surface_distance *s, int32_t *items, int32_t count,
                          int32_t k, int axis) {
  int32_t lo = 0, hi = count - 1;
  while (lo < hi) {
    double pivot = vec3_get(tri_centroid(s, items[(lo + hi) / 2]), axis);
    int32_t i = lo, j = hi;
    while (i <= j) {
      while (vec3_get(tri_centroid(s, items[i]), axis) < pivot) ++i;
      while (vec3_get(tri_centroid(s, items[j]), axis) > pivot) --j;
      if (i <= j) {
        int32_t tmp = items[i];
        items[i] = items[j];
        items[j] = tmp;
        ++i;
        --j;
      }
    }
    if (k <= j)
      hi = j;
    else if (k >= i)
      lo = i;
    else
      break;
  }
}

static int32_t build_node(piola__surface_distance *s, int32_t first, int32_t count) {
  int32_t id = s->node_count++;
  bvh_node node = {0};
  node.lo = vec3_make(INFINITY, INFINITY, INFINITY);
  node.hi = vec3_neg(node.lo);
  vec3 clo = node.lo, chi = node.hi;
  double area_sum = 0;
  vec3 weighted = {0, 0, 0};
  for (int32_t i = first; i < first + count; ++i) {
    const int32_t *f = s->tri + 3 * (size_t)s->order[i];
    vec3 a = s->x[f[0]], b = s->x[f[1]], c = s->x[f[2]];
    node.lo = vmin(node.lo, vmin(a, vmin(b, c)));
    node.hi = vmax(node.hi, vmax(a, vmax(b, c)));
    vec3 m = tri_centroid(s, s->order[i]);
    clo = vmin(clo, m);
    chi = vmax(chi, m);
    vec3 an = vec3_scale(vec3_cross(vec3_sub(b, a), vec3_sub(c, a)), 0.5);
    double area = vec3_norm(an);
    node.area_normal = vec3_add(node.area_normal, an);
    weighted = vec3_add(weighted, vec3_scale(m, area));
    area_sum += area;
  }
  node.centroid = area_sum > 0 ? vec3_scale(weighted, 1.0 / area_sum)
                               : vec3_scale(vec3_add(node.lo, node.hi), 0.5);
  vec3 box_mid = vec3_scale(vec3_add(node.lo, node.hi), 0.5);
  node.radius = vec3_norm(vec3_sub(node.centroid, box_mid)) +
                0.5 * vec3_norm(vec3_sub(node.hi, node.lo));
  node.first = first;
  node.count = count;
  node.left = node.right = -1;
  s->nodes[id] = node;
  if (count > LEAF_SIZE) {
    vec3 ext = vec3_sub(chi, clo);
    int axis = ext.x >= ext.y ? (ext.x >= ext.z ? 0 : 2) : (ext.y >= ext.z ? 1 : 2);
    int32_t half = count / 2;
    select_median(s, s->order + first, count, half, axis);
    int32_t left = build_node(s, first, half);
    int32_t right = build_node(s, first + half, count - half);
    s->nodes[id].left = left;
    s->nodes[id].right = right;
  }
  return id;
}

piola_status piola__surface_distance_create(const piola_tri_mesh *mesh,
                                            piola__surface_distance **out) {
  *out = NULL;
  PIOLA_TRY(piola__surface_check_closed(mesh));
  piola__surface_distance *s = calloc(1, sizeof(*s));
  if (!s) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "surface: distance object");
  s->vertex_count = mesh->vertex_count;
  s->triangle_count = mesh->triangle_count;
  s->x = malloc((size_t)s->vertex_count * sizeof(vec3));
  s->tri = malloc((size_t)s->triangle_count * 3 * sizeof(int32_t));
  s->order = malloc((size_t)s->triangle_count * sizeof(int32_t));
  s->nodes = malloc((size_t)s->triangle_count * 2 * sizeof(bvh_node));
  if (!s->x || !s->tri || !s->order || !s->nodes) {
    piola__surface_distance_destroy(s);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "surface: distance object");
  }
  s->lo = vec3_make(INFINITY, INFINITY, INFINITY);
  s->hi = vec3_neg(s->lo);
  for (int32_t v = 0; v < s->vertex_count; ++v) {
    s->x[v] = vec3_load(mesh->positions + 3 * (size_t)v);
    s->lo = vmin(s->lo, s->x[v]);
    s->hi = vmax(s->hi, s->x[v]);
  }
  memcpy(s->tri, mesh->triangles, (size_t)s->triangle_count * 3 * sizeof(int32_t));
  for (int32_t t = 0; t < s->triangle_count; ++t) s->order[t] = t;
  build_node(s, 0, s->triangle_count);
  *out = s;
  return PIOLA_OK;
}

void piola__surface_distance_destroy(piola__surface_distance *s) {
  if (!s) return;
  free(s->x);
  free(s->tri);
  free(s->order);
  free(s->nodes);
  free(s);
}

void piola__surface_bounds(const piola__surface_distance *s, vec3 *lo, vec3 *hi) {
  *lo = s->lo;
  *hi = s->hi;
}

double piola__surface_volume(const piola__surface_distance *s) {
  double v = 0;
  for (int32_t t = 0; t < s->triangle_count; ++t) {
    const int32_t *f = s->tri + 3 * (size_t)t;
    v += vec3_dot(s->x[f[0]], vec3_cross(s->x[f[1]], s->x[f[2]]));
  }
  return v / 6.0;
}

/* ------------------------------------------------------------------ queries */

/* Closest point of triangle (a, b, c) to p, by the Voronoi region of p. */
static vec3 closest_on_triangle(vec3 p, vec3 a, vec3 b, vec3 c) {
  vec3 ab = vec3_sub(b, a), ac = vec3_sub(c, a), ap = vec3_sub(p, a);
  double d1 = vec3_dot(ab, ap), d2 = vec3_dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  vec3 bp = vec3_sub(p, b);
  double d3 = vec3_dot(ab, bp), d4 = vec3_dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return vec3_add(a, vec3_scale(ab, d1 / (d1 - d3)));
  vec3 cp = vec3_sub(p, c);
  double d5 = vec3_dot(ab, cp), d6 = vec3_dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return vec3_add(a, vec3_scale(ac, d2 / (d2 - d6)));
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return vec3_add(b, vec3_scale(vec3_sub(c, b), w));
  }
  double denom = 1.0 / (va + vb + vc);
  return vec3_add(a, vec3_add(vec3_scale(ab, vb * denom), vec3_scale(ac, vc * denom)));
}

static double box_distance2(vec3 p, vec3 lo, vec3 hi) {
  double dx = lo.x - p.x > 0 ? lo.x - p.x : (p.x - hi.x > 0 ? p.x - hi.x : 0);
  double dy = lo.y - p.y > 0 ? lo.y - p.y : (p.y - hi.y > 0 ? p.y - hi.y : 0);
  double dz = lo.z - p.z > 0 ? lo.z - p.z : (p.z - hi.z > 0 ? p.z - hi.z : 0);
  return dx * dx + dy * dy + dz * dz;
}

double piola__surface_closest_point(const piola__surface_distance *s, vec3 p, vec3 *closest,
                                    int32_t *triangle) {
  return piola__surface_closest_point_within(s, p, INFINITY, closest, triangle);
}

double piola__surface_closest_point_within(const piola__surface_distance *s, vec3 p,
                                           double max_distance, vec3 *closest,
                                           int32_t *triangle) {
  double best = max_distance * max_distance;
  vec3 best_point = p;
  int32_t best_tri = -1;
  int32_t stack[STACK_DEPTH];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const bvh_node *n = &s->nodes[stack[--top]];
    if (box_distance2(p, n->lo, n->hi) >= best) continue;
    if (n->left < 0) {
      for (int32_t i = n->first; i < n->first + n->count; ++i) {
        const int32_t *f = s->tri + 3 * (size_t)s->order[i];
        vec3 q = closest_on_triangle(p, s->x[f[0]], s->x[f[1]], s->x[f[2]]);
        double d2 = vec3_norm2(vec3_sub(p, q));
        if (d2 < best) {
          best = d2;
          best_point = q;
          best_tri = s->order[i];
        }
      }
      continue;
    }
    /* Push the farther child first so the nearer one is searched first. */
    double dl = box_distance2(p, s->nodes[n->left].lo, s->nodes[n->left].hi);
    double dr = box_distance2(p, s->nodes[n->right].lo, s->nodes[n->right].hi);
    if (top + 2 > STACK_DEPTH) continue; /* cannot happen for a median-split tree */
    if (dl < dr) {
      stack[top++] = n->right;
      stack[top++] = n->left;
    } else {
      stack[top++] = n->left;
      stack[top++] = n->right;
    }
  }
  if (closest) *closest = best_point;
  if (triangle) *triangle = best_tri;
  return best_tri < 0 ? INFINITY : sqrt(best);
}

static double triangle_solid_angle(vec3 p, vec3 a, vec3 b, vec3 c) {
  vec3 x = vec3_sub(a, p), y = vec3_sub(b, p), z = vec3_sub(c, p);
  double lx = vec3_norm(x), ly = vec3_norm(y), lz = vec3_norm(z);
  double numerator = vec3_dot(x, vec3_cross(y, z));
  double denominator = lx * ly * lz + vec3_dot(x, y) * lz + vec3_dot(x, z) * ly + vec3_dot(y, z) * lx;
  return 2.0 * atan2(numerator, denominator);
}

double piola__surface_winding_number(const piola__surface_distance *s, vec3 p) {
  double total = 0;
  int32_t stack[STACK_DEPTH];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const bvh_node *n = &s->nodes[stack[--top]];
    vec3 r = vec3_sub(n->centroid, p);
    double dist = vec3_norm(r);
    if (dist > FAR_FIELD_RATIO * n->radius) {
      total += vec3_dot(r, n->area_normal) / (dist * dist * dist);
      continue;
    }
    if (n->left < 0 || top + 2 > STACK_DEPTH) {
      for (int32_t i = n->first; i < n->first + n->count; ++i) {
        const int32_t *f = s->tri + 3 * (size_t)s->order[i];
        total += triangle_solid_angle(p, s->x[f[0]], s->x[f[1]], s->x[f[2]]);
      }
      continue;
    }
    stack[top++] = n->left;
    stack[top++] = n->right;
  }
  return total / (4.0 * M_PI);
}

double piola__surface_signed_distance(const piola__surface_distance *s, vec3 p, vec3 *normal,
                                      vec3 *closest) {
  vec3 q;
  int32_t t;
  double d = piola__surface_closest_point(s, p, &q, &t);
  int inside = piola__surface_winding_number(s, p) > 0.5;
  if (closest) *closest = q;
  if (normal) {
    vec3 away = vec3_sub(p, q);
    double len = vec3_norm(away);
    if (len > 1e-12 * (1.0 + vec3_norm(p))) {
      *normal = vec3_scale(away, inside ? -1.0 / len : 1.0 / len);
    } else {
      const int32_t *f = s->tri + 3 * (size_t)t;
      vec3 m = vec3_cross(vec3_sub(s->x[f[1]], s->x[f[0]]), vec3_sub(s->x[f[2]], s->x[f[0]]));
      double ml = vec3_norm(m);
      *normal = ml > 0 ? vec3_scale(m, 1.0 / ml) : vec3_make(0, 0, 1);
    }
  }
  return inside ? -d : d;
}
