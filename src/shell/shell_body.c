/* The shell body object and its force loops: in-plane forces (section 8 of the paper), the
 * BMF03 hinge forces, damping of both, and the deterministic gather. Layout and determinism
 * are explained in shell_body_internal.h, the bending model in bending.c. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "material/membrane_kernels.h"
#include "math/mat3.h"
#include "piola/diagonalize.h"
#include "piola/threads.h"
#include "shell/shell_body_internal.h"
#include "shell/svd3x2.h"

/* Bodies smaller than this many elements run their loops on one thread: waking a team
 * costs more than the work (a 200-triangle cloth step is a few microseconds). */
#define SHELL_PARALLEL_MIN_ELEMENTS 4096

/* A triangle whose signed fhat[1] is below this counts as degenerate in the statistics. */
#define DEGENERATE_FHAT 1e-3

piola_shell_body_def piola_default_shell_body_def(void) {
  piola_shell_body_def def;
  memset(&def, 0, sizeof def);
  def.thickness = 1e-3;
  def.density = 1000.0;
  def.bending.yield_angle = INFINITY;
  def.bending.plastic_rate = INFINITY;
  def.plasticity.yield_strain = INFINITY;
  def.plasticity.rate = INFINITY;
  def.plasticity.max_plastic_stretch = 4.0;
  return def;
}

piola_status piola_shell_body_create(const piola_shell_body_def *def, piola_shell_body **out) {
  if (!out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "shell body out is NULL");
  *out = NULL;
  piola_shell_body *body = calloc(1, sizeof *body);
  if (!body) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "shell body: out of memory");
  piola_status status = piola__shell_body_build(body, def);
  if (status != PIOLA_OK) {
    piola__shell_body_free_arrays(body);
    free(body);
    return status;
  }
  *out = body;
  return PIOLA_OK;
}

void piola_shell_body_destroy(piola_shell_body *body) {
  if (!body) return;
  piola__shell_body_free_arrays(body);
  free(body);
}

int32_t piola_shell_body_vertex_count(const piola_shell_body *body) { return body->vertex_count; }
int32_t piola_shell_body_triangle_count(const piola_shell_body *body) {
  return body->triangle_count;
}
const int32_t *piola_shell_body_triangles(const piola_shell_body *body) {
  return body->triangle_indices;
}
const double *piola_shell_body_rest_positions(const piola_shell_body *body) {
  return body->rest_positions;
}
const double *piola_shell_body_masses(const piola_shell_body *body) { return body->masses; }
double piola_shell_body_min_rest_altitude(const piola_shell_body *body) {
  return body->min_rest_altitude;
}
double piola_shell_body_max_wave_speed(const piola_shell_body *body) {
  return body->max_wave_speed;
}
double piola_shell_body_bending_time_scale(const piola_shell_body *body) {
  return body->bending_time_scale;
}
double piola_shell_body_bending_damping(const piola_shell_body *body) {
  return body->bending.damping;
}
int32_t piola_shell_body_hinge_count(const piola_shell_body *body) { return body->hinge_count; }
const int32_t *piola_shell_body_hinges(const piola_shell_body *body) { return body->hinge_indices; }
const double *piola_shell_body_rest_angles(const piola_shell_body *body) {
  return body->rest_angles;
}
const double *piola_shell_body_angles(const piola_shell_body *body) { return body->angles; }
const double *piola_shell_body_fhat(const piola_shell_body *body) { return body->fhat; }
const double *piola_shell_body_fp_inverse(const piola_shell_body *body) { return body->fp_inv; }

piola_status piola_shell_body_set_rest_angles(piola_shell_body *body, const double *angles) {
  if (!body || !angles)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "set_rest_angles: NULL argument");
  for (int32_t h = 0; h < body->hinge_count; ++h)
    if (!(fabs(angles[h]) <= M_PI))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "rest angle of hinge %d must be in [-pi, pi] rad, got %g", (int)h,
                        angles[h]);
  for (int32_t h = 0; h < body->hinge_count; ++h)
    body->hinges[h].rest_angle = body->rest_angles[h] = angles[h];
  return PIOLA_OK;
}

