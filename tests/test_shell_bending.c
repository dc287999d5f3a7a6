/* BMF03 bending: the angle and its gradient, forces against the bending energy by finite
 * differences, zero force flat and under rigid motion, invariants, the plate calibration,
 * bending damping and plastic bending. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shell/shell_body_internal.h"
#include "test_shell_fixtures.h"

/* A sheet with bending only (in-plane stiffness negligible next to bending). */
static piola_shell_body *bending_body(const piola_tri_mesh *mesh, double stiffness) {
  piola_material material = shell_material(PIOLA_MODEL_COROTATED, 1e-6);
  return shell_body_from(mesh, &material, stiffness);
}

static double bending_energy(piola_shell_body *body, const double *x) {
  int32_t n = piola_shell_body_vertex_count(body);
  double *f = malloc(sizeof(double) * 3 * (size_t)n);
  piola_shell_stats stats;
  assert_int_equal(piola_shell_body_update(body, x, 1.0, f, &stats), PIOLA_OK);
  free(f);
  return stats.bending_energy;
}

/* Bends a flat sheet (z = 0) into a cylinder of radius r around the y axis, plus noise. */
static void bend(const piola_tri_mesh *mesh, double radius, test_rng *rng, double noise,
                 double *x) {
  for (int i = 0; i < mesh->vertex_count; ++i) {
    const double *p = mesh->positions + 3 * i;
    double a = p[0] / radius;
    x[3 * i] = radius * sin(a);
    x[3 * i + 1] = p[1];
    x[3 * i + 2] = radius * (1 - cos(a));
    for (int k = 0; k < 3; ++k) x[3 * i + k] += noise * (rng ? test_rng_uniform(rng, -1, 1) : 0);
  }
}

static void angle_gradient_matches_finite_differences(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(17);
  long samples = test_samples(300, 20);
  for (long s = 0; s < samples; ++s) {
    double p[12], g[12];
    for (int i = 0; i < 12; ++i) p[i] = test_rng_normal(&rng);
    double theta = piola__hinge_angle(p, p + 3, p + 6, p + 9, g);
    if (fabs(fabs(theta) - M_PI) < 1e-3) continue; /* the +-pi seam */
    double scale = shell_max_abs(g, 12), sum[3] = {0, 0, 0};
    for (int i = 0; i < 12; ++i) {
      const double h = 1e-7, pi = p[i];
      p[i] = pi + h;
      double tp = piola__hinge_angle(p, p + 3, p + 6, p + 9, NULL);
      p[i] = pi - h;
      double tm = piola__hinge_angle(p, p + 3, p + 6, p + 9, NULL);
      p[i] = pi;
      assert_close(g[i], (tp - tm) / (2 * h), 1e-6 * scale);
      sum[i % 3] += g[i];
    }
    for (int k = 0; k < 3; ++k) assert_close(sum[k], 0.0, 1e-12 * scale);
  }
  /* a flat hinge has angle 0; lifting x1 along its normal gives a negative angle */
  double flat[12] = {0.5, 1, 0, 0.5, -1, 0, 0, 0, 0, 1, 0, 0};
  assert_close(piola__hinge_angle(flat, flat + 3, flat + 6, flat + 9, NULL), 0.0, 1e-15);
  flat[2] = 0.1;
  assert_close(piola__hinge_angle(flat, flat + 3, flat + 6, flat + 9, NULL), -atan(0.1), 1e-14);
  /* degenerate hinges: zero gradient, no NaN */
  double line[12] = {0.5, 0, 0, 0.5, -1, 0, 0, 0, 0, 1, 0, 0}, g[12];
  double theta = piola__hinge_angle(line, line + 3, line + 6, line + 9, g);
  assert_true(isfinite(theta));
  assert_true(shell_max_abs(g, 12) == 0);
}

