/* Damping forces (paper section 6.2): the robust variant, made to conserve angular momentum.
 *
 * The velocity gradient Fdot = Ds_dot Dm^-1 is rotated into the frame of the last update's
 * diagonalization, Fdot_hat = U^T Fdot V; the damping stress there is the rotated-linear
 * analogue Phat = beta (Fdot_hat + Fdot_hat^T) + alpha tr(Fdot_hat) I, rotated back,
 * P = U Phat V^T, and turned into nodal forces exactly as the elastic stress is. It never
 * divides by Fhat, so it does not vanish (or blow up) on flat, collapsed or inverted tets,
 * which is what keeps those from oscillating.
 *
 * Angular momentum. As the paper notes, this stress has a torque unless Phat Fhat is
 * symmetric, which fails for deformed tets; recovering from a collapse (all tets flat) that
 * torque spins the whole body up, and nothing damps a rigid spin afterwards. So each tet's
 * damping map D_t (12 velocities -> 12 forces) is sandwiched between the projection that
 * removes the tet's infinitesimal rigid rotations about its centroid at the current
 * positions: D'_t = P_t D_t P_t, P_t = I - R (R^T R + eps I)^-1 R^T, R the 12x3 matrix of
 * rotation generators (e_k x r_a), r_a = x_a - centroid. Then:
 *   - the net torque of each tet's forces is zero (R^T P f = 0), and their sum is zero;
 *   - rigid rotations are not damped at any deformation, not only at rest;
 *   - compression and shear rates of flat and inverted tets still are (P only removes the
 *     3 rotation directions of the 12);
 *   - D'_t is symmetric negative semi-definite because D_t is and P_t is symmetric, and
 *     linear in v: with A = Fdot_hat(P v), B = Fdot_hat(P w),
 *     w . f(v) = -sum V0 [beta/2 (A + A^T):(B + B^T) + alpha tr A tr B].
 *     So the implicit step's M - dt/2 D is symmetric positive definite and CG applies.
 * eps = 1e-12 tr(R^T R) regularizes tets collapsed to a line or a point, whose R^T R is
 * singular (for a point R = 0 and P = I: all corners coincide, so there is no torque). */
#include <math.h>

#include "force/elastic_body_internal.h"
#include "force/svd_kernel.h"

#define B PIOLA_TET_BLOCK

/* Removes from the 4 corner vectors y (12) their rigid-rotation part about the centroid
 * of positions p (12). */
static void remove_rotation(const double p[12], double y[12]) {
  double c[3] = {0, 0, 0};
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) c[i] += 0.25 * p[3 * a + i];
  double r[4][3], m[3][3] = {{0}}, tau[3] = {0, 0, 0};
  for (int a = 0; a < 4; ++a) {
    for (int i = 0; i < 3; ++i) r[a][i] = p[3 * a + i] - c[i];
    double rr = r[a][0] * r[a][0] + r[a][1] * r[a][1] + r[a][2] * r[a][2];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) m[i][j] += (i == j ? rr : 0.0) - r[a][i] * r[a][j];
    const double *ya = y + 3 * a;
    tau[0] += r[a][1] * ya[2] - r[a][2] * ya[1];
    tau[1] += r[a][2] * ya[0] - r[a][0] * ya[2];
    tau[2] += r[a][0] * ya[1] - r[a][1] * ya[0];
  }
  double eps = 1e-12 * (m[0][0] + m[1][1] + m[2][2]);
  if (!(eps > 0)) return; /* all corners at one point: no rotation to remove */
  for (int i = 0; i < 3; ++i) m[i][i] += eps;
  double cof[3][3] = {
      {m[1][1] * m[2][2] - m[1][2] * m[2][1], m[1][2] * m[2][0] - m[1][0] * m[2][2], m[1][0] * m[2][1] - m[1][1] * m[2][0]},
      {m[0][2] * m[2][1] - m[0][1] * m[2][2], m[0][0] * m[2][2] - m[0][2] * m[2][0], m[0][1] * m[2][0] - m[0][0] * m[2][1]},
      {m[0][1] * m[1][2] - m[0][2] * m[1][1], m[0][2] * m[1][0] - m[0][0] * m[1][2], m[0][0] * m[1][1] - m[0][1] * m[1][0]}};
  double det = m[0][0] * cof[0][0] + m[0][1] * cof[0][1] + m[0][2] * cof[0][2];
  /* omega = (R^T R + eps)^-1 R^T y; m is symmetric so its inverse is cof / det */
  double omega[3];
  for (int i = 0; i < 3; ++i) omega[i] = (cof[i][0] * tau[0] + cof[i][1] * tau[1] + cof[i][2] * tau[2]) / det;
  for (int a = 0; a < 4; ++a) {
    y[3 * a] -= omega[1] * r[a][2] - omega[2] * r[a][1];
    y[3 * a + 1] -= omega[2] * r[a][0] - omega[0] * r[a][2];
    y[3 * a + 2] -= omega[0] * r[a][1] - omega[1] * r[a][0];
  }
}

