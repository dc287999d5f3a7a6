/* Plasticity of shells: in-plane (a 2x2 Fp per triangle) and bending (the rest angle of each
 * hinge), both from the state of the last update.
 *
 * In plane (paper section 6.3, kept simple): F = Fe Fp with the trial Fe = F Fp^-1 =
 * U Fhat V^T from the last update. Each principal log-stretch e_i = ln fhat_i beyond the
 * yield strain Y moves toward the yield surface by the fraction a = 1 - exp(-rate dt) of
 * its excess: e_i' = e_i - a (e_i - sign(e_i) Y). With Fhat' = exp(e'), the new plastic part
 * keeps F unchanged: Fp' = V Fhat'^-1 Fhat V^T Fp, i.e. Fp'^-1 = Fp^-1 V (Fhat'/Fhat) V^T.
 * Fp stays well conditioned: if a singular value of Fp' would leave [1/max, max], the flow
 * fraction is halved (up to 8 times) and otherwise the triangle does not flow this step.
 * Collapsed and inverted triangles (fhat_1 below the material's inversion threshold) do not
 * flow: their Fhat says nothing reliable about a plastic stretch, which is what keeps Fp from
 * ever inverting.
 *
 * Bending: when |theta - theta0| exceeds the yield angle, theta0 moves toward theta by the
 * fraction a of the excess, so a dent bent past yield keeps part of its shape (paper
 * Figure 8). Degenerate hinges (zero gradient) do not flow. */
#include <math.h>
#include <string.h>

#include "piola/threads.h"
#include "shell/shell_body_internal.h"

static double flow_fraction(double rate, double dt) {
  return isinf(rate) ? 1.0 : 1.0 - exp(-rate * dt);
}

/* Singular values of a 2x2 matrix m (row-major): largest in s[0]. */
static void singular_values2(const double m[4], double s[2]) {
  double a = m[0] * m[0] + m[2] * m[2], b = m[0] * m[1] + m[2] * m[3], c = m[1] * m[1] + m[3] * m[3];
  double mean = 0.5 * (a + c), diff = sqrt(0.25 * (a - c) * (a - c) + b * b);
  s[0] = sqrt(mean + diff);
  s[1] = sqrt(fmax(0.0, mean - diff));
}

/* Fp'^-1 = Fp^-1 V diag(ratio) V^T. */
static void flowed_fp_inv(const double fp_inv[4], const double v[4], const double ratio[2],
                          double out[4]) {
  double s[4]; /* V diag(ratio) V^T, symmetric */
  s[0] = v[0] * v[0] * ratio[0] + v[1] * v[1] * ratio[1];
  s[1] = v[0] * v[2] * ratio[0] + v[1] * v[3] * ratio[1];
  s[2] = s[1];
  s[3] = v[2] * v[2] * ratio[0] + v[3] * v[3] * ratio[1];
  out[0] = fp_inv[0] * s[0] + fp_inv[1] * s[2];
  out[1] = fp_inv[0] * s[1] + fp_inv[1] * s[3];
  out[2] = fp_inv[2] * s[0] + fp_inv[3] * s[2];
  out[3] = fp_inv[2] * s[1] + fp_inv[3] * s[3];
}

static int flow_triangle(piola_shell_body *body, int32_t t, double fraction) {
  shell_triangle *tri = &body->triangles[t];
  const double yield = body->plasticity.yield_strain;
  if (!(tri->fhat[1] > body->materials[tri->material].threshold)) return 0;
  double e[2] = {log(tri->fhat[0]), log(tri->fhat[1])};
  if (!(fabs(e[0]) > yield) && !(fabs(e[1]) > yield)) return 0;
  const double limit = body->plasticity.max_plastic_stretch;
  for (int attempt = 0; attempt < 9; ++attempt, fraction *= 0.5) {
    double ratio[2];
    for (int i = 0; i < 2; ++i) {
      double excess = fabs(e[i]) > yield ? e[i] - copysign(yield, e[i]) : 0.0;
      ratio[i] = exp(-fraction * excess); /* fhat_i' / fhat_i */
    }
    double candidate[4], s[2];
    flowed_fp_inv(tri->fp_inv, tri->vrot, ratio, candidate);
    singular_values2(candidate, s);
    /* singular values of Fp^-1 are the reciprocals of those of Fp */
    if (s[0] <= limit && s[1] >= 1.0 / limit) {
      memcpy(tri->fp_inv, candidate, sizeof candidate);
      const double *d = tri->dm_inv, *p = tri->fp_inv;
      tri->dm_inv_eff[0] = d[0] * p[0] + d[1] * p[2];
      tri->dm_inv_eff[1] = d[0] * p[1] + d[1] * p[3];
      tri->dm_inv_eff[2] = d[2] * p[0] + d[3] * p[2];
      tri->dm_inv_eff[3] = d[2] * p[1] + d[3] * p[3];
      memcpy(body->fp_inv + 4 * (size_t)t, candidate, sizeof candidate);
      return 1;
    }
  }
  return 0;
}

static int flow_hinge(piola_shell_body *body, int32_t h, double fraction) {
  shell_hinge *hg = &body->hinges[h];
  double g2 = 0;
  for (int i = 0; i < 12; ++i) g2 += hg->grad[i] * hg->grad[i];
  if (!(g2 > 0)) return 0;
  double diff = hg->angle - hg->rest_angle;
  double excess = fabs(diff) - body->bending.yield_angle;
  if (!(excess > 0)) return 0;
  double theta0 = hg->rest_angle + fraction * copysign(excess, diff);
  hg->rest_angle = body->rest_angles[h] = fmax(-M_PI, fmin(M_PI, theta0));
  return 1;
}

int32_t piola_shell_body_plastic_flow(piola_shell_body *body, double dt) {
  if (!body || !(dt > 0) || !isfinite(dt)) return 0;
  int32_t flowed = 0;
  if (isfinite(body->plasticity.yield_strain)) {
    const double fraction = flow_fraction(body->plasticity.rate, dt);
#pragma omp parallel for schedule(static) reduction(+ : flowed) \
    num_threads(piola_thread_count()) if (body->triangle_count > 4096)
    for (int32_t t = 0; t < body->triangle_count; ++t) flowed += flow_triangle(body, t, fraction);
  }
  if (isfinite(body->bending.yield_angle)) {
    const double fraction = flow_fraction(body->bending.plastic_rate, dt);
#pragma omp parallel for schedule(static) reduction(+ : flowed) \
    num_threads(piola_thread_count()) if (body->hinge_count > 4096)
    for (int32_t h = 0; h < body->hinge_count; ++h) flowed += flow_hinge(body, h, fraction);
  }
  return flowed;
}
