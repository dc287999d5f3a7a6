/* The elastic body: rest state, elastic forces against energy, invariants, inversion
 * handling, determinism, fast kernel against the scalar reference, bad input. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "force/elastic_body_internal.h"
#include "support/elastic_referees.h"
#include "force/svd_kernel.h"
#include "test_elastic_body_fixtures.h"

static const piola_material_model all_models[] = {PIOLA_MODEL_ROTATED_LINEAR, PIOLA_MODEL_COROTATED,
                                                  PIOLA_MODEL_STVK, PIOLA_MODEL_NEOHOOKEAN,
                                                  PIOLA_MODEL_SPLINE};
#define MODEL_COUNT 5

static void rest_state_of_a_single_tet(void **state) {
  (void)state;
  piola_tet_mesh mesh = fixture_single_tet(2.0);
  piola_material material = fixture_material(PIOLA_MODEL_NEOHOOKEAN);
  piola_elastic_body *body = fixture_body(&mesh, &material);
  double volume = 8.0 / 6.0;
  const double *m = piola_elastic_body_masses(body);
  for (int i = 0; i < 4; ++i) assert_close(m[i], 1000 * volume / 4, 1e-9);
  /* altitudes: 2 from the three axis corners, 2/sqrt(3) from the origin */
  assert_close(piola_elastic_body_min_rest_altitude(body), 2.0 / sqrt(3.0), 1e-12);
  assert_close(piola_elastic_body_max_wave_speed(body),
               sqrt((material.lambda + 2 * material.mu) / 1000.0), 1e-9);
  piola_elastic_body_destroy(body);
  fixture_mesh_free(&mesh);
}

static void negative_rest_tet_is_reoriented(void **state) {
  (void)state;
  piola_tet_mesh mesh = fixture_single_tet(1.0);
  int32_t tmp = mesh.tets[1];
  mesh.tets[1] = mesh.tets[2];
  mesh.tets[2] = tmp;
  assert_true(fixture_signed_volume(mesh.positions, mesh.tets) < 0);
  piola_material material = fixture_material(PIOLA_MODEL_COROTATED);
  piola_elastic_body *body = fixture_body(&mesh, &material);
  assert_true(fixture_signed_volume(mesh.positions, piola_elastic_body_tets(body)) > 0);
  double forces[12];
  piola_elastic_stats stats;
  assert_int_equal(piola_elastic_body_update(body, mesh.positions, 1.0, forces, &stats), PIOLA_OK);
  assert_true(fixture_max_abs(forces, 12) < 1e-9);
  assert_int_equal(stats.inverted_count, 0);
  assert_close(stats.min_det_f, 1.0, 1e-12);
  piola_elastic_body_destroy(body);
  fixture_mesh_free(&mesh);
}

/* Positions: the rest grid, randomly perturbed by `noise` times the edge length. */
static void perturb(test_rng *rng, const double *rest, double *x, int n, double noise) {
  for (int i = 0; i < n; ++i) x[i] = rest[i] + noise * test_rng_uniform(rng, -1, 1);
}