/* f = -dE/dx for the bending energy, at random bent configurations and rest angles. */
static void bending_forces_are_energy_gradient(void **state) {
  (void)state;
  piola_tri_mesh mesh = shell_sheet(1.0, 0.8, 3, 3);
  int n = mesh.vertex_count;
  double *x = malloc(sizeof(double) * 3 * n), *f = malloc(sizeof(double) * 3 * n);
  piola_shell_body *body = bending_body(&mesh, 0.5);
  int nh = piola_shell_body_hinge_count(body);
  double *rest = malloc(sizeof(double) * nh);
  test_rng rng = test_rng_seeded(23);
  long trials = test_samples(8, 2);
  for (long trial = 0; trial < trials; ++trial) {
    for (int h = 0; h < nh; ++h) rest[h] = trial == 0 ? 0.0 : test_rng_uniform(&rng, -1.5, 1.5);
    assert_int_equal(piola_shell_body_set_rest_angles(body, rest), PIOLA_OK);
    bend(&mesh, 0.4 + 0.2 * trial, &rng, 0.05, x);
    assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
    double scale = shell_max_abs(f, 3 * (size_t)n);
    assert_true(scale > 0);
    for (int i = 0; i < 3 * n; ++i) {
      const double h = 1e-6, xi = x[i];
      x[i] = xi + h;
      double ep = shell_energy(body, x);
      x[i] = xi - h;
      double em = shell_energy(body, x);
      x[i] = xi;
      assert_close(f[i], -(ep - em) / (2 * h), 1e-5 * scale);
    }
    /* no net force or torque */
    double net[3], torque[3];
    shell_net_force_torque(n, x, f, net, torque);
    for (int k = 0; k < 3; ++k) {
      assert_close(net[k], 0.0, 1e-10 * scale);
      assert_close(torque[k], 0.0, 1e-10 * scale);
    }
  }
  free(rest);
  piola_shell_body_destroy(body);
  free(x);
  free(f);
  piola_tri_mesh_free(&mesh);
}

/* A flat sheet, also stretched in its plane, has no bending force; a sheet at rest in a bent
 * shape has none after any rigid motion; a bent sheet's forces rotate with it. */
