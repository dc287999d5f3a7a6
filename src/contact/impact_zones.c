/* Rigid impact zones (Provot 1997, BFA02 section 7.3): the fail-safe of collision processing. */
#include <stdlib.h>
#include <string.h>

#include "common/union_find.h"
#include "contact/contact_internal.h"
#include "math/inertia.h"

/* The points zones are made of: the surface's vertices, or an embedded surface's nodes. */
typedef struct zone_points {
  int32_t n;
  int32_t *parent, *order;
  uint8_t *in_zone, *dirty;
  const double *inverse_mass, *x0;
  double *v;
} zone_points;

/* Groups the points marked in_zone by their root (parent) and gives every zone the rigid
 * velocity field; returns the number of zones, or -1 out of memory. */
static int32_t rigid_zones(piola_collision_surface *s, const zone_points *z, int32_t *zone_vertices) {
  int32_t *parent = z->parent;
  const double *x0 = z->x0;
  double *v = z->v;
  /* Group zone vertices by root with a counting sort (zone_order), roots ascending. */
  const int32_t n = z->n;
  int32_t *start = calloc((size_t)n + 1, sizeof(int32_t));
  if (!start) return -1;
  int32_t members = 0;
  for (int32_t i = 0; i < n; ++i)
    if (z->in_zone[i]) ++start[piola__union_find_root(parent, i) + 1], ++members;
  for (int32_t i = 0; i < n; ++i) start[i + 1] += start[i];
  int32_t *fill = malloc(sizeof(int32_t) * ((size_t)n + 1));
  if (!fill) {
    free(start);
    return -1;
  }
  for (int32_t i = 0; i <= n; ++i) fill[i] = start[i];
  for (int32_t i = 0; i < n; ++i)
    if (z->in_zone[i]) z->order[fill[piola__union_find_root(parent, i)]++] = i;
  free(fill);

  int32_t zones = 0;
  for (int32_t root = 0; root < n; ++root) {
    const int32_t begin = start[root], end = start[root + 1];
    if (begin == end) continue;
    ++zones;
    const int32_t *ids = z->order + begin;
    /* Pinned vertices, if any, decide the motion: the rigid field that fits their velocities
     * best (equal weights); otherwise momentum does: v_cm and w from L = I w. */
    int pinned = 0;
    for (int32_t j = 0; j < end - begin; ++j) pinned += z->inverse_mass[ids[j]] == 0.0;
    double total = 0.0;
    vec3 centre = {0, 0, 0}, momentum = {0, 0, 0};
    for (int32_t j = 0; j < end - begin; ++j) {
      const int32_t i = ids[j];
      const double im = z->inverse_mass[i];
      if (pinned ? im != 0.0 : im == 0.0) continue;
      double m = pinned ? 1.0 : 1.0 / im;
      total += m;
      centre = vec3_add(centre, vec3_scale(vec3_load(x0 + 3 * i), m));
      momentum = vec3_add(momentum, vec3_scale(vec3_load(v + 3 * i), m));
    }
    centre = vec3_scale(centre, 1.0 / total);
    vec3 v_centre = vec3_scale(momentum, 1.0 / total);
    vec3 angular = {0, 0, 0};
    mat3 inertia = mat3_zero();
    for (int32_t j = 0; j < end - begin; ++j) {
      const int32_t i = ids[j];
      const double im = z->inverse_mass[i];
      if (pinned ? im != 0.0 : im == 0.0) continue;
      double m = pinned ? 1.0 : 1.0 / im;
      vec3 r = vec3_sub(vec3_load(x0 + 3 * i), centre);
      angular =
          vec3_add(angular, vec3_scale(vec3_cross(r, vec3_sub(vec3_load(v + 3 * i), v_centre)), m));
      inertia = mat3_add(inertia, point_inertia(r, m));
    }
    vec3 omega = solve_inertia(inertia, angular);
    if (pinned > 1) {
      /* Can the zone follow all its pinned vertices? */
      double scale = 0.0, misfit = 0.0;
      for (int32_t j = 0; j < end - begin; ++j) {
        const int32_t i = ids[j];
        if (z->inverse_mass[i] != 0.0) continue;
        vec3 vi = vec3_load(v + 3 * i);
        vec3 fit = vec3_add(v_centre, vec3_cross(omega, vec3_sub(vec3_load(x0 + 3 * i), centre)));
        scale = fmax(scale, vec3_norm(vi));
        misfit = fmax(misfit, vec3_norm(vec3_sub(vi, fit)));
      }
      if (misfit > 1e-9 * scale + 1e-300) s->zone_misfit = 1;
    }
    for (int32_t j = 0; j < end - begin; ++j) {
      const int32_t i = ids[j];
      if (z->inverse_mass[i] == 0.0) {
        z->dirty[i] = 1; /* a pinned vertex in a new zone: its pairs are tested again */
        continue;
      }
      vec3 r = vec3_sub(vec3_load(x0 + 3 * i), centre);
      vec3_store(v + 3 * i, vec3_add(v_centre, vec3_cross(omega, r)));
      z->dirty[i] = 1;
    }
  }
  free(start);
  *zone_vertices = members;
  return zones;
}


