/* The derivatives of the shell's element forces (see shell_stiffness.h for the why). */
#include <math.h>
#include <string.h>

#include "force/element_stiffness.h"
#include "material/membrane_kernels.h"
#include "shell/shell_body_internal.h"
#include "shell/shell_stiffness.h"

/* The rows g_a of a triangle's effective Dm^-1 (F = sum_a x_a g_a^T), rotated by V:
 * gh_a = V^T g_a. */
static void rotated_gradients(const shell_triangle *tri, double gh[3][2]) {
  const double *r = tri->vrot;
  double g[3][2];
  shell_triangle_gradients(tri, g);
  for (int a = 0; a < 3; ++a)
    for (int j = 0; j < 2; ++j) gh[a][j] = r[j] * g[a][0] + r[2 + j] * g[a][1];
}

/* U completed to a frame: columns u0, u1 (the update's U) and n = u0 x u1. */
static void full_frame(const shell_triangle *tri, double uf[3][3]) {
  const double *u = tri->u;
  for (int i = 0; i < 3; ++i) uf[i][0] = u[2 * i], uf[i][1] = u[2 * i + 1];
  uf[0][2] = u[2] * u[5] - u[4] * u[3];
  uf[1][2] = u[4] * u[1] - u[0] * u[5];
  uf[2][2] = u[0] * u[3] - u[2] * u[1];
}

/* out (9 x 9) = scale * Uf M_ab Uf^T for every corner pair, M_ab from mm(a, b). */
static void rotate_blocks(double uf[3][3], double mm[3][3][3][3], double scale,
                          double out[81]) {
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      double um[3][3];
      for (int i = 0; i < 3; ++i)
        for (int q = 0; q < 3; ++q)
          um[i][q] = uf[i][0] * mm[a][b][0][q] + uf[i][1] * mm[a][b][1][q] + uf[i][2] * mm[a][b][2][q];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          out[9 * (3 * a + i) + 3 * b + j] =
              scale * (um[i][0] * uf[j][0] + um[i][1] * uf[j][1] + um[i][2] * uf[j][2]);
    }
}

void piola__shell_triangle_stiffness(const piola_shell_body *body, int32_t t, int project,
                                     double out[81]) {
  const shell_triangle *tri = &body->triangles[t];
  const piola_material *material = &body->materials[tri->material];
  const double f0 = tri->fhat[0], f1 = tri->fhat[1];
  double p[2];
  membrane_stress_kernel(material, f0, f1, &p[0], &p[1]);
  double k3[3][3];
  piola_material_stress_derivative(material, (const double[3]){f0, f1, 1.0}, k3);
  double k[3][3] = {{k3[0][0], k3[0][1], 0}, {k3[1][0], k3[1][1], 0}, {0, 0, 0}};
  /* the pair (dFhat_01, dFhat_10): a symmetric shear and a rotation in the plane; below
   * the gap a quotient loses its digits and its limit replaces it */
  const double f[2] = {f0, f1};
  const double gap = 1e-6 * fmax(fmax(fabs(f0), fabs(f1)), 1e-3);
  double shear = fabs(f0 - f1) > gap ? (p[0] - p[1]) / (f0 - f1)
                                     : 0.5 * (k[0][0] - k[0][1] + k[1][1] - k[1][0]);
  double twist = fabs(f0 + f1) > gap ? (p[0] + p[1]) / (f0 + f1)
                                     : 0.5 * (k[0][0] + k[0][1] + k[1][0] + k[1][1]);
  /* out of plane: turning u_j towards n changes P by (P_j / f_j) n v_j^T */
  double normal[2];
  for (int j = 0; j < 2; ++j) normal[j] = fabs(f[j]) > gap ? p[j] / f[j] : k[j][j];
  if (project) {
    shear = fmax(shear, 0.0);
    /* the rotation and out-of-plane quotients grow without bound near a reflection or a
     * collapse (the extended stress does not vanish there): capped at the triangle's other
     * stiffnesses, as for solids, where they would only stall Newton */
    const double cap = fmax(shear, fmax(fabs(k[0][0]), fabs(k[1][1])));
    twist = fmin(fmax(twist, 0.0), cap);
    for (int j = 0; j < 2; ++j) normal[j] = fmin(fmax(normal[j], 0.0), cap);
    piola__project_symmetric3(k);
  }
  const double pair_a = 0.5 * (shear + twist), pair_b = 0.5 * (shear - twist);
  double gh[3][2];
  rotated_gradients(tri, gh);
  double mm[3][3][3][3];
  memset(mm, 0, sizeof mm);
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      const double *ga = gh[a], *gb = gh[b];
      double(*m)[3] = mm[a][b];
      m[0][0] = k[0][0] * ga[0] * gb[0] + pair_a * ga[1] * gb[1];
      m[1][1] = k[1][1] * ga[1] * gb[1] + pair_a * ga[0] * gb[0];
      m[0][1] = k[0][1] * ga[0] * gb[1] + pair_b * ga[1] * gb[0];
      m[1][0] = k[1][0] * ga[1] * gb[0] + pair_b * ga[0] * gb[1];
      m[2][2] = normal[0] * ga[0] * gb[0] + normal[1] * ga[1] * gb[1];
    }
  double uf[3][3];
  full_frame(tri, uf);
  rotate_blocks(uf, mm, -tri->volume * body->last_stiffness_scale, out);
}

void piola__shell_triangle_damping(const piola_shell_body *body, int32_t t, double beta,
                                   double alpha, double out[81]) {
  const shell_triangle *tri = &body->triangles[t];
  double gh[3][2];
  rotated_gradients(tri, gh);
  /* Phat = beta (A + A^T) + alpha tr(A) I with A = sum_b (U^T v_b) gh_b^T, and the force on
   * corner a is -V0 U Phat gh_a: N_ab[p][q] = beta (ga . gb) delta_pq + beta ga_q gb_p +
   * alpha ga_p gb_q, in the plane of U only */
  double mm[3][3][3][3];
  memset(mm, 0, sizeof mm);
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      const double *ga = gh[a], *gb = gh[b];
      const double dot = ga[0] * gb[0] + ga[1] * gb[1];
      for (int p = 0; p < 2; ++p)
        for (int q = 0; q < 2; ++q)
          mm[a][b][p][q] = (p == q ? beta * dot : 0.0) + beta * ga[q] * gb[p] + alpha * ga[p] * gb[q];
    }
  double uf[3][3];
  full_frame(tri, uf);
  rotate_blocks(uf, mm, -tri->volume, out);
}

/* out (12 x 12) = -c grad grad^T. */
static void hinge_outer(const shell_hinge *hg, double c, double out[144]) {
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j) out[12 * i + j] = -c * hg->grad[i] * hg->grad[j];
}

void piola__shell_hinge_stiffness(const piola_shell_body *body, int32_t h, double out[144]) {
  const shell_hinge *hg = &body->hinges[h];
  /* Phi''(theta) = cos(theta/2) / 2, negative only past the seam at +-pi */
  const double curvature = fmax(0.5 * cos(0.5 * hg->angle), 0.0);
  hinge_outer(hg, body->last_stiffness_scale * body->bending.stiffness * hg->weight * curvature,
              out);
}

void piola__shell_hinge_damping(const piola_shell_body *body, int32_t h, double out[144]) {
  const shell_hinge *hg = &body->hinges[h];
  hinge_outer(hg, 0.5 * body->bending.damping * hg->weight, out);
}