static void forces_are_minus_the_energy_gradient(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(11);
  piola_tet_mesh mesh = fixture_grid(2, 1.0);
  int n = 3 * mesh.vertex_count;
  double *x = malloc(sizeof(double) * (size_t)n), *f = malloc(sizeof(double) * (size_t)n);
  double *scratch = malloc(sizeof(double) * (size_t)n);
  long samples = test_samples(6, 2);
  for (int mi = 0; mi < MODEL_COUNT; ++mi) {
    piola_material material = fixture_material(all_models[mi]);
    piola_elastic_body *body = fixture_body(&mesh, &material);
    for (long s = 0; s < samples; ++s) {
      /* Large deformations, but every entry of Fhat above the inversion threshold: past it
       * the extended stress is not the gradient of any energy (docs/materials.md). */
      piola_elastic_stats stats;
      double min_fhat;
      do {
        perturb(&rng, mesh.positions, x, n, s % 2 ? 0.15 : 0.25);
        assert_int_equal(piola_elastic_body_update(body, x, 1.0, f, &stats), PIOLA_OK);
        min_fhat = INFINITY;
        const double *fh = piola_elastic_body_fhat(body);
        for (int t = 0; t < 3 * mesh.tet_count; ++t) min_fhat = fmin(min_fhat, fh[t]);
      } while (min_fhat <= material.threshold + 0.05);
      double scale = fixture_max_abs(f, n);
      const double h = 1e-6;
      for (int i = 0; i < n; ++i) {
        piola_elastic_stats plus, minus;
        double xi = x[i];
        x[i] = xi + h;
        assert_int_equal(piola_elastic_body_update(body, x, 1.0, scratch, &plus), PIOLA_OK);
        x[i] = xi - h;
        assert_int_equal(piola_elastic_body_update(body, x, 1.0, scratch, &minus), PIOLA_OK);
        x[i] = xi;
        double fd = -(plus.elastic_energy - minus.elastic_energy) / (2 * h);
        if (!(fabs(fd - f[i]) <= 1e-5 * scale + 1e-6))
          fail_msg("model %d sample %ld dof %d: force %.12g, -dE/dx %.12g (scale %g, %d inverted)",
                   mi, s, i, f[i], fd, scale, (int)stats.inverted_count);
      }
    }
    piola_elastic_body_destroy(body);
  }
  free(x);
  free(f);
  free(scratch);
  fixture_mesh_free(&mesh);
}

static void every_tet_has_zero_net_force_and_torque(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(12);
  piola_tet_mesh mesh = fixture_single_tet(1.0);
  long samples = test_samples(400, 20);
  int inverted_seen = 0;
  for (int mi = 0; mi < MODEL_COUNT; ++mi) {
    piola_material material = fixture_material(all_models[mi]);
    piola_elastic_body *body = fixture_body(&mesh, &material);
    for (long s = 0; s < samples; ++s) {
      double x[12], f[12];
      for (int i = 0; i < 12; ++i) x[i] = test_rng_uniform(&rng, -1, 1);
      if (s % 5 == 0) /* a flat tet: corner 3 in the plane of the others */
        for (int i = 0; i < 3; ++i) x[9 + i] = 0.3 * x[i] + 0.3 * x[3 + i] + 0.4 * x[6 + i];
      piola_elastic_stats stats;
      assert_int_equal(piola_elastic_body_update(body, x, 1.0, f, &stats), PIOLA_OK);
      inverted_seen += stats.inverted_count;
      double scale = fixture_max_abs(f, 12) + 1e-300;
      for (int i = 0; i < 3; ++i) assert_true(fabs(f[i] + f[3 + i] + f[6 + i] + f[9 + i]) <= 1e-12 * scale);
      double torque[3] = {0, 0, 0};
      for (int c = 0; c < 4; ++c) {
        const double *p = x + 3 * c, *g = f + 3 * c;
        torque[0] += p[1] * g[2] - p[2] * g[1];
        torque[1] += p[2] * g[0] - p[0] * g[2];
        torque[2] += p[0] * g[1] - p[1] * g[0];
      }
      double lever = fixture_max_abs(x, 12);
      for (int i = 0; i < 3; ++i)
        if (!(fabs(torque[i]) <= 1e-10 * scale * lever))
          fail_msg("model %d sample %ld: torque %g vs force scale %g", mi, s, torque[i], scale);
    }
    piola_elastic_body_destroy(body);
  }
  assert_true(inverted_seen > 0);
  fixture_mesh_free(&mesh);
}

