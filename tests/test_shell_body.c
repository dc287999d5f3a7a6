/* The shell body in plane: rest state, membrane models against their energy, in-plane forces
 * against the energy by finite differences, invariants, degenerate and inverted triangles,
 * determinism, damping, bad input. Bending has its own file (test_shell_bending.c). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "piola/diagonalize.h"
#include "piola/elastic_body.h"
#include "shell/svd3x2.h"
#include "test_shell_fixtures.h"

static void rest_state_of_a_sheet(void **state) {
  (void)state;
  piola_tri_mesh mesh = shell_sheet(2.0, 1.0, 4, 3);
  piola_material material = shell_material(PIOLA_MODEL_NEOHOOKEAN, 1e5);
  piola_shell_body *body = shell_body_from(&mesh, &material, 0.0);
  assert_int_equal(piola_shell_body_vertex_count(body), 20);
  assert_int_equal(piola_shell_body_triangle_count(body), 24);
  /* interior edges: 3 * 12 cells... all edges minus boundary ones */
  int edges = 4 * 4 + 3 * 5 + 12, boundary = 2 * (4 + 3);
  assert_int_equal(piola_shell_body_hinge_count(body), edges - boundary);
  double mass = 0;
  for (int i = 0; i < 20; ++i) mass += piola_shell_body_masses(body)[i];
  assert_close(mass, 500 * 0.01 * 2.0, 1e-12);
  /* cells 0.5 x 1/3: the altitude onto the diagonal, a b / sqrt(a^2 + b^2) */
  assert_close(piola_shell_body_min_rest_altitude(body), 0.5 / 3.0 / sqrt(0.25 + 1.0 / 9), 1e-12);
  /* plane stress wave speed sqrt(E / (rho (1 - nu^2))) */
  assert_close(piola_shell_body_max_wave_speed(body), sqrt(1e5 / (500 * (1 - 0.09))), 1e-9);
  for (int h = 0; h < piola_shell_body_hinge_count(body); ++h)
    assert_close(piola_shell_body_rest_angles(body)[h], 0.0, 1e-15);
  double f[60];
  piola_shell_stats stats;
  assert_int_equal(piola_shell_body_update(body, mesh.positions, 1.0, f, &stats), PIOLA_OK);
  assert_true(shell_max_abs(f, 60) < 1e-9);
  assert_close(stats.membrane_energy, 0.0, 1e-12);
  assert_int_equal(stats.inverted_count, 0);
  piola_shell_body_destroy(body);
  piola_tri_mesh_free(&mesh);
}