static void zero_bending_force_flat_and_under_rigid_motion(void **state) {
  (void)state;
  piola_tri_mesh mesh = shell_sheet(1.0, 0.8, 5, 4);
  int n = mesh.vertex_count;
  double *x = malloc(sizeof(double) * 3 * n), *f = malloc(sizeof(double) * 3 * n);
  piola_shell_body *body = bending_body(&mesh, 1.0);
  for (int i = 0; i < n; ++i) {
    x[3 * i] = 1.3 * mesh.positions[3 * i] + 0.2 * mesh.positions[3 * i + 1];
    x[3 * i + 1] = 0.8 * mesh.positions[3 * i + 1];
    x[3 * i + 2] = 0;
  }
  piola_shell_stats stats;
  assert_int_equal(piola_shell_body_update(body, x, 1.0, f, &stats), PIOLA_OK);
  assert_close(stats.bending_energy, 0.0, 1e-15);
  /* only the tiny in-plane stiffness remains: compare with the bending scale of a bend */
  double in_plane = shell_max_abs(f, 3 * (size_t)n);
  piola_shell_body_destroy(body);

  /* rest shape bent: rigid motions give zero force */
  double *bent = malloc(sizeof(double) * 3 * n), *xr = malloc(sizeof(double) * 3 * n);
  bend(&mesh, 0.5, NULL, 0, bent);
  piola_tri_mesh bent_mesh = mesh;
  bent_mesh.positions = bent;
  body = bending_body(&bent_mesh, 1.0);
  test_rng rng = test_rng_seeded(31);
  for (int trial = 0; trial < 5; ++trial) {
    double r[9], t[3] = {test_rng_normal(&rng), test_rng_normal(&rng), test_rng_normal(&rng)};
    shell_random_rotation(&rng, r);
    for (int i = 0; i < n; ++i)
      for (int a = 0; a < 3; ++a)
        xr[3 * i + a] = r[3 * a] * bent[3 * i] + r[3 * a + 1] * bent[3 * i + 1] +
                        r[3 * a + 2] * bent[3 * i + 2] + t[a];
    assert_int_equal(piola_shell_body_update(body, xr, 1.0, f, &stats), PIOLA_OK);
    assert_true(shell_max_abs(f, 3 * (size_t)n) < 1e-9);
    assert_close(stats.bending_energy, 0.0, 1e-12);
  }
  piola_shell_body_destroy(body);

  /* flat rest, bent now: forces are nonzero and rotate with the sheet */
  body = bending_body(&mesh, 1.0);
  bend(&mesh, 0.5, &rng, 0.02, x);
  double *f0 = malloc(sizeof(double) * 3 * n);
  assert_int_equal(piola_shell_body_update(body, x, 1.0, f0, NULL), PIOLA_OK);
  double scale = shell_max_abs(f0, 3 * (size_t)n);
  assert_true(scale > 1e3 * in_plane);
  double r[9];
  shell_random_rotation(&rng, r);
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a)
      xr[3 * i + a] = r[3 * a] * x[3 * i] + r[3 * a + 1] * x[3 * i + 1] + r[3 * a + 2] * x[3 * i + 2] - 2;
  assert_int_equal(piola_shell_body_update(body, xr, 1.0, f, NULL), PIOLA_OK);
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a)
      assert_close(f[3 * i + a],
                   r[3 * a] * f0[3 * i] + r[3 * a + 1] * f0[3 * i + 1] + r[3 * a + 2] * f0[3 * i + 2],
                   1e-9 * scale);
  piola_shell_body_destroy(body);
  free(x);
  free(f);
  free(f0);
  free(bent);
  free(xr);
  piola_tri_mesh_free(&mesh);
}

/* An equilateral lattice: rows of nx + 1 vertices at spacing a, odd rows shifted by a/2,
 * row spacing a sqrt(3)/2; ny rows of triangles. */
static piola_tri_mesh equilateral_lattice(double a, int nx, int ny) {
  piola_tri_mesh mesh;
  memset(&mesh, 0, sizeof mesh);
  mesh.vertex_count = (nx + 1) * (ny + 1);
  mesh.triangle_count = 2 * nx * ny;
  mesh.positions = calloc(3 * (size_t)mesh.vertex_count, sizeof(double));
  mesh.triangles = malloc(3 * sizeof(int32_t) * (size_t)mesh.triangle_count);
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      double *p = mesh.positions + 3 * (j * (nx + 1) + i);
      p[0] = a * (i + 0.5 * (j % 2)) - 0.5 * a * nx;
      p[1] = a * sqrt(3.0) / 2 * j - 0.25 * a * sqrt(3.0) * ny;
    }
  int32_t *t = mesh.triangles;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      int32_t v00 = j * (nx + 1) + i, v10 = v00 + 1, v01 = v00 + nx + 1, v11 = v01 + 1;
      if (j % 2 == 0) { /* upper row shifted right */
        int32_t tri[6] = {v00, v10, v01, v10, v11, v01};
        memcpy(t, tri, sizeof tri);
      } else {
        int32_t tri[6] = {v00, v11, v01, v00, v10, v11};
        memcpy(t, tri, sizeof tri);
      }
      t += 6;
    }
  return mesh;
}

/* On an equilateral mesh bent into a cylinder of curvature k (any direction), the bending
 * energy per unit area is the plate's D k^2 / 2 (docs/shells.md: the factor 2 in the hinge weight is calibrated here): the
 * calibration behind "stiffness is the flexural rigidity D". Edges on the boundary have no
 * hinge, so the comparison counts the area of the interior hinges only: the sum over
 * hinges of (A1 + A2) / 3. */