piola_status piola_shell_body_set_reference_normals(piola_shell_body *body, const double *normals) {
  if (!body || !normals)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "set_reference_normals: NULL argument");
  for (int32_t i = 0; i < 3 * body->triangle_count; ++i)
    if (!isfinite(normals[i]))
      return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "reference normal of triangle %d is not finite",
                        (int)(i / 3));
  for (int32_t t = 0; t < body->triangle_count; ++t)
    memcpy(body->triangles[t].reference, normals + 3 * t, 3 * sizeof(double));
  return PIOLA_OK;
}

void piola__shell_body_gather(const piola_shell_body *body, double *forces) {
  const int32_t *ts = body->tri_start, *ti = body->tri_incidence;
  const int32_t *hs = body->hinge_start, *hi = body->hinge_incidence;
  const double *tf = body->triangle_forces, *hf = body->hinge_forces;
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) \
    if (body->vertex_count > SHELL_PARALLEL_MIN_ELEMENTS)
  for (int32_t i = 0; i < body->vertex_count; ++i) {
    double fx = 0, fy = 0, fz = 0;
    for (int32_t e = ts[i]; e < ts[i + 1]; ++e) {
      const double *g = tf + 3 * (size_t)ti[e]; /* 9 t + 3 corner = 3 (3 t + corner) */
      fx += g[0];
      fy += g[1];
      fz += g[2];
    }
    for (int32_t e = hs[i]; e < hs[i + 1]; ++e) {
      const double *g = hf + 3 * (size_t)hi[e]; /* 12 h + 3 slot = 3 (4 h + slot) */
      fx += g[0];
      fy += g[1];
      fz += g[2];
    }
    forces[3 * i] = fx;
    forces[3 * i + 1] = fy;
    forces[3 * i + 2] = fz;
  }
}

/* Nodal forces of a triangle from its 3x2 stress P: G = -V0 P Dm_eff^-T; columns are the
 * forces on corners 1 and 2, corner 0 gets minus their sum. */
static void triangle_nodal_forces(const shell_triangle *tri, double p[3][2], double *out) {
  const double *d = tri->dm_inv_eff;
  for (int i = 0; i < 3; ++i) {
    double g1 = -tri->volume * (p[i][0] * d[0] + p[i][1] * d[1]);
    double g2 = -tri->volume * (p[i][0] * d[2] + p[i][1] * d[3]);
    out[i] = -(g1 + g2);
    out[3 + i] = g1;
    out[6 + i] = g2;
  }
}

static void update_triangle(piola_shell_body *body, const double *x, double scale, int want_energy,
                            int32_t t) {
  shell_triangle *tri = &body->triangles[t];
  const double *x0 = x + 3 * tri->v[0], *x1 = x + 3 * tri->v[1], *x2 = x + 3 * tri->v[2];
  double e1[3] = {x1[0] - x0[0], x1[1] - x0[1], x1[2] - x0[2]};
  double e2[3] = {x2[0] - x0[0], x2[1] - x0[1], x2[2] - x0[2]};
  const double *d = tri->dm_inv_eff;
  double f[3][2];
  for (int i = 0; i < 3; ++i) {
    f[i][0] = e1[i] * d[0] + e2[i] * d[2];
    f[i][1] = e1[i] * d[1] + e2[i] * d[3];
  }
  double u[6], v[4], fhat[2];
  /* positions were checked finite, so this fails only if F overflows the double range */
  if (piola__svd3x2(f, u, fhat, v)) {
    static const double u_identity[6] = {1, 0, 0, 1, 0, 0}, v_identity[4] = {1, 0, 0, 1};
    memcpy(u, u_identity, sizeof u);
    memcpy(v, v_identity, sizeof v);
    fhat[0] = fhat[1] = 0;
  }
  if (body->use_reference_normals) {
    /* the triangle normal against the reference: opposed means inverted, read as "as
     * little inverted as possible", i.e. the smaller entry negative (U's column flipped so
     * that U Fhat V^T is still F) */
    double n0 = e1[1] * e2[2] - e1[2] * e2[1], n1 = e1[2] * e2[0] - e1[0] * e2[2],
           n2 = e1[0] * e2[1] - e1[1] * e2[0];
    if (n0 * tri->reference[0] + n1 * tri->reference[1] + n2 * tri->reference[2] < 0) {
      fhat[1] = -fhat[1];
      for (int i = 0; i < 3; ++i) u[2 * i + 1] = -u[2 * i + 1];
    }
  }
  /* the energy only when statistics ask for it: stepping needs forces */
  double p0, p1, psi = 0;
  if (want_energy)
    membrane_stress_energy_kernel(&body->materials[tri->material], fhat[0], fhat[1], &p0, &p1, &psi);
  else
    membrane_stress_kernel(&body->materials[tri->material], fhat[0], fhat[1], &p0, &p1);
  p0 *= scale;
  p1 *= scale;
  double p[3][2];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) p[i][j] = u[2 * i] * p0 * v[2 * j] + u[2 * i + 1] * p1 * v[2 * j + 1];
  triangle_nodal_forces(tri, p, body->triangle_forces + 9 * (size_t)t);
  memcpy(tri->u, u, sizeof u);
  memcpy(tri->vrot, v, sizeof v);
  tri->fhat[0] = body->fhat[2 * t] = fhat[0];
  tri->fhat[1] = body->fhat[2 * t + 1] = fhat[1];
  tri->energy_density = psi * scale;
}