static void generated_sheets_are_valid(void **state) {
  (void)state;
  piola_tri_mesh disk;
  assert_int_equal(piola_tri_mesh_disk(0.5, 4, &disk), PIOLA_OK);
  assert_int_equal(disk.vertex_count, 1 + 3 * 4 * 5);
  assert_int_equal(disk.triangle_count, 6 * 16);
  double area = 0;
  for (int t = 0; t < disk.triangle_count; ++t) {
    const double *a = disk.positions + 3 * disk.triangles[3 * t];
    const double *b = disk.positions + 3 * disk.triangles[3 * t + 1];
    const double *c = disk.positions + 3 * disk.triangles[3 * t + 2];
    double z = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    assert_true(z > 0); /* counterclockwise, non-degenerate */
    area += 0.5 * z;
  }
  /* inscribed 24-gon: 6 k^2 ... the outer ring is a regular 24-gon of radius 0.5 */
  assert_close(area, 0.5 * 24 * 0.25 * sin(2 * M_PI / 24), 1e-12);
  /* the disk is a manifold with every interior edge in two triangles */
  piola_material material = shell_material(PIOLA_MODEL_COROTATED, 1e5);
  piola_shell_body *body = shell_body_from(&disk, &material, 1.0);
  assert_int_equal(piola_shell_body_hinge_count(body), (3 * 96 - 24) / 2);
  piola_shell_body_destroy(body);
  piola_tri_mesh_free(&disk);

  /* tori, closed and half: area near 4 pi^2 R r (times the sweep), normals out of the tube */
  for (int half = 0; half < 2; ++half) {
    piola_tri_mesh torus;
    assert_int_equal(piola_tri_mesh_torus(1.0, 0.25, 64, 32, half ? 180 : 360, &torus), PIOLA_OK);
    double torus_area = 0;
    for (int t = 0; t < torus.triangle_count; ++t) {
      const double *a = torus.positions + 3 * torus.triangles[3 * t];
      const double *b = torus.positions + 3 * torus.triangles[3 * t + 1];
      const double *c = torus.positions + 3 * torus.triangles[3 * t + 2];
      double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                     e1[0] * e2[1] - e1[1] * e2[0]};
      torus_area += 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      /* from the tube's centre circle to the centroid */
      double g[3] = {(a[0] + b[0] + c[0]) / 3, (a[1] + b[1] + c[1]) / 3, (a[2] + b[2] + c[2]) / 3};
      double rho = sqrt(g[0] * g[0] + g[1] * g[1]);
      double out[3] = {g[0] - g[0] / rho, g[1] - g[1] / rho, g[2]};
      assert_true(n[0] * out[0] + n[1] * out[1] + n[2] * out[2] > 0);
    }
    double expected = 4 * M_PI * M_PI * 0.25 * (half ? 0.5 : 1.0);
    assert_close(torus_area, expected, 0.01 * expected);
    piola_tri_mesh_free(&torus);
  }

  piola_tri_mesh bad;
  assert_int_equal(piola_tri_mesh_torus(1, 1, 8, 8, 360, &bad), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_int_equal(piola_tri_mesh_rectangle(1, 0, 3, 3, &bad), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_int_equal(piola_tri_mesh_rectangle(1, 1, 0, 3, &bad), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_int_equal(piola_tri_mesh_disk(1, 0, &bad), PIOLA_ERROR_INVALID_ARGUMENT);
}

/* The membrane stress is the derivative of the membrane energy, for every model, wherever
 * no entry is below the inversion threshold. Below it the extension (the solids' one) is a
 * Taylor expansion whose cross terms are not a gradient (docs/materials.md), so there the
 * test checks what the extension promises: finite, and compressive for entries <= 0. */
static void membrane_stress_is_energy_derivative(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(11);
  long samples = test_samples(400, 20);
  for (int m = 0; m < SHELL_MODEL_COUNT; ++m) {
    piola_material material = shell_material(shell_all_models[m], 1e5);
    double rest[2] = {1, 1}, p0[2];
    piola_membrane_stress(&material, rest, p0);
    assert_close(p0[0], 0.0, 1e-9);
    assert_close(p0[1], 0.0, 1e-9);
    assert_close(piola_membrane_energy_density(&material, rest), 0.0, 1e-9);
    for (long s = 0; s < samples; ++s) {
      double f[2] = {test_rng_uniform(&rng, 0.05, 2.0), test_rng_uniform(&rng, -0.5, 2.0)};
      double p[2];
      piola_membrane_stress(&material, f, p);
      assert_true(isfinite(p[0]) && isfinite(p[1]));
      if (f[1] <= 0) assert_true(p[1] < 0);
      if (f[0] < material.threshold + 1e-3 || f[1] < material.threshold + 1e-3) continue;
      for (int i = 0; i < 2; ++i) {
        const double h = 1e-6;
        double fp[2] = {f[0], f[1]}, fm[2] = {f[0], f[1]};
        fp[i] += h;
        fm[i] -= h;
        double fd = (piola_membrane_energy_density(&material, fp) -
                     piola_membrane_energy_density(&material, fm)) /
                    (2 * h);
        assert_close(p[i], fd, 1e-5 * (1e5 + fabs(p[i])));
      }
    }
  }
}

/* Small strain: uniaxial stress in plane stress has sigma = E eps and lateral stress zero
 * when the lateral stretch is 1 - nu eps. */
static void membrane_is_plane_stress_near_rest(void **state) {
  (void)state;
  for (int m = 0; m < SHELL_MODEL_COUNT; ++m) {
    piola_material material = shell_material(shell_all_models[m], 1e5);
    const double eps = 1e-6;
    double f[2] = {1 + eps, 1 - 0.3 * eps}, p[2];
    piola_membrane_stress(&material, f, p);
    assert_close(p[0], 1e5 * eps, 1e5 * eps * 1e-4);
    assert_close(p[1], 0.0, 1e5 * eps * 1e-4);
  }
}

/* The force loop's closed-form 3x2 diagonalization: F = U diag(fhat) V^T, U^T U = I,
 * V a rotation, fhat sorted and equal to the robust public one's, for well-shaped, thin
 * (fast path) and collapsed (fallback) F at scales from 1e-8 to 1e8. */
static void fast_svd3x2_matches_the_robust_one(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(41);
  long samples = test_samples(20000, 200);
  for (long s = 0; s < samples; ++s) {
    double f[3][2];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 2; ++j) f[i][j] = test_rng_normal(&rng);
    int kind = (int)(s % 4);
    if (kind >= 1) { /* second column nearly parallel to the first */
      double eps = kind == 1 ? 1e-3 : kind == 2 ? 1e-7 : 0.0;
      for (int i = 0; i < 3; ++i) f[i][1] = 0.7 * f[i][0] + eps * f[i][1];
    }
    double scale = pow(10.0, test_rng_uniform(&rng, -8, 8));
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 2; ++j) f[i][j] *= scale;
    double u[6], v[4], fhat[2];
    assert_int_equal(piola__svd3x2(f, u, fhat, v), 0);
    double norm = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 2; ++j) {
        norm += f[i][j] * f[i][j];
        double r = u[2 * i] * fhat[0] * v[2 * j] + u[2 * i + 1] * fhat[1] * v[2 * j + 1];
        assert_close(r, f[i][j], 1e-13 * scale * 4);
      }
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) {
        double dot = u[a] * u[b] + u[2 + a] * u[2 + b] + u[4 + a] * u[4 + b];
        assert_close(dot, a == b ? 1.0 : 0.0, 1e-13);
      }
    assert_close(v[0] * v[3] - v[1] * v[2], 1.0, 1e-13);
    assert_true(fhat[0] >= fhat[1] && fhat[1] >= 0);
    piola_mat3x2 fm, um;
    piola_mat2 vm;
    double ref[2];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 2; ++j) fm.m[i][j] = f[i][j];
    assert_int_equal(piola_diagonalize3x2(&fm, &um, ref, &vm), PIOLA_OK);
    assert_close(fhat[0], ref[0], 1e-13 * ref[0]);
    /* the small value to the accuracy F's rounding allows; relative where well separated */
    assert_close(fhat[1], ref[1], 1e-13 * ref[0] + (kind == 0 ? 1e-12 * ref[1] : 0));
  }
}