static void bending_energy_matches_plate_energy(void **state) {
  (void)state;
  piola_tri_mesh mesh = equilateral_lattice(0.02, 20, 20);
  int n = mesh.vertex_count;
  double *x = malloc(sizeof(double) * 3 * n), *rotated = malloc(sizeof(double) * 3 * n);
  const double d = 0.01, radius = 2.0;
  piola_shell_body *body = bending_body(&mesh, d);
  const double triangle_area = sqrt(3.0) / 4 * 0.02 * 0.02;
  double hinge_area = piola_shell_body_hinge_count(body) * 2 * triangle_area / 3;
  for (int turn = 0; turn < 3; ++turn) {
    /* bend along a direction at angle 0, 20, 45 degrees to the lattice */
    double angle = turn == 0 ? 0 : turn == 1 ? M_PI / 9 : M_PI / 4, c = cos(angle), s = sin(angle);
    piola_tri_mesh turned = mesh;
    turned.positions = rotated;
    for (int i = 0; i < n; ++i) {
      const double *p = mesh.positions + 3 * i;
      rotated[3 * i] = c * p[0] - s * p[1];
      rotated[3 * i + 1] = s * p[0] + c * p[1];
      rotated[3 * i + 2] = 0;
    }
    bend(&turned, radius, NULL, 0, x);
    double expected = 0.5 * d / (radius * radius) * hinge_area;
    double energy = bending_energy(body, x);
    printf("plate calibration at %.0f degrees: discrete / continuum = %.4f\n", angle * 180 / M_PI,
           energy / expected);
    assert_close(energy / expected, 1.0, 0.02);
  }
  piola_shell_body_destroy(body);
  free(x);
  free(rotated);
  piola_tri_mesh_free(&mesh);
}

/* Bending damping: -(eta w / 2) (grad theta . v) grad theta. A velocity that only opens
 * one hinge is opposed; rigid velocities are not. */
static void bending_damping_opposes_angle_rate(void **state) {
  (void)state;
  piola_tri_mesh mesh = shell_sheet(1.0, 1.0, 1, 1); /* two triangles, one hinge */
  piola_material material = shell_material(PIOLA_MODEL_COROTATED, 1e-6);
  piola_shell_body_def def = shell_def_of(&mesh, &material);
  def.bending.stiffness = 1.0;
  def.bending.damping = 0.25;
  piola_shell_body *body;
  assert_int_equal(piola_shell_body_create(&def, &body), PIOLA_OK);
  assert_int_equal(piola_shell_body_hinge_count(body), 1);
  double f[12], v[12] = {0};
  assert_int_equal(piola_shell_body_update(body, mesh.positions, 1.0, f, NULL), PIOLA_OK);
  const int32_t *hinge = piola_shell_body_hinges(body);
  v[3 * hinge[0] + 2] = 1.0; /* x1 moves out of plane */
  piola_shell_body_damping_forces(body, v, 0, 0, f);
  assert_true(f[3 * hinge[0] + 2] < 0);
  /* theta rate = grad . v = -1/h1 with h1 the height of x1 over the edge (sqrt(2)/2) */
  double h1 = sqrt(0.5), weight = 2.0 * 2.0 / 1.0;
  assert_close(f[3 * hinge[0] + 2], -0.5 * 0.25 * weight / (h1 * h1), 1e-12);
  for (int i = 0; i < 4; ++i) v[3 * i] = 1, v[3 * i + 1] = -2, v[3 * i + 2] = 0.5;
  piola_shell_body_damping_forces(body, v, 0, 0, f);
  assert_true(shell_max_abs(f, 12) < 1e-12);
  piola_shell_body_destroy(body);
  piola_tri_mesh_free(&mesh);
}

/* Plastic bending: past the yield angle the rest angle flows toward the current angle
 * (at once with an infinite rate, a fraction 1 - exp(-rate dt) otherwise); within it,
 * nothing flows. After flowing, releasing the sheet keeps part of the bend. */