static void update_hinge(piola_shell_body *body, const double *x, double stiffness, int32_t h) {
  shell_hinge *hg = &body->hinges[h];
  double theta = piola__hinge_angle(x + 3 * hg->v[0], x + 3 * hg->v[1], x + 3 * hg->v[2],
                                   x + 3 * hg->v[3], hg->grad);
  /* the branch of the angle nearest the rest angle: a hinge whose rest angle is near +-pi
   * (folded, e.g. by plastic bending) then bends smoothly through the seam instead of
   * seeing sin(theta/2) flip sign there */
  if (theta - hg->rest_angle > M_PI) theta -= 2.0 * M_PI;
  if (theta - hg->rest_angle < -M_PI) theta += 2.0 * M_PI;
  hg->angle = theta;
  body->angles[h] = hg->angle;
  double slope;
  piola__bending_potential(hg->angle, hg->rest_angle, &slope);
  double k = -stiffness * hg->weight * slope;
  double *out = body->hinge_forces + 12 * (size_t)h;
  for (int i = 0; i < 12; ++i) out[i] = k * hg->grad[i];
}

piola_status piola_shell_body_update(piola_shell_body *body, const double *x,
                                     double stiffness_scale, double *forces,
                                     piola_shell_stats *stats) {
  if (!body || !x || !forces)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "shell body update: NULL argument");
  if (!(stiffness_scale >= 0) || !isfinite(stiffness_scale))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "stiffness_scale must be >= 0, got %g",
                      stiffness_scale);
  for (int32_t i = 0; i < 3 * body->vertex_count; ++i)
    if (!isfinite(x[i]))
      return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "position of shell vertex %d is not finite",
                        (int)(i / 3));
  const int threads = piola_thread_count();
#pragma omp parallel num_threads(threads) if (body->triangle_count > SHELL_PARALLEL_MIN_ELEMENTS)
  {
#pragma omp for schedule(static) nowait
    for (int32_t t = 0; t < body->triangle_count; ++t)
      update_triangle(body, x, stiffness_scale, stats != NULL, t);
    const double stiffness = stiffness_scale * body->bending.stiffness;
    /* without stiffness, damping or plastic bending the hinges have nothing to do */
    const int32_t hinges = body->bending.stiffness > 0 || body->bending.damping > 0 ||
                                   isfinite(body->bending.yield_angle)
                               ? body->hinge_count
                               : 0;
#pragma omp for schedule(static)
    for (int32_t h = 0; h < hinges; ++h) update_hinge(body, x, stiffness, h);
  }
  piola__shell_body_gather(body, forces);
  body->last_stiffness_scale = stiffness_scale;
  if (stats) {
    double membrane = 0, bending = 0, min_fhat = INFINITY;
    int32_t inverted = 0, degenerate = 0;
    for (int32_t t = 0; t < body->triangle_count; ++t) {
      const shell_triangle *tri = &body->triangles[t];
      membrane += tri->volume * tri->energy_density;
      inverted += tri->fhat[1] < 0;
      degenerate += tri->fhat[1] < DEGENERATE_FHAT;
      min_fhat = fmin(min_fhat, tri->fhat[1]);
    }
    const double stiffness = stiffness_scale * body->bending.stiffness;
    for (int32_t h = 0; h < body->hinge_count; ++h) {
      const shell_hinge *hg = &body->hinges[h];
      bending += stiffness * hg->weight * piola__bending_potential(hg->angle, hg->rest_angle, NULL);
    }
    stats->membrane_energy = membrane;
    stats->bending_energy = bending;
    stats->inverted_count = inverted;
    stats->degenerate_count = degenerate;
    stats->min_fhat = min_fhat;
  }
  return PIOLA_OK;
}