static void perturbed_sheet(const piola_tri_mesh *mesh, test_rng *rng, double amplitude,
                            double *x) {
  for (int i = 0; i < mesh->vertex_count; ++i) {
    x[3 * i] = 1.2 * mesh->positions[3 * i] + amplitude * test_rng_uniform(rng, -1, 1);
    x[3 * i + 1] = 0.9 * mesh->positions[3 * i + 1] + amplitude * test_rng_uniform(rng, -1, 1);
    x[3 * i + 2] = mesh->positions[3 * i + 2] + amplitude * test_rng_uniform(rng, -1, 1);
  }
}

/* f = -dE/dx by central differences, for every model, at random large deformations. */
static void inplane_forces_are_energy_gradient(void **state) {
  (void)state;
  piola_tri_mesh mesh = shell_sheet(1.0, 0.8, 3, 2);
  int n = mesh.vertex_count;
  double *x = malloc(sizeof(double) * 3 * n), *f = malloc(sizeof(double) * 3 * n);
  test_rng rng = test_rng_seeded(3);
  long trials = test_samples(6, 2);
  for (int m = 0; m < SHELL_MODEL_COUNT; ++m) {
    piola_material material = shell_material(shell_all_models[m], 1e5);
    piola_shell_body *body = shell_body_from(&mesh, &material, 0.0);
    for (long trial = 0; trial < trials; ++trial) {
      perturbed_sheet(&mesh, &rng, 0.08, x);
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
    }
    piola_shell_body_destroy(body);
  }
  free(x);
  free(f);
  piola_tri_mesh_free(&mesh);
}