static void plastic_bending_flows_past_yield(void **state) {
  (void)state;
  piola_tri_mesh mesh = shell_sheet(1.0, 1.0, 1, 1);
  piola_material material = shell_material(PIOLA_MODEL_COROTATED, 1e5);
  piola_shell_body_def def = shell_def_of(&mesh, &material);
  def.bending.stiffness = 1.0;
  def.bending.yield_angle = 0.2;
  piola_shell_body *body;
  assert_int_equal(piola_shell_body_create(&def, &body), PIOLA_OK);
  const int32_t *hinge = piola_shell_body_hinges(body);
  double x[12], f[12];
  memcpy(x, mesh.positions, sizeof x);
  /* fold x1 about the edge by an angle a: rotate it about the edge's line */
  const double *p3 = mesh.positions + 3 * hinge[2], *p4 = mesh.positions + 3 * hinge[3];
  const double *p1 = mesh.positions + 3 * hinge[0];
  double e[3] = {p4[0] - p3[0], p4[1] - p3[1], 0}, le = sqrt(e[0] * e[0] + e[1] * e[1]);
  e[0] /= le, e[1] /= le;
  double r[3] = {p1[0] - p3[0], p1[1] - p3[1], 0};
  double along = r[0] * e[0] + r[1] * e[1];
  double perp[3] = {r[0] - along * e[0], r[1] - along * e[1], 0};
  double a = 0.15;
  for (int k = 0; k < 3; ++k) x[3 * hinge[0] + k] = p3[k] + along * e[k] + cos(a) * perp[k];
  x[3 * hinge[0] + 2] = sin(a) * sqrt(perp[0] * perp[0] + perp[1] * perp[1]);
  assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
  double theta = piola_shell_body_angles(body)[0];
  assert_close(fabs(theta), a, 1e-12);
  assert_int_equal(piola_shell_body_plastic_flow(body, 0.01), 0);
  assert_close(piola_shell_body_rest_angles(body)[0], 0.0, 0.0);
  a = 0.5;
  for (int k = 0; k < 3; ++k) x[3 * hinge[0] + k] = p3[k] + along * e[k] + cos(a) * perp[k];
  x[3 * hinge[0] + 2] = sin(a) * sqrt(perp[0] * perp[0] + perp[1] * perp[1]);
  assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
  theta = piola_shell_body_angles(body)[0];
  assert_int_equal(piola_shell_body_plastic_flow(body, 0.01), 1);
  assert_close(piola_shell_body_rest_angles(body)[0], copysign(0.3, theta), 1e-12);
  /* the flat sheet now feels a force toward the dent */
  assert_int_equal(piola_shell_body_update(body, mesh.positions, 1.0, f, NULL), PIOLA_OK);
  assert_true(shell_max_abs(f, 12) > 0);
  piola_shell_body_destroy(body);

  /* finite rate: fraction 1 - exp(-rate dt) of the excess */
  def.bending.plastic_rate = 10;
  assert_int_equal(piola_shell_body_create(&def, &body), PIOLA_OK);
  assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
  assert_int_equal(piola_shell_body_plastic_flow(body, 0.01), 1);
  assert_close(piola_shell_body_rest_angles(body)[0], copysign(0.3 * (1 - exp(-0.1)), theta),
               1e-12);
  piola_shell_body_destroy(body);
  piola_tri_mesh_free(&mesh);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(angle_gradient_matches_finite_differences),
      cmocka_unit_test(bending_forces_are_energy_gradient),
      cmocka_unit_test(zero_bending_force_flat_and_under_rigid_motion),
      cmocka_unit_test(bending_energy_matches_plate_energy),
      cmocka_unit_test(bending_damping_opposes_angle_rate),
      cmocka_unit_test(plastic_bending_flows_past_yield),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
