/* The state-aware step bound of shells (shell/shell_stable_step.h; docs/time-stepping.md,
 * "Step size"):
 *  - the membrane modulus bounds every plane wave of a triangle: for every model on random
 *    stretched, compressed and sheared triangles (entries above the threshold), k_t is at
 *    least dF : dP/dF : dF for random unit rank-one dF = a n^T, the quadratic form taken
 *    from the exact (unprojected) triangle stiffness, and equal to it for some wave at rest;
 *  - collapsed and inverted triangles get a finite, positive bound;
 *  - a sheet at rest keeps its rest step to the bit, a stretched one steps below it;
 *  - a St. Venant-Kirchhoff sheet pulled to three times its length by a driven edge (it blew
 *    up at the rest bound, issue 21) runs to the end with a finite, bounded state. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "piola/world_shells.h"
#include "shell/shell_body_internal.h"
#include "shell/shell_stable_step.h"
#include "shell/shell_stiffness.h"
#include "test_shell_fixtures.h"

/* The triangle's modulus k_t (Pa) behind the body's rate: rate2 rho h_t^2. */
static double triangle_modulus(const piola_shell_body *body) {
  double g[3][2];
  shell_triangle_gradients(&body->triangles[0], g);
  double most = 0;
  for (int a = 0; a < 3; ++a) most = fmax(most, g[a][0] * g[a][0] + g[a][1] * g[a][1]);
  return piola__shell_body_membrane_rate2(body, NULL) * body->density / most;
}

/* dF : C : dF for dF = a n^T (a in 3D, n in the rest plane's 2D frame): the displacement
 * x_c = a (n . X_c) of the rest corners X_c makes exactly that dF, and its stiffness
 * quadratic form is V0 dF : C : dF. */
static double wave_stiffness(const piola_shell_body *body, const double a[3], const double n[2]) {
  const shell_triangle *tri = &body->triangles[0];
  const double *d = tri->dm_inv_eff; /* rest edges: the columns of its inverse */
  const double det = d[0] * d[3] - d[1] * d[2];
  const double e1[2] = {d[3] / det, -d[2] / det}, e2[2] = {-d[1] / det, d[0] / det};
  const double s1 = n[0] * e1[0] + n[1] * e1[1], s2 = n[0] * e2[0] + n[1] * e2[1];
  double dx[9] = {0};
  for (int k = 0; k < 3; ++k) dx[3 + k] = a[k] * s1, dx[6 + k] = a[k] * s2;
  double k9[81];
  piola__shell_triangle_stiffness(body, 0, 0, k9);
  double q = 0;
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 9; ++j) q -= dx[i] * k9[9 * i + j] * dx[j];
  return q / tri->volume;
}

static void random_unit(test_rng *rng, double *v, int n) {
  double s = 0;
  for (int k = 0; k < n; ++k) v[k] = test_rng_uniform(rng, -1, 1), s += v[k] * v[k];
  for (int k = 0; k < n; ++k) v[k] /= sqrt(s);
}