/* Net force and torque of the in-plane forces vanish; rotating the deformed sheet rotates
 * the forces. */
static void inplane_forces_are_invariant(void **state) {
  (void)state;
  piola_tri_mesh mesh = shell_sheet(1.0, 0.8, 4, 3);
  int n = mesh.vertex_count;
  double *x = malloc(sizeof(double) * 3 * n), *f = malloc(sizeof(double) * 3 * n);
  double *xr = malloc(sizeof(double) * 3 * n), *fr = malloc(sizeof(double) * 3 * n);
  test_rng rng = test_rng_seeded(5);
  for (int m = 0; m < SHELL_MODEL_COUNT; ++m) {
    piola_material material = shell_material(shell_all_models[m], 1e5);
    piola_shell_body *body = shell_body_from(&mesh, &material, 0.0);
    perturbed_sheet(&mesh, &rng, 0.1, x);
    assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
    double scale = shell_max_abs(f, 3 * (size_t)n), net[3], torque[3];
    shell_net_force_torque(n, x, f, net, torque);
    for (int k = 0; k < 3; ++k) {
      assert_close(net[k], 0.0, 1e-10 * scale);
      assert_close(torque[k], 0.0, 1e-10 * scale);
    }
    double r[9];
    shell_random_rotation(&rng, r);
    for (int i = 0; i < n; ++i)
      for (int a = 0; a < 3; ++a)
        xr[3 * i + a] = r[3 * a] * x[3 * i] + r[3 * a + 1] * x[3 * i + 1] +
                        r[3 * a + 2] * x[3 * i + 2] + 0.7 * (a + 1);
    assert_int_equal(piola_shell_body_update(body, xr, 1.0, fr, NULL), PIOLA_OK);
    for (int i = 0; i < n; ++i)
      for (int a = 0; a < 3; ++a) {
        double expected = r[3 * a] * f[3 * i] + r[3 * a + 1] * f[3 * i + 1] + r[3 * a + 2] * f[3 * i + 2];
        assert_close(fr[3 * i + a], expected, 1e-9 * scale);
      }
    piola_shell_body_destroy(body);
  }
  free(x);
  free(f);
  free(xr);
  free(fr);
  piola_tri_mesh_free(&mesh);
}

/* Gradient descent steps along the force from a collapsed triangle: forces are finite and
 * nonzero, the energy drops and the triangle reopens. */
static void descend(piola_shell_body *body, double *x, int steps, double step) {
  double f[9];
  for (int s = 0; s < steps; ++s) {
    assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
    for (int i = 0; i < 9; ++i) {
      assert_true(isfinite(f[i]));
      x[i] += step * f[i];
    }
  }
}

static double triangle_area_of(const double *x) {
  double e1[3] = {x[3] - x[0], x[4] - x[1], x[5] - x[2]}, e2[3] = {x[6] - x[0], x[7] - x[1], x[8] - x[2]};
  double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                 e1[0] * e2[1] - e1[1] * e2[0]};
  return 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

static void collapsed_triangles_recover(void **state) {
  (void)state;
  piola_tri_mesh mesh = shell_single_triangle(1.0);
  const double rest_area = 0.4;
  for (int m = 0; m < SHELL_MODEL_COUNT; ++m) {
    piola_material material = shell_material(shell_all_models[m], 1e5);
    piola_shell_body *body = shell_body_from(&mesh, &material, 0.0);
    /* per unit stiffness: one step moves a node by ~ step * E * V0 / L */
    const double step = 0.02 / (1e5 * 0.01 * rest_area);
    /* a line: the third corner on the first edge; and a line along a diagonal in 3D */
    double lines[2][9] = {{0, 0, 0, 1, 0, 0, 0.4, 0, 0}, {0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1}};
    for (int l = 0; l < 2; ++l) {
      double x[9], f[9];
      memcpy(x, lines[l], sizeof x);
      piola_shell_stats stats;
      assert_int_equal(piola_shell_body_update(body, x, 1.0, f, &stats), PIOLA_OK);
      assert_true(shell_max_abs(f, 9) > 0);
      assert_int_equal(stats.degenerate_count, 1);
      double e0 = stats.membrane_energy;
      descend(body, x, 40, step);
      assert_true(triangle_area_of(x) > 0.1 * rest_area);
      assert_true(shell_energy(body, x) < e0);
    }
    /* a point */
    double x[9] = {0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2}, f[9];
    piola_shell_stats stats;
    assert_int_equal(piola_shell_body_update(body, x, 1.0, f, &stats), PIOLA_OK);
    assert_true(shell_max_abs(f, 9) > 0);
    assert_close(piola_shell_body_fhat(body)[0], 0.0, 0.0);
    double e0 = stats.membrane_energy;
    descend(body, x, 60, step);
    assert_true(triangle_area_of(x) > 0.1 * rest_area);
    assert_true(shell_energy(body, x) < e0);
    piola_shell_body_destroy(body);
  }
  piola_tri_mesh_free(&mesh);
}