int32_t piola__impact_zones_apply(piola_collision_surface *s, const piola__contact_list *hits,
                                  const double *x0, double *v, int32_t *zone_vertices) {
  int32_t *parent = s->zone_parent;
  for (int64_t i = 0; i < hits->count; ++i) {
    const piola__contact *c = &hits->items[i];
    for (int k = 0; k < 4; ++k) s->in_zone[c->v[k]] = 1;
    for (int k = 1; k < 4; ++k) piola__union_find_join(parent, c->v[0], c->v[k]);
  }
  const zone_points z = {.n = s->vertex_count, .parent = parent, .order = s->zone_order,
                         .in_zone = s->in_zone, .dirty = s->dirty,
                         .inverse_mass = s->inverse_mass, .x0 = x0, .v = v};
  return rigid_zones(s, &z, zone_vertices);
}

int32_t piola__embedded_zones_apply(piola_collision_surface *s, const piola__contact_list *hits,
                                    int32_t *zone_vertices) {
  int32_t *parent = s->node_zone_parent;
  for (int64_t i = 0; i < hits->count; ++i) {
    const piola__contact *c = &hits->items[i];
    int32_t first = -1;
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < PIOLA_COLLISION_EMBED_NODES; ++j) {
        const int32_t node = s->embed_nodes[PIOLA_COLLISION_EMBED_NODES * c->v[k] + j];
        if (node < 0) continue;
        s->node_in_zone[node] = 1;
        if (first < 0) first = node;
        else piola__union_find_join(parent, first, node);
      }
  }
  memset(s->node_dirty, 0, (size_t)s->node_count);
  const zone_points z = {.n = s->node_count, .parent = parent, .order = s->node_zone_order,
                         .in_zone = s->node_in_zone, .dirty = s->node_dirty,
                         .inverse_mass = s->node_inverse_mass, .x0 = s->node_x0, .v = s->node_v};
  int32_t zones = rigid_zones(s, &z, zone_vertices);
  /* the vertices of every node that moved follow it */
  for (int32_t node = 0; zones >= 0 && node < s->node_count; ++node) {
    if (!s->node_dirty[node]) continue;
    for (int32_t q = s->node_vertex_start[node]; q < s->node_vertex_start[node + 1]; ++q) {
      const int32_t vertex = s->node_vertices[q];
      double *vv = s->vertex_v + 3 * (size_t)vertex;
      vv[0] = vv[1] = vv[2] = 0;
      for (int j = 0; j < PIOLA_COLLISION_EMBED_NODES; ++j) {
        const int32_t m = s->embed_nodes[PIOLA_COLLISION_EMBED_NODES * vertex + j];
        if (m < 0) continue;
        const double w = s->embed_weights[PIOLA_COLLISION_EMBED_NODES * vertex + j];
        for (int k = 0; k < 3; ++k) vv[k] += w * s->node_v[3 * (size_t)m + k];
      }
      s->dirty[vertex] = 1;
    }
  }
  return zones;
}

int piola__embedded_same_zone(piola_collision_surface *s, const piola__contact *c) {
  int32_t root = -1;
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < PIOLA_COLLISION_EMBED_NODES; ++j) {
      const int32_t node = s->embed_nodes[PIOLA_COLLISION_EMBED_NODES * c->v[k] + j];
      if (node < 0) continue;
      if (!s->node_in_zone[node]) return 0;
      const int32_t r = piola__union_find_root(s->node_zone_parent, node);
      if (root >= 0 && r != root) return 0;
      root = r;
    }
  return 1;
}