static void membrane_modulus_bounds_every_wave(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(21);
  for (int mi = 0; mi < SHELL_MODEL_COUNT; ++mi) {
    piola_material material = shell_material(shell_all_models[mi], 1e5);
    piola_tri_mesh mesh = shell_single_triangle(0.1);
    piola_shell_body *body = shell_body_from(&mesh, &material, 0.0);
    double x[9], f[9];
    for (int trial = 0; trial < 40; ++trial) {
      /* rest at trial 0; else a random F = R diag(s) V^T-ish deformation of the rest corners,
       * its entries between 0.5 and 3 (above the membrane threshold 0.3) */
      const double *rest = piola_shell_body_rest_positions(body);
      double m[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
      if (trial > 0) {
        double s0 = test_rng_uniform(&rng, 0.5, 3.0), s1 = test_rng_uniform(&rng, 0.5, 3.0),
               shear = test_rng_uniform(&rng, -0.4, 0.4);
        double c = cos(trial), sn = sin(trial);
        const double l[3][3] = {{s0, shear, 0}, {0, s1, 0}, {0, 0, 1}};
        const double r[3][3] = {{c, 0, sn}, {0, 1, 0}, {-sn, 0, c}}; /* out of plane too */
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            m[i][j] = 0;
            for (int k = 0; k < 3; ++k) m[i][j] += r[i][k] * l[k][j];
          }
      }
      for (int v = 0; v < 3; ++v)
        for (int i = 0; i < 3; ++i)
          x[3 * v + i] =
              m[i][0] * rest[3 * v] + m[i][1] * rest[3 * v + 1] + m[i][2] * rest[3 * v + 2];
      assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
      const shell_triangle *tri = &body->triangles[0];
      const double fs = fabs(tri->fhat[0] + tri->fhat[1]);
      if (!(fmin(tri->fhat[0], tri->fhat[1]) > 0.35 && fs > 0.7)) continue;
      const double k = triangle_modulus(body);
      assert_true(isfinite(k) && k > 0);
      double largest = 0;
      for (int w = 0; w < 400; ++w) {
        double a[3], n[2];
        random_unit(&rng, a, 3), random_unit(&rng, n, 2);
        largest = fmax(largest, wave_stiffness(body, a, n));
      }
      if (largest > k * (1 + 1e-9) + 1e-9 * k)
        fail_msg("model %d, trial %d, Fhat (%g, %g): a wave of %g Pa above the bound %g Pa", mi,
                 trial, tri->fhat[0], tri->fhat[1], largest, k);
      if (trial == 0) {
        /* at rest the longitudinal wave is lambda* + 2 mu, the bound exactly */
        const double longitudinal = body->materials[0].lambda + 2.0 * body->materials[0].mu;
        assert_true(fabs(k - longitudinal) <= 1e-9 * longitudinal);
        const double along[3] = {1, 0, 0}, nx[2] = {1, 0};
        assert_true(fabs(wave_stiffness(body, along, nx) - longitudinal) <= 1e-6 * longitudinal);
      }
    }
    /* collapsed to a line, to a point, and folded over (reference normals): finite and positive */
    const double *rest = piola_shell_body_rest_positions(body);
    const double squash[3][3] = {{1, 0, 0}, {0, 1e-9, 0}, {0, 0, 1}}, point[3][3] = {{0}},
                 fold[3][3] = {{1, 0, 0}, {0, -0.7, 0}, {0, 0, 1}};
    const double(*states[3])[3] = {squash, point, fold};
    for (int s = 0; s < 3; ++s) {
      for (int v = 0; v < 3; ++v)
        for (int i = 0; i < 3; ++i)
          x[3 * v + i] = states[s][i][0] * rest[3 * v] + states[s][i][1] * rest[3 * v + 1];
      assert_int_equal(piola_shell_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
      const double k = triangle_modulus(body);
      if (!(isfinite(k) && k > 0))
        fail_msg("model %d, collapsed state %d, Fhat (%g, %g): bound %g Pa", mi, s,
                 body->triangles[0].fhat[0], body->triangles[0].fhat[1], k);
    }
    piola_shell_body_destroy(body);
    piola_tri_mesh_free(&mesh);
  }
}

static piola_world *sheet_world(piola_material_model model, double pull_speed, double bending) {
  piola_constraint_def ends[2];
  memset(ends, 0, sizeof ends);
  for (int e = 0; e < 2; ++e) {
    const double x = e == 0 ? -0.5 : 0.5;
    ends[e].selector.type = PIOLA_SELECT_BOX;
    ends[e].selector.box_min = (piola_vec3){x - 0.01, -1, -1};
    ends[e].selector.box_max = (piola_vec3){x + 0.01, 1, 1};
  }
  ends[1].driven = true;
  ends[1].motion = piola_default_rigid_motion_def();
  ends[1].motion.velocity[0] = piola_track_constant(pull_speed);
  return shell_sheet_world(model, 0.5, bending, ends, pull_speed > 0 ? 2 : 1);
}

static void a_sheet_at_rest_keeps_its_rest_step(void **state) {
  (void)state;
  for (int mi = 0; mi < SHELL_MODEL_COUNT; ++mi) {
    piola_world *world = sheet_world(shell_all_models[mi], 0.0, 0.0);
    const piola_shell_body *body = piola_world_shell_body(world, 0);
    const double rest =
        0.5 * piola_shell_body_min_rest_altitude(body) / piola_shell_body_max_wave_speed(body);
    assert_true(piola_world_stable_dt(world) == rest);
    piola_world_destroy(world);
  }
}

static void a_pulled_stvk_sheet_does_not_blow_up(void **state) {
  (void)state;
  const piola_material_model models[2] = {PIOLA_MODEL_STVK, PIOLA_MODEL_SPLINE};
  for (int mi = 0; mi < 2; ++mi) {
    piola_world *world = sheet_world(models[mi], 4.0, 1e-4);
    const piola_shell_body *body = piola_world_shell_body(world, 0);
    const double rest =
        0.5 * piola_shell_body_min_rest_altitude(body) / piola_shell_body_max_wave_speed(body);
    /* 0.5 s: the driven edge ends 2 m out, the sheet three times its length */
    while (piola_world_time(world) < 0.5)
      assert_int_equal(
          piola_world_advance_to(world, fmin(0.5, piola_world_time(world) + 0.05), NULL), PIOLA_OK);
    const double *v = piola_world_shell_velocities(world, 0);
    const double *xs = piola_world_shell_positions(world, 0);
    double fastest = 0, farthest = 0;
    for (int i = 0; i < piola_shell_body_vertex_count(body); ++i) {
      for (int k = 0; k < 3; ++k) assert_true(isfinite(v[3 * i + k]) && isfinite(xs[3 * i + k]));
      fastest = fmax(fastest, sqrt(v[3 * i] * v[3 * i] + v[3 * i + 1] * v[3 * i + 1] +
                                   v[3 * i + 2] * v[3 * i + 2]));
      farthest = fmax(farthest, xs[3 * i]);
    }
    assert_true(fabs(farthest - 2.5) < 1e-9); /* the driven edge */
    /* no node faster than a few times the edge's speed: a blow-up reaches 1e100 */
    if (!(fastest < 40.0)) fail_msg("model %d: a node at %g m/s", mi, fastest);
    /* the stretched sheet is stiffer than at rest: its step is below the rest step */
    assert_true(piola_world_stable_dt(world) < 0.9 * rest);
    piola_world_destroy(world);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(membrane_modulus_bounds_every_wave),
      cmocka_unit_test(a_sheet_at_rest_keeps_its_rest_step),
      cmocka_unit_test(a_pulled_stvk_sheet_does_not_blow_up),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