/* With reference normals, a triangle flipped through its edge is inverted: signed fhat < 0,
 * forces push it back until its normal agrees with the reference. Without them, the same
 * flipped triangle is a rigid rotation of the rest shape and feels no force. */
static void triangles_inverted_against_reference_are_pushed_back(void **state) {
  (void)state;
  piola_tri_mesh mesh = shell_single_triangle(1.0);
  for (int m = 0; m < SHELL_MODEL_COUNT; ++m) {
    piola_material material = shell_material(shell_all_models[m], 1e5);
    piola_shell_body_def def = shell_def_of(&mesh, &material);
    def.thickness = 0.01;
    def.use_reference_normals = true;
    piola_shell_body *body;
    assert_int_equal(piola_shell_body_create(&def, &body), PIOLA_OK);
    double flipped[9] = {0, 0, 0, 1, 0, 0, 0.3, -0.8, 0}, f[9];
    piola_shell_stats stats;
    assert_int_equal(piola_shell_body_update(body, flipped, 1.0, f, &stats), PIOLA_OK);
    assert_int_equal(stats.inverted_count, 1);
    assert_true(piola_shell_body_fhat(body)[1] < 0);
    /* the free corner is pushed toward +y (back through the edge) */
    assert_true(f[7] > 0);
    double x[9];
    memcpy(x, flipped, sizeof x);
    const double step = 0.02 / (1e5 * 0.01 * 0.4);
    for (int s = 0; s < 200 && stats.inverted_count; ++s) {
      assert_int_equal(piola_shell_body_update(body, x, 1.0, f, &stats), PIOLA_OK);
      for (int i = 0; i < 9; ++i) x[i] += step * f[i];
    }
    assert_int_equal(stats.inverted_count, 0);
    /* the force is a descent direction of the (extended) energy there */
    memcpy(x, flipped, sizeof x);
    x[2] = 0.05;
    assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
    double e0 = shell_energy(body, x);
    for (int i = 0; i < 9; ++i) x[i] += 1e-3 * step * f[i];
    assert_true(shell_energy(body, x) < e0);
    piola_shell_body_destroy(body);

    body = shell_body_from(&mesh, &material, 0.0);
    assert_int_equal(piola_shell_body_update(body, flipped, 1.0, f, &stats), PIOLA_OK);
    assert_int_equal(stats.inverted_count, 0);
    assert_true(shell_max_abs(f, 9) < 1e-8);
    piola_shell_body_destroy(body);
  }
  /* reference normals given explicitly: +z reference, triangle wound clockwise at rest is
   * inverted from the start */
  piola_material material = shell_material(PIOLA_MODEL_COROTATED, 1e5);
  piola_shell_body_def def = shell_def_of(&mesh, &material);
  def.use_reference_normals = true;
  double down[3] = {0, 0, -1};
  def.reference_normals = down;
  piola_shell_body *body;
  assert_int_equal(piola_shell_body_create(&def, &body), PIOLA_OK);
  double f[9];
  piola_shell_stats stats;
  assert_int_equal(piola_shell_body_update(body, mesh.positions, 1.0, f, &stats), PIOLA_OK);
  assert_int_equal(stats.inverted_count, 1);
  double up[3] = {0, 0, 2};
  assert_int_equal(piola_shell_body_set_reference_normals(body, up), PIOLA_OK);
  assert_int_equal(piola_shell_body_update(body, mesh.positions, 1.0, f, &stats), PIOLA_OK);
  assert_int_equal(stats.inverted_count, 0);
  piola_shell_body_destroy(body);
  piola_tri_mesh_free(&mesh);
}