/* The damping forces of tet t at corner velocities vt (12, already projected). */
static void tet_damping(const piola_elastic_body *body, int32_t t, const double vt[12], double beta,
                        double alpha, double out[12]) {
  double *const *dmi = body->dm_inv;
  double d[3][3], fd[3][3], fv[3][3], a[3][3], ph[3][3], p[3][3], u[3][3], v[3][3], dm[3][3];
  for (int k = 0; k < 9; ++k) {
    u[k / 3][k % 3] = body->u[k][t];
    v[k / 3][k % 3] = body->v[k][t];
    dm[k / 3][k % 3] = dmi[k][t];
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) d[i][j] = vt[3 * (j + 1) + i] - vt[i];
  /* Fdot = Ds_dot Dm^-1 */
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) fd[i][j] = d[i][0] * dm[0][j] + d[i][1] * dm[1][j] + d[i][2] * dm[2][j];
  /* Fdot_hat = U^T Fdot V */
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) fv[i][j] = fd[i][0] * v[0][j] + fd[i][1] * v[1][j] + fd[i][2] * v[2][j];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) a[i][j] = u[0][i] * fv[0][j] + u[1][i] * fv[1][j] + u[2][i] * fv[2][j];
  double tr = alpha * (a[0][0] + a[1][1] + a[2][2]);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) ph[i][j] = beta * (a[i][j] + a[j][i]) + (i == j ? tr : 0.0);
  /* P = U Phat V^T */
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) fv[i][j] = u[i][0] * ph[0][j] + u[i][1] * ph[1][j] + u[i][2] * ph[2][j];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) p[i][j] = fv[i][0] * v[j][0] + fv[i][1] * v[j][1] + fv[i][2] * v[j][2];
  /* G = -V0 P Dm^-T: column j is the force on corner j + 1 */
  double w = -body->rest_volume[t];
  for (int i = 0; i < 3; ++i) out[i] = 0.0;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      double g = w * (p[i][0] * dm[j][0] + p[i][1] * dm[j][1] + p[i][2] * dm[j][2]);
      out[3 * (j + 1) + i] = g;
      out[i] -= g;
    }
}

/* Writes tet t's 12 force components into the blocked per-tet buffer. */
static void store_tet_forces(const piola_elastic_body *body, int32_t t, const double out[12]) {
  for (int c = 0; c < 4; ++c) {
    double *o = body->tet_forces + piola__tet_force_offset(t, c);
    for (int i = 0; i < 3; ++i) o[i * B] = out[3 * c + i];
  }
}

static void damping_block(const piola_elastic_body *body, const double *vel, double beta,
                          double alpha, int32_t block) {
  const int32_t base = block * B;
  for (int l = 0; l < B; ++l) {
    const int32_t t = base + l;
    double out[12] = {0};
    if (t >= body->tet_count) {
      store_tet_forces(body, t, out);
      continue;
    }
    double pt[12], vt[12];
    for (int c = 0; c < 4; ++c) {
      int32_t i = body->tet_vertices[c][t];
      for (int k = 0; k < 3; ++k) {
        pt[3 * c + k] = body->positions[3 * i + k];
        vt[3 * c + k] = vel[3 * i + k];
      }
    }
    remove_rotation(pt, vt);
    tet_damping(body, t, vt, beta, alpha, out);
    remove_rotation(pt, out);
    store_tet_forces(body, t, out);
  }
}

void piola_elastic_body_damping_forces(const piola_elastic_body *body, const double *v,
                                       double shear_viscosity, double bulk_viscosity,
                                       double *forces) {
  if (!body || !v || !forces) return;
  int32_t blocks = body->padded_tet_count / B;
  /* the per-tet buffer is scratch shared with the elastic update: concurrent calls on one
   * body are not allowed */
#pragma omp parallel for schedule(static) num_threads(piola__thread_count()) \
    if (blocks >= PIOLA_PARALLEL_MIN_BLOCKS)
  for (int32_t b = 0; b < blocks; ++b)
    damping_block(body, v, shear_viscosity, bulk_viscosity, b);
  piola__elastic_body_gather_forces(body, forces);
}
