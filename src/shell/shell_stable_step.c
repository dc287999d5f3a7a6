/* The state-aware step bound of a shell; see shell_stable_step.h for the why. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "force/stable_step_modulus.h"
#include "material/membrane_kernels.h"
#include "shell/shell_body_internal.h"
#include "shell/shell_stable_step.h"

/* The membrane modulus of Fhat = (f0, f1) for the plane-stress material m (Pa). In the frame
 * of the diagonalization a unit rank-one dF = a n^T of the 3x2 F has the diagonal entries
 * d_0, d_1, the in-plane pair (x, y) = (dF_01, dF_10) with d_0 d_1 = x y, and the two
 * out-of-plane entries z_j = dF_2j, their squares summing to 1; dF : C : dF is
 * sum_ij K_ij d_i d_j + the pair block [[a, b], [b, a]] + K_01 [[0, 1], [1, 0]] on (x, y)
 * (as for solids) + sum_j (P_j / f_j) z_j^2 (turning u_j out of the plane), so its largest
 * value over the unit waves is at most max(K_00, K_11, a + |b + K_01|, P_0 / f_0, P_1 / f_1).
 * The quotients' denominators are kept at least the threshold c from zero, as for solids:
 * they are singular where the entries collapse, and the extension's stress stays finite
 * there. */
/* Whether the model's own value and slopes are the stress's at (f0, f1, 1): no entry below
 * the threshold, an extension that adds nothing there, a model without the threshold's rise. */
static int plain_parts(const piola_material *m, double f0, double f1) {
  switch (m->model) {
    case PIOLA_MODEL_ROTATED_LINEAR:
    case PIOLA_MODEL_COROTATED:
    case PIOLA_MODEL_STVK:
    case PIOLA_MODEL_NEOHOOKEAN:
    case PIOLA_MODEL_SPLINE:
      return m->inversion_mode != PIOLA_INVERSION_ENERGY && lane_unclamped(m, f0, f1, 1.0);
    default:
      return 0;
  }
}

static double modulus_at(const piola_material *m, double f0, double f1) {
  double p0, p1, k[3][3];
  if (plain_parts(m, f0, f1)) {
    /* one evaluation of the model's parts: the public derivative and the stress each took
     * as long (a fifth of a cloth's step between them) */
    material_parts parts;
    material_model_parts(m->model, m, KERNEL_EXACT_DIVIDE, f0, f1, 1.0, &parts);
    p0 = parts.p[0], p1 = parts.p[1];
    memcpy(k, parts.k, sizeof k);
  } else {
    membrane_stress_kernel(m, f0, f1, &p0, &p1);
    piola_material_stress_derivative(m, (const double[3]){f0, f1, 1.0}, k);
  }
  const double c = m->threshold;
  double modulus = fmax(k[0][0], k[1][1]);
  modulus = fmax(modulus, step_pair_modulus(KERNEL_EXACT_DIVIDE, c, p0, p1, f0, f1, k[0][0],
                                            k[1][1], 0.5 * (k[0][1] + k[1][0])));
  const double f[2] = {f0, f1}, p[2] = {p0, p1};
  for (int j = 0; j < 2; ++j) {
    const double den = f[j] >= 0.0 ? fmax(f[j], c) : fmin(f[j], -c);
    modulus = fmax(modulus, p[j] / den);
  }
  return modulus;
}

/* The modulus at Fhat and, where an entry is below the threshold c, at least the one at the
 * clamped point (max(f_i, c)): past the threshold the clamp's stress is constant and its
 * slopes vanish, but a step sized by them would not be stable once the entry is back above
 * it (the solids' bound takes the extension's slopes at the threshold likewise). */
static double membrane_modulus(const piola_material *m, double f0, double f1) {
  const double c = m->threshold, k = modulus_at(m, f0, f1);
  if (f0 >= c && f1 >= c) return k;
  return fmax(k, modulus_at(m, fmax(f0, c), fmax(f1, c)));
}

/* 1 / h_t^2 of a triangle: its largest squared shape-function gradient. */
static double inverse_altitude2(const shell_triangle *tri) {
  double g[3][2];
  shell_triangle_gradients(tri, g);
  double most = 0;
  for (int a = 0; a < 3; ++a) most = fmax(most, g[a][0] * g[a][0] + g[a][1] * g[a][1]);
  return most;
}

double piola__shell_body_triangle_altitude(const piola_shell_body *body, int32_t t) {
  return 1.0 / sqrt(inverse_altitude2(&body->triangles[t]));
}

double piola__shell_body_membrane_rate2(const piola_shell_body *body, int32_t *worst) {
  double rate2 = 0;
  int32_t at = -1;
  for (int32_t t = 0; t < body->triangle_count; ++t) {
    const shell_triangle *tri = &body->triangles[t];
    const double r = membrane_modulus(&body->materials[tri->material], tri->fhat[0], tri->fhat[1]) *
                     inverse_altitude2(tri) / body->density;
    if (r > rate2) rate2 = r, at = t;
  }
  if (worst) *worst = at;
  return rate2;
}

double piola__shell_body_bending_rate2(const piola_shell_body *body) {
  const double stiffness = body->bending.stiffness;
  if (!(stiffness > 0) || body->hinge_count == 0) return 0;
  double *omega2 = body->vertex_rate2;
  memset(omega2, 0, sizeof(double) * (size_t)body->vertex_count);
  /* the hinge stiffness D w/2 g g^T summed over hinges, bounded per vertex a by Gershgorin
   * on M^-1/2 K M^-1/2: omega^2 <= max_a sum_h (D w / 2) |g_a| / sqrt(m_a) sum_b |g_b| /
   * sqrt(m_b), with the gradients g of the last update (at rest: the rest bound) */
  for (int32_t h = 0; h < body->hinge_count; ++h) {
    const shell_hinge *hg = &body->hinges[h];
    double norms[4], sum = 0;
    for (int k = 0; k < 4; ++k) {
      const double *g = hg->grad + 3 * k;
      norms[k] =
          sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]) * body->inverse_sqrt_masses[hg->v[k]];
      sum += norms[k];
    }
    for (int k = 0; k < 4; ++k) omega2[hg->v[k]] += 0.5 * stiffness * hg->weight * norms[k] * sum;
  }
  double largest = 0;
  for (int32_t i = 0; i < body->vertex_count; ++i) largest = fmax(largest, omega2[i]);
  return largest;
}
