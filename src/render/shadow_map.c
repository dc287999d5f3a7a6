/* Shadows of the surfaces on the ground, from a shadow map.
 *
 * A "sun" shines from above, tilted towards the key light's side so shadows fall away from
 * the lit side. The surface triangles are rasterized orthographically along the sun
 * direction into a square grid of heights (how far towards the sun the nearest surface
 * is); a ground point is in shadow where the grid holds a surface above it. Four texels are
 * blended, so shadow edges are soft over one texel instead of stair-stepped. Only the
 * ground receives shadows: it is what anchors a solid visually, and it keeps the cost to
 * one rasterization of the triangles into a small grid. */
#include <math.h>
#include <stdlib.h>

#include "render/render_internal.h"

enum { SHADOW_SIZE = 640 }; /* texels per side: soft enough, and cheap next to the ray pass */

vec3 piola__render_sun(const render_camera *cam, vec3 up) {
  vec3 k = cam->key;
  vec3 horizontal = vec3_sub(k, vec3_scale(up, vec3_dot(k, up)));
  double hl = vec3_norm(horizontal);
  vec3 s = hl > 0 ? vec3_add(up, vec3_scale(horizontal, 0.45 / hl)) : up;
  return vec3_scale(s, 1.0 / vec3_norm(s));
}

void piola__render_shadow_free(render_shadow *s) {
  free(s->height);
  s->height = NULL;
  s->size = 0;
}

piola_status piola__render_shadow_build(vec3 sun, const piola_render_mesh *mesh, render_shadow *s) {
  s->size = 0;
  if (!mesh || mesh->triangle_count == 0 || mesh->vertex_count == 0) return PIOLA_OK;
  s->sun = sun;
  vec3 a = fabs(sun.z) < 0.9 ? (vec3){0, 0, 1} : (vec3){1, 0, 0};
  s->u = vec3_cross(sun, a);
  s->u = vec3_scale(s->u, 1.0 / vec3_norm(s->u));
  s->v = vec3_cross(sun, s->u);
  double lo_u = INFINITY, hi_u = -INFINITY, lo_v = INFINITY, hi_v = -INFINITY;
  for (int32_t i = 0; i < mesh->vertex_count; ++i) {
    vec3 p = vec3_load(mesh->positions + 3 * (size_t)i);
    double pu = vec3_dot(p, s->u), pv = vec3_dot(p, s->v);
    lo_u = fmin(lo_u, pu), hi_u = fmax(hi_u, pu), lo_v = fmin(lo_v, pv), hi_v = fmax(hi_v, pv);
  }
  double extent = fmax(hi_u - lo_u, hi_v - lo_v);
  if (!(extent > 0) || !isfinite(extent)) return PIOLA_OK;
  const int n = SHADOW_SIZE;
  s->texel = extent / (n - 4);
  s->u0 = lo_u - 2 * s->texel;
  s->v0 = lo_v - 2 * s->texel;
  float *h = malloc((size_t)n * n * sizeof *h);
  if (!h) return PIOLA_OK; /* no memory for shadows: draw without them */
  for (size_t i = 0; i < (size_t)n * n; ++i) h[i] = -INFINITY;
  const double *x = mesh->positions;
  for (int32_t t = 0; t < mesh->triangle_count; ++t) {
    const int32_t *c = mesh->triangles + 3 * (size_t)t;
    double pu[3], pv[3], ph[3];
    for (int k = 0; k < 3; ++k) {
      vec3 p = vec3_load(x + 3 * (size_t)c[k]);
      pu[k] = (vec3_dot(p, s->u) - s->u0) / s->texel;
      pv[k] = (vec3_dot(p, s->v) - s->v0) / s->texel;
      ph[k] = vec3_dot(p, sun);
    }
    double area = (pu[1] - pu[0]) * (pv[2] - pv[0]) - (pv[1] - pv[0]) * (pu[2] - pu[0]);
    if (!(fabs(area) > 1e-12)) continue;
    int i0 = (int)ceil(fmin(pu[0], fmin(pu[1], pu[2])) - 0.5),
        i1 = (int)floor(fmax(pu[0], fmax(pu[1], pu[2])) - 0.5);
    int j0 = (int)ceil(fmin(pv[0], fmin(pv[1], pv[2])) - 0.5),
        j1 = (int)floor(fmax(pv[0], fmax(pv[1], pv[2])) - 0.5);
    if (i0 < 0) i0 = 0;
    if (j0 < 0) j0 = 0;
    if (i1 > n - 1) i1 = n - 1;
    if (j1 > n - 1) j1 = n - 1;
    /* barycentric weights are affine in (cu, cv): w_k = A_k cu + B_k cv + C_k */
    double inv = 1.0 / area, A[2], B[2], C[2];
    for (int k = 0; k < 2; ++k) {
      int a1 = (k + 1) % 3, a2 = (k + 2) % 3;
      A[k] = (pv[a1] - pv[a2]) * inv;
      B[k] = (pu[a2] - pu[a1]) * inv;
      C[k] = (pu[a1] * pv[a2] - pu[a2] * pv[a1]) * inv;
    }
    for (int j = j0; j <= j1; ++j) {
      double cv = j + 0.5;
      double w0 = A[0] * (i0 + 0.5) + B[0] * cv + C[0], w1 = A[1] * (i0 + 0.5) + B[1] * cv + C[1];
      float *row = h + (size_t)j * n;
      for (int i = i0; i <= i1; ++i, w0 += A[0], w1 += A[1]) {
        double w2 = 1 - w0 - w1;
        if (w0 < 0 || w1 < 0 || w2 < 0) continue;
        float z = (float)(w0 * ph[0] + w1 * ph[1] + w2 * ph[2]);
        if (z > row[i]) row[i] = z;
      }
    }
  }
  s->height = h;
  s->size = n;
  return PIOLA_OK;
}

double piola__render_shadow_at(const render_shadow *s, vec3 p) {
  if (s->size == 0) return 0;
  double fu = (vec3_dot(p, s->u) - s->u0) / s->texel - 0.5,
         fv = (vec3_dot(p, s->v) - s->v0) / s->texel - 0.5;
  if (!(fu >= 0 && fv >= 0 && fu < s->size - 1 && fv < s->size - 1)) return 0;
  int i = (int)fu, j = (int)fv;
  double au = fu - i, av = fv - j;
  double ph =
      vec3_dot(p, s->sun) + 1.5 * s->texel; /* bias: the ground's own texel never shades it */
  const float *h = s->height + (size_t)j * s->size + i;
  double s00 = h[0] > ph, s10 = h[1] > ph, s01 = h[s->size] > ph, s11 = h[s->size + 1] > ph;
  return (1 - av) * ((1 - au) * s00 + au * s10) + av * ((1 - au) * s01 + au * s11);
}
