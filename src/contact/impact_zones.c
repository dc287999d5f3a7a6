/* Rigid impact zones (Provot 1997, BFA02 section 7.3): the fail-safe of collision processing. */
#include <stdlib.h>

#include "common/union_find.h"
#include "contact/contact_internal.h"

/* Solves m w = b for the symmetric positive semi-definite inertia-like matrix m; when it is
 * (nearly) singular (a zone whose points are collinear) a small multiple of the trace is added
 * so that the rotation about the degenerate axis, which moves nothing, is taken as zero. */
static vec3 solve_inertia(mat3 m, vec3 b) {
  double tr = mat3_trace(m);
  if (!(tr > 0.0)) return (vec3){0, 0, 0};
  double det = mat3_det(m);
  if (!(fabs(det) > 1e-12 * tr * tr * tr)) {
    for (int k = 0; k < 3; ++k) m.m[k][k] += 1e-9 * tr;
    det = mat3_det(m);
    if (!(fabs(det) > 0.0)) return (vec3){0, 0, 0};
  }
  return mat3_mul_vec(mat3_inverse(m), b);
}

static mat3 point_inertia(vec3 r, double m) {
  double r2 = vec3_norm2(r);
  mat3 out;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      out.m[i][j] = m * ((i == j ? r2 : 0.0) - vec3_get(r, i) * vec3_get(r, j));
  return out;
}

int32_t piola__impact_zones_apply(piola_collision_surface *s, const piola__contact_list *hits,
                                  const double *x0, double *v, int32_t *zone_vertices) {
  int32_t *parent = s->zone_parent;
  for (int64_t i = 0; i < hits->count; ++i) {
    const piola__contact *c = &hits->items[i];
    for (int k = 0; k < 4; ++k) s->in_zone[c->v[k]] = 1;
    for (int k = 1; k < 4; ++k) piola__union_find_join(parent, c->v[0], c->v[k]);
  }
  /* Group zone vertices by root with a counting sort (zone_order), roots ascending. */
  const int32_t n = s->vertex_count;
  int32_t *start = calloc((size_t)n + 1, sizeof(int32_t));
  if (!start) return -1;
  int32_t members = 0;
  for (int32_t i = 0; i < n; ++i)
    if (s->in_zone[i]) ++start[piola__union_find_root(parent, i) + 1], ++members;
  for (int32_t i = 0; i < n; ++i) start[i + 1] += start[i];
  int32_t *fill = malloc(sizeof(int32_t) * ((size_t)n + 1));
  if (!fill) {
    free(start);
    return -1;
  }
  for (int32_t i = 0; i <= n; ++i) fill[i] = start[i];
  for (int32_t i = 0; i < n; ++i)
    if (s->in_zone[i]) s->zone_order[fill[piola__union_find_root(parent, i)]++] = i;
  free(fill);

  int32_t zones = 0;
  for (int32_t root = 0; root < n; ++root) {
    const int32_t begin = start[root], end = start[root + 1];
    if (begin == end) continue;
    ++zones;
    const int32_t *ids = s->zone_order + begin;
    /* Pinned vertices, if any, decide the motion: the rigid field that fits their velocities
     * best (equal weights); otherwise momentum does: v_cm and w from L = I w. */
    int pinned = 0;
    for (int32_t j = 0; j < end - begin; ++j) pinned += s->inverse_mass[ids[j]] == 0.0;
    double total = 0.0;
    vec3 centre = {0, 0, 0}, momentum = {0, 0, 0};
    for (int32_t j = 0; j < end - begin; ++j) {
      const int32_t i = ids[j];
      const double im = s->inverse_mass[i];
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
      const double im = s->inverse_mass[i];
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
        if (s->inverse_mass[i] != 0.0) continue;
        vec3 vi = vec3_load(v + 3 * i);
        vec3 fit = vec3_add(v_centre, vec3_cross(omega, vec3_sub(vec3_load(x0 + 3 * i), centre)));
        scale = fmax(scale, vec3_norm(vi));
        misfit = fmax(misfit, vec3_norm(vec3_sub(vi, fit)));
      }
      if (misfit > 1e-9 * scale + 1e-300) s->zone_misfit = 1;
    }
    for (int32_t j = 0; j < end - begin; ++j) {
      const int32_t i = ids[j];
      if (s->inverse_mass[i] == 0.0) {
        s->dirty[i] = 1; /* a pinned vertex in a new zone: its pairs are tested again */
        continue;
      }
      vec3 r = vec3_sub(vec3_load(x0 + 3 * i), centre);
      vec3_store(v + 3 * i, vec3_add(v_centre, vec3_cross(omega, r)));
      s->dirty[i] = 1;
    }
  }
  free(start);
  *zone_vertices = members;
  return zones;
}