static void forces_do_not_depend_on_thread_count(void **state) {
  (void)state;
  /* large enough that every loop runs in parallel (small bodies run on one thread) */
  piola_tri_mesh mesh = shell_sheet(1.0, 1.0, 70, 70);
  int n = mesh.vertex_count;
  double *x = malloc(sizeof(double) * 3 * n), *f1 = malloc(sizeof(double) * 3 * n),
         *f2 = malloc(sizeof(double) * 3 * n);
  test_rng rng = test_rng_seeded(9);
  perturbed_sheet(&mesh, &rng, 0.01, x);
  piola_material material = shell_material(PIOLA_MODEL_NEOHOOKEAN, 1e5);
  piola_shell_body *body = shell_body_from(&mesh, &material, 0.01);
  piola_set_thread_count(1);
  assert_int_equal(piola_shell_body_update(body, x, 1.0, f1, NULL), PIOLA_OK);
  piola_set_thread_count(3);
  assert_int_equal(piola_shell_body_update(body, x, 1.0, f2, NULL), PIOLA_OK);
  assert_memory_equal(f1, f2, sizeof(double) * 3 * n);
  piola_shell_body_damping_forces(body, x, 0.3, 0.1, f2);
  piola_set_thread_count(1);
  piola_shell_body_damping_forces(body, x, 0.3, 0.1, f1);
  assert_memory_equal(f1, f2, sizeof(double) * 3 * n);
  piola_set_thread_count(0);
  piola_shell_body_destroy(body);
  free(x);
  free(f1);
  free(f2);
  piola_tri_mesh_free(&mesh);
}

/* In-plane and bending damping: linear, symmetric (w . f(v) = v . f(w)), dissipative, and
 * zero for rigid velocities of the rest shape. */
static void damping_is_symmetric_dissipative_and_rigid_free(void **state) {
  (void)state;
  piola_tri_mesh mesh = shell_sheet(1.0, 0.8, 4, 3);
  int n = mesh.vertex_count;
  double *x = malloc(sizeof(double) * 3 * n), *f = malloc(sizeof(double) * 3 * n);
  double *v = malloc(sizeof(double) * 3 * n), *w = malloc(sizeof(double) * 3 * n);
  double *g = malloc(sizeof(double) * 3 * n);
  test_rng rng = test_rng_seeded(21);
  piola_material material = shell_material(PIOLA_MODEL_COROTATED, 1e5);
  piola_shell_body_def def = shell_def_of(&mesh, &material);
  def.bending.stiffness = 0.1;
  def.bending.damping = 0.02;
  piola_shell_body *body;
  assert_int_equal(piola_shell_body_create(&def, &body), PIOLA_OK);
  perturbed_sheet(&mesh, &rng, 0.1, x);
  assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
  for (int i = 0; i < 3 * n; ++i) v[i] = test_rng_normal(&rng), w[i] = test_rng_normal(&rng);
  piola_shell_body_damping_forces(body, v, 0.5, 0.2, f);
  piola_shell_body_damping_forces(body, w, 0.5, 0.2, g);
  double wf = 0, vg = 0, vf = 0;
  for (int i = 0; i < 3 * n; ++i) wf += w[i] * f[i], vg += v[i] * g[i], vf += v[i] * f[i];
  assert_close(wf, vg, 1e-10 * (fabs(wf) + fabs(vg)));
  assert_true(vf < 0);
  /* linear: f(2 v + w) = 2 f(v) + f(w) */
  for (int i = 0; i < 3 * n; ++i) w[i] = 2 * v[i] + w[i];
  double *h = malloc(sizeof(double) * 3 * n);
  piola_shell_body_damping_forces(body, w, 0.5, 0.2, h);
  for (int i = 0; i < 3 * n; ++i) assert_close(h[i], 2 * f[i] + g[i], 1e-9 * shell_max_abs(h, 3 * (size_t)n));
  /* rigid velocity (translation + rotation) at the rest shape: no damping force */
  assert_int_equal(piola_shell_body_update(body, mesh.positions, 1.0, f, NULL), PIOLA_OK);
  double omega[3] = {0.3, -0.7, 0.2}, t[3] = {1, 2, -1};
  for (int i = 0; i < n; ++i) {
    const double *p = mesh.positions + 3 * i;
    v[3 * i] = t[0] + omega[1] * p[2] - omega[2] * p[1];
    v[3 * i + 1] = t[1] + omega[2] * p[0] - omega[0] * p[2];
    v[3 * i + 2] = t[2] + omega[0] * p[1] - omega[1] * p[0];
  }
  piola_shell_body_damping_forces(body, v, 0.5, 0.2, f);
  assert_true(shell_max_abs(f, 3 * (size_t)n) < 1e-12);
  piola_shell_body_destroy(body);
  free(x);
  free(f);
  free(v);
  free(w);
  free(g);
  free(h);
  piola_tri_mesh_free(&mesh);
}