/* ------------------------------------------------------------------ damping */

static void damp_triangle(piola_shell_body *body, const double *vel, double beta, double alpha,
                          int32_t t) {
  const shell_triangle *tri = &body->triangles[t];
  const double *v0 = vel + 3 * tri->v[0], *v1 = vel + 3 * tri->v[1], *v2 = vel + 3 * tri->v[2];
  const double *d = tri->dm_inv_eff, *u = tri->u, *r = tri->vrot;
  double fd[3][2];
  for (int i = 0; i < 3; ++i) {
    double a = v1[i] - v0[i], b = v2[i] - v0[i];
    fd[i][0] = a * d[0] + b * d[2];
    fd[i][1] = a * d[1] + b * d[3];
  }
  /* A = U^T Fdot V (2x2) */
  double fv[3][2], a[2][2];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) fv[i][j] = fd[i][0] * r[j] + fd[i][1] * r[2 + j];
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) a[i][j] = u[i] * fv[0][j] + u[2 + i] * fv[1][j] + u[4 + i] * fv[2][j];
  double tr = alpha * (a[0][0] + a[1][1]);
  double ph[2][2];
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) ph[i][j] = beta * (a[i][j] + a[j][i]) + (i == j ? tr : 0.0);
  /* P = U Phat V^T */
  double up[3][2], p[3][2];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) up[i][j] = u[2 * i] * ph[0][j] + u[2 * i + 1] * ph[1][j];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) p[i][j] = up[i][0] * r[2 * j] + up[i][1] * r[2 * j + 1];
  triangle_nodal_forces(tri, p, body->triangle_forces + 9 * (size_t)t);
}

static void damp_hinge(piola_shell_body *body, const double *vel, double viscosity, int32_t h) {
  const shell_hinge *hg = &body->hinges[h];
  double rate = 0;
  for (int k = 0; k < 4; ++k) {
    const double *vk = vel + 3 * hg->v[k];
    rate += hg->grad[3 * k] * vk[0] + hg->grad[3 * k + 1] * vk[1] + hg->grad[3 * k + 2] * vk[2];
  }
  double c = -0.5 * viscosity * hg->weight * rate;
  double *out = body->hinge_forces + 12 * (size_t)h;
  for (int i = 0; i < 12; ++i) out[i] = c * hg->grad[i];
}

void piola_shell_body_damping_forces(const piola_shell_body *body, const double *v,
                                     double shear_viscosity, double bulk_viscosity,
                                     double *forces) {
  if (!body || !v || !forces) return;
  /* the per-element buffers are scratch shared with the update: one call at a time per body */
  piola_shell_body *b = (piola_shell_body *)body;
  const double eta = body->bending.damping;
#pragma omp parallel num_threads(piola_thread_count()) \
    if (body->triangle_count > SHELL_PARALLEL_MIN_ELEMENTS)
  {
#pragma omp for schedule(static) nowait
    for (int32_t t = 0; t < body->triangle_count; ++t)
      damp_triangle(b, v, shear_viscosity, bulk_viscosity, t);
#pragma omp for schedule(static)
    for (int32_t h = 0; h < body->hinge_count; ++h) damp_hinge(b, v, eta, h);
  }
  piola__shell_body_gather(body, forces);
}
