/* Scalar referees of the force and damping loops (elastic_referees.h). */
#include "support/elastic_referees.h"

#include <math.h>

#include "common/status_report.h"
#include "math/mat3.h"
#include "piola/diagonalize.h"
#include "piola/material.h"

piola_status piola__elastic_body_update_reference(const piola_elastic_body *body,
                                                  const double *x, double stiffness_scale,
                                                  double *forces, piola_elastic_stats *stats) {
  for (int32_t i = 0; i < 3 * body->vertex_count; ++i) {
    if (!isfinite(x[i]))
      return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "position of vertex %d is not finite", (int)(i / 3));
    forces[i] = 0;
  }
  double energy = 0, min_det = INFINITY;
  int32_t inverted = 0;
  for (int32_t t = 0; t < body->tet_count; ++t) {
    const int32_t *idx = body->tets + 4 * t;
    vec3 x0 = vec3_load(x + 3 * idx[0]);
    mat3 ds = mat3_from_columns(vec3_sub(vec3_load(x + 3 * idx[1]), x0),
                                vec3_sub(vec3_load(x + 3 * idx[2]), x0),
                                vec3_sub(vec3_load(x + 3 * idx[3]), x0));
    mat3 dm_inv;
    for (int k = 0; k < 9; ++k) dm_inv.m[k / 3][k % 3] = body->dm_inv[k][t];
    mat3 f = mat3_mul(ds, dm_inv);
    mat3 u, v;
    vec3 fhat;
    PIOLA_TRY(piola_diagonalize3(&f, &u, &fhat, &v));
    const piola_material *material = &body->materials[body->tet_material[t]];
    double fh[3] = {fhat.x, fhat.y, fhat.z}, ph[3];
    piola_material_stress(material, fh, ph);
    double psi = piola_material_energy_density(material, fh) * stiffness_scale;
    mat3 p = mat3_mul_diag_transpose(u, vec3_scale(vec3_make(ph[0], ph[1], ph[2]), stiffness_scale), v);
    if (body->fiber[0]) { /* fibre part in the diagonal frame, ahat = V^T a (section 6.1) */
      vec3 a = vec3_make(body->fiber[0][t], body->fiber[1][t], body->fiber[2][t]);
      vec3 ah = mat3_mul_vec(mat3_transpose(v), a);
      double ahat[3] = {ah.x, ah.y, ah.z}, pf[3][3];
      piola_material_fiber_stress(material, fh, ahat, body->activation, pf);
      mat3 pfm;
      for (int k = 0; k < 9; ++k) pfm.m[k / 3][k % 3] = pf[k / 3][k % 3] * stiffness_scale;
      p = mat3_add(p, mat3_mul(mat3_mul(u, pfm), mat3_transpose(v)));
      psi += piola_material_fiber_energy_density(material, fh, ahat, body->activation) * stiffness_scale;
    }
    mat3 g = mat3_scale(mat3_mul_transpose_b(p, dm_inv), -body->rest_volume[t]);
    vec3 g0 = vec3_make(0, 0, 0);
    for (int c = 1; c < 4; ++c) {
      vec3 gc = mat3_column(g, c - 1);
      g0 = vec3_sub(g0, gc);
      for (int i = 0; i < 3; ++i) forces[3 * idx[c] + i] += vec3_get(gc, i);
    }
    for (int i = 0; i < 3; ++i) forces[3 * idx[0] + i] += vec3_get(g0, i);
    double det = mat3_det(f);
    energy += body->rest_volume[t] * psi;
    inverted += det < 0;
    min_det = fmin(min_det, det);
  }
  if (stats) {
    stats->elastic_energy = energy;
    stats->inverted_count = inverted;
    stats->min_det_f = min_det;
  }
  return PIOLA_OK;
}

/* Removes from the 4 corner vectors y (12) their rigid-rotation part about the centroid
 * of positions p (12). */
static void reference_remove_rotation(const double p[12], double y[12]) {
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
static void reference_tet_damping(const piola_elastic_body *body, int32_t t, const double vt[12], double beta,
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

void piola__elastic_body_damping_reference(const piola_elastic_body *body, const double *v,
                                           double shear_viscosity, double bulk_viscosity,
                                           double *forces) {
  for (int32_t i = 0; i < 3 * body->vertex_count; ++i) forces[i] = 0.0;
  for (int32_t t = 0; t < body->tet_count; ++t) {
    double pt[12], vt[12], out[12];
    for (int c = 0; c < 4; ++c) {
      int32_t i = body->tet_vertices[c][t];
      for (int k = 0; k < 3; ++k) {
        pt[3 * c + k] = body->positions[3 * i + k];
        vt[3 * c + k] = v[3 * i + k];
      }
    }
    reference_remove_rotation(pt, vt);
    reference_tet_damping(body, t, vt, shear_viscosity, bulk_viscosity, out);
    reference_remove_rotation(pt, out);
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 3; ++k) forces[3 * body->tet_vertices[c][t] + k] += out[3 * c + k];
  }
}