static void bad_input_is_reported(void **state) {
  (void)state;
  piola_tri_mesh mesh = shell_single_triangle(1.0);
  piola_material material = shell_material(PIOLA_MODEL_COROTATED, 1e5);
  piola_shell_body_def def = shell_def_of(&mesh, &material);
  piola_shell_body *body = (piola_shell_body *)&def;
  def.thickness = 0;
  assert_int_equal(piola_shell_body_create(&def, &body), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_null(body);
  def.thickness = 1e-3;
  def.bending.stiffness = -1;
  assert_int_equal(piola_shell_body_create(&def, &body), PIOLA_ERROR_INVALID_ARGUMENT);
  def.bending.stiffness = 0;
  def.plasticity.max_plastic_stretch = 1;
  assert_int_equal(piola_shell_body_create(&def, &body), PIOLA_ERROR_INVALID_ARGUMENT);
  def.plasticity.max_plastic_stretch = 4;
  mesh.triangles[2] = 7;
  assert_int_equal(piola_shell_body_create(&def, &body), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "triangle 0"));
  mesh.triangles[2] = 2;
  mesh.positions[6] = 0.5, mesh.positions[7] = 0; /* collinear rest triangle */
  assert_int_equal(piola_shell_body_create(&def, &body), PIOLA_ERROR_DEGENERATE_ELEMENT);
  mesh.positions[7] = 0.8;
  assert_int_equal(piola_shell_body_create(&def, &body), PIOLA_OK);
  double x[9] = {0, 0, 0, 1, 0, 0, 0.3, NAN, 0}, f[9] = {7, 7, 7, 7, 7, 7, 7, 7, 7};
  assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_ERROR_NOT_FINITE);
  assert_non_null(strstr(piola_last_error(), "vertex 2"));
  assert_close(f[0], 7.0, 0.0);
  assert_int_equal(piola_shell_body_update(body, mesh.positions, -1.0, f, NULL),
                   PIOLA_ERROR_INVALID_ARGUMENT);
  piola_shell_body_destroy(body);
  piola_tri_mesh_free(&mesh);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(rest_state_of_a_sheet),
      cmocka_unit_test(generated_sheets_are_valid),
      cmocka_unit_test(membrane_stress_is_energy_derivative),
      cmocka_unit_test(fast_svd3x2_matches_the_robust_one),
      cmocka_unit_test(membrane_is_plane_stress_near_rest),
      cmocka_unit_test(inplane_forces_are_energy_gradient),
      cmocka_unit_test(inplane_forces_are_invariant),
      cmocka_unit_test(collapsed_triangles_recover),
      cmocka_unit_test(triangles_inverted_against_reference_are_pushed_back),
      cmocka_unit_test(forces_do_not_depend_on_thread_count),
      cmocka_unit_test(damping_is_symmetric_dissipative_and_rigid_free),
      cmocka_unit_test(bad_input_is_reported),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