static void affine_deformation_gives_zero_force_inside(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(13);
  piola_tet_mesh mesh = fixture_grid(3, 0.5);
  int nv = mesh.vertex_count;
  double *x = malloc(sizeof(double) * 3 * (size_t)nv), *f = malloc(sizeof(double) * 3 * (size_t)nv);
  for (int mi = 0; mi < MODEL_COUNT; ++mi) {
    piola_material material = fixture_material(all_models[mi]);
    piola_elastic_body *body = fixture_body(&mesh, &material);
    for (int s = 0; s < 4; ++s) {
      double a[9];
      for (int k = 0; k < 9; ++k) a[k] = (k % 4 == 0) + test_rng_uniform(&rng, -0.4, 0.4);
      if (s == 3) /* an inverted affine map: mirror the first row */
        for (int k = 0; k < 3; ++k) a[k] = -a[k];
      for (int v = 0; v < nv; ++v)
        for (int i = 0; i < 3; ++i)
          x[3 * v + i] = 0.1 * i + a[3 * i] * mesh.positions[3 * v] +
                         a[3 * i + 1] * mesh.positions[3 * v + 1] + a[3 * i + 2] * mesh.positions[3 * v + 2];
      assert_int_equal(piola_elastic_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
      double scale = fixture_max_abs(f, 3 * nv);
      assert_true(scale > 0);
      int interior = 0;
      for (int v = 0; v < nv; ++v) {
        int i = v % 4, j = (v / 4) % 4, k = v / 16;
        if (i == 0 || i == 3 || j == 0 || j == 3 || k == 0 || k == 3) continue;
        ++interior;
        for (int c = 0; c < 3; ++c)
          if (!(fabs(f[3 * v + c]) <= 1e-10 * scale))
            fail_msg("model %d map %d: interior vertex %d force %g (boundary scale %g)", mi, s, v,
                     f[3 * v + c], scale);
      }
      assert_int_equal(interior, 8);
    }
    piola_elastic_body_destroy(body);
  }
  free(x);
  free(f);
  fixture_mesh_free(&mesh);
}

static void rest_and_rigid_motions_have_zero_force(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(14);
  piola_tet_mesh mesh = fixture_grid(2, 1.0);
  int nv = mesh.vertex_count;
  double *x = malloc(sizeof(double) * 3 * (size_t)nv), *f = malloc(sizeof(double) * 3 * (size_t)nv);
  for (int mi = 0; mi < MODEL_COUNT; ++mi) {
    piola_material material = fixture_material(all_models[mi]);
    piola_elastic_body *body = fixture_body(&mesh, &material);
    /* a force scale: E times a face area */
    double scale = 1e4;
    for (int s = 0; s < 5; ++s) {
      double r[9];
      fixture_random_rotation(&rng, r);
      if (s == 0) memcpy(r, (double[9]){1, 0, 0, 0, 1, 0, 0, 0, 1}, sizeof r);
      double shift[3] = {test_rng_uniform(&rng, -5, 5), test_rng_uniform(&rng, -5, 5), test_rng_uniform(&rng, -5, 5)};
      for (int v = 0; v < nv; ++v)
        for (int i = 0; i < 3; ++i)
          x[3 * v + i] = shift[i] + r[3 * i] * mesh.positions[3 * v] +
                         r[3 * i + 1] * mesh.positions[3 * v + 1] + r[3 * i + 2] * mesh.positions[3 * v + 2];
      piola_elastic_stats stats;
      assert_int_equal(piola_elastic_body_update(body, x, 1.0, f, &stats), PIOLA_OK);
      assert_true(fixture_max_abs(f, 3 * nv) <= 1e-9 * scale);
      assert_true(fabs(stats.elastic_energy) <= 1e-9 * scale);
      assert_int_equal(stats.inverted_count, 0);
      const double *fhat = piola_elastic_body_fhat(body);
      for (int t = 0; t < 3 * mesh.tet_count; ++t) assert_close(fhat[t], 1.0, 1e-12);
    }
    piola_elastic_body_destroy(body);
  }
  free(x);
  free(f);
  fixture_mesh_free(&mesh);
}

/* Inverted, flat, line and point configurations of one tet: forces are finite, and a small
 * step along them makes the tet less inverted (its volume grows). */
static void collapsed_and_inverted_tets_are_pushed_back(void **state) {
  (void)state;
  piola_tet_mesh mesh = fixture_single_tet(1.0);
  double configs[5][12] = {
      {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, -1},          /* inverted (mirrored) */
      {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.2, 0.3, 0},       /* flat: corner 3 in the plane */
      {0, 0, 0, 1, 0, 0, 0.5, 0, 0, 2, 0, 0},         /* collapsed to a line */
      {0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3}, /* a point */
      {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.1, 0.1, -0.05},   /* slightly inverted */
  };
  for (int mi = 0; mi < MODEL_COUNT; ++mi) {
    piola_material material = fixture_material(all_models[mi]);
    piola_elastic_body *body = fixture_body(&mesh, &material);
    const int32_t *tet = piola_elastic_body_tets(body);
    for (int c = 0; c < 5; ++c) {
      double x[12], f[12];
      memcpy(x, configs[c], sizeof x);
      assert_int_equal(piola_elastic_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
      for (int i = 0; i < 12; ++i) assert_true(isfinite(f[i]));
      double before = fixture_signed_volume(x, tet);
      double fmax = fixture_max_abs(f, 12);
      assert_true(fmax > 0);
      double eps = 1e-3 / fmax; /* a displacement of 1e-3 m at most */
      for (int i = 0; i < 12; ++i) x[i] += eps * f[i];
      double after = fixture_signed_volume(x, tet);
      const double *fh = piola_elastic_body_fhat(body);
      double min_before = fmin(fh[0], fmin(fh[1], fh[2]));
      assert_int_equal(piola_elastic_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
      double min_after = fmin(fh[0], fmin(fh[1], fh[2]));
      /* the most compressed (or inverted) direction opens up */
      if (!(min_after > min_before))
        fail_msg("model %d config %d: smallest Fhat entry %.17g -> %.17g", mi, c, min_before, min_after);
      /* and the volume grows, except for St. Venant-Kirchhoff on the mirrored tet: its
       * lambda tr(E) term is compressive in all directions, so the two unflipped axes shrink
       * while the flipped one opens, and the signed volume (the product) can fall. */
      if (!(all_models[mi] == PIOLA_MODEL_STVK && c == 0))
        if (!(after > before)) fail_msg("model %d config %d: volume %.17g -> %.17g", mi, c, before, after);
    }
    piola_elastic_body_destroy(body);
  }
  fixture_mesh_free(&mesh);
}

static void forces_do_not_depend_on_the_thread_count(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(15);
  /* large enough that the loops do run in parallel (PIOLA_PARALLEL_MIN_BLOCKS, _VERTICES) */
  piola_tet_mesh mesh = fixture_grid(17, 0.1);
  assert_true(mesh.tet_count >= 8 * PIOLA_PARALLEL_MIN_BLOCKS);
  assert_true(mesh.vertex_count >= PIOLA_PARALLEL_MIN_VERTICES);
  int n = 3 * mesh.vertex_count;
  double *x = malloc(sizeof(double) * (size_t)n);
  double *f[3];
  piola_elastic_stats stats[3];
  for (int k = 0; k < 3; ++k) f[k] = malloc(sizeof(double) * (size_t)n);
  perturb(&rng, mesh.positions, x, n, 0.06);
  piola_material material = fixture_material(PIOLA_MODEL_NEOHOOKEAN);
  piola_elastic_body *body = fixture_body(&mesh, &material);
  for (int k = 0; k < 3; ++k) {
    piola_set_thread_count(k + 1);
    assert_int_equal(piola_elastic_body_update(body, x, 1.0, f[k], &stats[k]), PIOLA_OK);
  }
  piola_set_thread_count(0);
  assert_true(stats[0].inverted_count > 0);
  for (int k = 1; k < 3; ++k) {
    assert_memory_equal(f[0], f[k], sizeof(double) * (size_t)n);
    assert_memory_equal(&stats[0].elastic_energy, &stats[k].elastic_energy, sizeof(double));
    assert_int_equal(stats[0].inverted_count, stats[k].inverted_count);
  }
  double *vel = malloc(sizeof(double) * (size_t)n), *d[2];
  perturb(&rng, mesh.positions, vel, n, 1.0);
  for (int k = 0; k < 2; ++k) {
    d[k] = malloc(sizeof(double) * (size_t)n);
    piola_set_thread_count(k + 1);
    piola_elastic_body_damping_forces(body, vel, 0.5, 0.2, d[k]);
  }
  piola_set_thread_count(0);
  assert_memory_equal(d[0], d[1], sizeof(double) * (size_t)n);
  for (int k = 0; k < 3; ++k) free(f[k]);
  free(d[0]);
  free(d[1]);
  free(vel);
  free(x);
  piola_elastic_body_destroy(body);
  fixture_mesh_free(&mesh);
}

static void fast_loop_matches_the_scalar_reference(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(16);
  piola_tet_mesh mesh = fixture_grid(4, 0.25);
  int n = 3 * mesh.vertex_count;
  double *x = malloc(sizeof(double) * (size_t)n), *f = malloc(sizeof(double) * (size_t)n);
  double *g = malloc(sizeof(double) * (size_t)n);
  for (int mi = 0; mi < MODEL_COUNT; ++mi) {
    piola_material material = fixture_material(all_models[mi]);
    piola_elastic_body *body = fixture_body(&mesh, &material);
    for (int s = 0; s < 3; ++s) {
      perturb(&rng, mesh.positions, x, n, 0.05 + 0.1 * s);
      /* collapse a few vertices onto one point and one plane */
      for (int i = 0; i < 3; ++i) x[3 * 5 + i] = x[3 * 6 + i] = x[3 * 7 + i];
      for (int v = 30; v < 40; ++v) x[3 * v + 2] = 0.3;
      piola_elastic_stats fast, ref;
      assert_int_equal(piola_elastic_body_update(body, x, 0.7, f, &fast), PIOLA_OK);
      assert_int_equal(piola__elastic_body_update_reference(body, x, 0.7, g, &ref), PIOLA_OK);
      double scale = fixture_max_abs(g, n);
      for (int i = 0; i < n; ++i)
        if (!(fabs(f[i] - g[i]) <= 1e-9 * scale))
          fail_msg("model %d sample %d dof %d: fast %.15g, reference %.15g", mi, s, i, f[i], g[i]);
      assert_close(fast.elastic_energy, ref.elastic_energy, 1e-9 * fabs(ref.elastic_energy));
      assert_int_equal(fast.inverted_count, ref.inverted_count);
      assert_close(fast.min_det_f, ref.min_det_f, 1e-12);
    }
    piola_elastic_body_destroy(body);
  }
  free(x);
  free(f);
  free(g);
  fixture_mesh_free(&mesh);
}

static void stiffness_scale_multiplies_forces(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(17);
  piola_tet_mesh mesh = fixture_grid(2, 1.0);
  int n = 3 * mesh.vertex_count;
  double *x = malloc(sizeof(double) * (size_t)n), *f1 = malloc(sizeof(double) * (size_t)n);
  double *f0 = malloc(sizeof(double) * (size_t)n);
  perturb(&rng, mesh.positions, x, n, 0.3);
  piola_material material = fixture_material(PIOLA_MODEL_STVK);
  piola_elastic_body *body = fixture_body(&mesh, &material);
  piola_elastic_stats s1, s0;
  assert_int_equal(piola_elastic_body_update(body, x, 1.0, f1, &s1), PIOLA_OK);
  assert_int_equal(piola_elastic_body_update(body, x, 0.0, f0, &s0), PIOLA_OK);
  assert_true(fixture_max_abs(f1, n) > 0);
  assert_true(fixture_max_abs(f0, n) == 0.0);
  assert_true(s0.elastic_energy == 0.0);
  assert_int_equal(piola_elastic_body_update(body, x, -1.0, f0, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  free(x);
  free(f0);
  free(f1);
  piola_elastic_body_destroy(body);
  fixture_mesh_free(&mesh);
}

static void bad_input_is_reported(void **state) {
  (void)state;
  piola_tet_mesh mesh = fixture_grid(1, 1.0);
  piola_material material = fixture_material(PIOLA_MODEL_NEOHOOKEAN);
  piola_elastic_body_def def = piola_default_elastic_body_def();
  def.rest_mesh = &mesh;
  def.materials = &material;
  def.material_count = 1;
  piola_elastic_body *body = NULL;

  def.density = 0;
  assert_int_equal(piola_elastic_body_create(&def, &body), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_null(body);
  assert_non_null(strstr(piola_last_error(), "density"));
  def.density = 1000;

  int32_t tet_materials[6] = {0, 0, 0, 1, 0, 0};
  def.tet_materials = tet_materials;
  assert_int_equal(piola_elastic_body_create(&def, &body), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "tet 3"));
  def.tet_materials = NULL;

  mesh.positions[4] = NAN;
  assert_int_equal(piola_elastic_body_create(&def, &body), PIOLA_ERROR_NOT_FINITE);
  assert_non_null(strstr(piola_last_error(), "vertex 1"));
  mesh.positions[4] = 0;

  /* make tet 2 flat: move one of its corners into the plane of the others */
  piola_tet_mesh flat = fixture_grid(1, 1.0);
  int32_t *t2 = flat.tets + 8;
  for (int i = 0; i < 3; ++i)
    flat.positions[3 * t2[3] + i] = 0.5 * flat.positions[3 * t2[1] + i] + 0.5 * flat.positions[3 * t2[2] + i];
  def.rest_mesh = &flat;
  piola_status status = piola_elastic_body_create(&def, &body);
  assert_int_equal(status, PIOLA_ERROR_DEGENERATE_ELEMENT);
  assert_non_null(strstr(piola_last_error(), "rest tet "));
  fixture_mesh_free(&flat);
  def.rest_mesh = &mesh;

  mesh.tets[5] = 99;
  assert_int_equal(piola_elastic_body_create(&def, &body), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "tet 1"));
  mesh.tets[5] = 1;

  assert_int_equal(piola_elastic_body_create(&def, &body), PIOLA_OK);
  double x[24], f[24];
  memcpy(x, mesh.positions, sizeof x);
  for (int i = 0; i < 24; ++i) f[i] = 42.0;
  x[7] = INFINITY;
  assert_int_equal(piola_elastic_body_update(body, x, 1.0, f, NULL), PIOLA_ERROR_NOT_FINITE);
  assert_non_null(strstr(piola_last_error(), "vertex 2"));
  for (int i = 0; i < 24; ++i) assert_true(f[i] == 42.0);
  piola_elastic_body_destroy(body);
  fixture_mesh_free(&mesh);
}

/* Two blocks through the interleaved kernel give exactly what two single calls give: the
 * force loop pairs blocks, and its results must not depend on the pairing. */
static void svd_kernel_pair_matches_single(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(19);
  for (int trial = 0; trial < 200; ++trial) {
    double f[2][9][8], u1[2][9][8], v1[2][9][8], s1[2][3][8], u2[2][9][8], v2[2][9][8], s2[2][3][8];
    for (int b = 0; b < 2; ++b)
      for (int l = 0; l < 8; ++l) {
        int kind = (trial + 3 * b + l) % 4;
        for (int k = 0; k < 9; ++k) {
          double r = test_rng_uniform(&rng, -1, 1);
          f[b][k][l] = kind == 0 ? r : kind == 1 ? (k % 4 == 0) + 0.01 * r : kind == 2 ? 0.0 : 1e-3 * r * (k < 3);
        }
      }
    for (int b = 0; b < 2; ++b)
      piola__svd3_kernel_v8(&f[b][0][0], 8, &u1[b][0][0], &v1[b][0][0], 8, &s1[b][0][0], 8);
    piola__svd3_kernel_v8x2(&f[0][0][0], &f[1][0][0], 8, &u2[0][0][0], &v2[0][0][0], &u2[1][0][0],
                            &v2[1][0][0], 8, &s2[0][0][0], &s2[1][0][0], 8);
    assert_memory_equal(u1, u2, sizeof u1);
    assert_memory_equal(v1, v2, sizeof v1);
    assert_memory_equal(s1, s2, sizeof s1);
  }
}

/* The vectorized SVD kernel: F = U Fhat V^T, proper rotations, the sign convention, on
 * random, rank-deficient, zero, near-identity, tiny and huge matrices. */
static void svd_kernel_is_accurate_and_proper(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(18);
  int n = (int)test_samples(40000, 800);
  double *f = malloc(sizeof(double) * 9 * (size_t)n), *u = malloc(sizeof(double) * 9 * (size_t)n);
  double *v = malloc(sizeof(double) * 9 * (size_t)n), *s = malloc(sizeof(double) * 3 * (size_t)n);
  for (int t = 0; t < n; ++t) {
    double *m = f + 9 * t;
    for (int k = 0; k < 9; ++k) m[k] = test_rng_uniform(&rng, -1, 1);
    switch (t % 8) {
      case 1: for (int r = 0; r < 3; ++r) m[3 * r + 2] = 0.5 * m[3 * r] - 0.25 * m[3 * r + 1]; break;
      case 2: for (int r = 0; r < 3; ++r) { m[3 * r + 1] = 2 * m[3 * r]; m[3 * r + 2] = -m[3 * r]; } break;
      case 3: memset(m, 0, 9 * sizeof(double)); break;
      case 4: for (int k = 0; k < 9; ++k) m[k] = (k % 4 == 0) + 1e-9 * m[k]; break;
      case 5: for (int k = 0; k < 9; ++k) m[k] *= 1e-120; break;
      case 6: for (int k = 0; k < 9; ++k) m[k] *= 1e120; break;
      case 7: for (int k = 0; k < 9; ++k) m[k] = (k == 0 ? 2.0 : k == 4 ? 2.0 : k == 8 ? -1e-3 : 0.0); break;
      default: break;
    }
  }
  piola__svd3_kernel_batch(n, f, u, s, v);
  for (int t = 0; t < n; ++t) {
    const double *m = f + 9 * t, *um = u + 9 * t, *vm = v + 9 * t, *sm = s + 3 * t;
    double err = 0, norm = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double r = 0;
        for (int k = 0; k < 3; ++k) r += um[3 * i + k] * sm[k] * vm[3 * j + k];
        err += (r - m[3 * i + j]) * (r - m[3 * i + j]);
        norm += m[3 * i + j] * m[3 * i + j];
      }
    if (!(sqrt(err) <= 1e-13 * sqrt(norm) + 1e-300))
      fail_msg("matrix %d (kind %d): reconstruction error %g of %g", t, t % 8, sqrt(err), sqrt(norm));
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double uu = 0, vv = 0;
        for (int k = 0; k < 3; ++k) {
          uu += um[3 * k + i] * um[3 * k + j];
          vv += vm[3 * k + i] * vm[3 * k + j];
        }
        assert_true(fabs(uu - (i == j)) <= 1e-13 && fabs(vv - (i == j)) <= 1e-13);
      }
    double det_u = um[0] * (um[4] * um[8] - um[5] * um[7]) - um[1] * (um[3] * um[8] - um[5] * um[6]) +
                   um[2] * (um[3] * um[7] - um[4] * um[6]);
    double det_v = vm[0] * (vm[4] * vm[8] - vm[5] * vm[7]) - vm[1] * (vm[3] * vm[8] - vm[5] * vm[6]) +
                   vm[2] * (vm[3] * vm[7] - vm[4] * vm[6]);
    assert_true(det_u > 0 && det_v > 0);
    double tol = 1e-13 * fabs(sm[0]);
    assert_true(sm[0] >= 0 && sm[1] >= -tol);
    assert_true(fabs(sm[0]) >= fabs(sm[1]) - tol && fabs(sm[1]) >= fabs(sm[2]) - tol);
    double det = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
                 m[2] * (m[3] * m[7] - m[4] * m[6]);
    if (fabs(det) > 1e-9 * sm[0] * sm[0] * sm[0]) assert_true((det < 0) == (sm[2] < 0));
  }
  free(f);
  free(u);
  free(v);
  free(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(rest_state_of_a_single_tet),
      cmocka_unit_test(negative_rest_tet_is_reoriented),
      cmocka_unit_test(forces_are_minus_the_energy_gradient),
      cmocka_unit_test(every_tet_has_zero_net_force_and_torque),
      cmocka_unit_test(affine_deformation_gives_zero_force_inside),
      cmocka_unit_test(rest_and_rigid_motions_have_zero_force),
      cmocka_unit_test(collapsed_and_inverted_tets_are_pushed_back),
      cmocka_unit_test(forces_do_not_depend_on_the_thread_count),
      cmocka_unit_test(fast_loop_matches_the_scalar_reference),
      cmocka_unit_test(stiffness_scale_multiplies_forces),
      cmocka_unit_test(bad_input_is_reported),
      cmocka_unit_test(svd_kernel_is_accurate_and_proper),
      cmocka_unit_test(svd_kernel_pair_matches_single),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
