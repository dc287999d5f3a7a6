/* Muscle fibres in an elastic body and in a world: the blocked force loop's fibre hook
 * agrees with the scalar reference (which goes through the public diagonal-frame functions),
 * forces are minus the gradient of the body's energy (fibre energy included), inverted tets
 * with active fibres are pushed back, the CFL wave speed counts the fibres, bad fibres are
 * rejected by tet, and an activated bar held at one end shortens along its fibres and
 * bulges sideways. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "force/elastic_body_internal.h"
#include "support/elastic_referees.h"
#include "piola/world.h"
#include "test_elastic_body_fixtures.h"

static piola_material muscle(double youngs) {
  piola_material_def def = piola_default_material_def();
  def.model = PIOLA_MODEL_MUSCLE;
  def.youngs_modulus = youngs;
  def.poisson_ratio = 0.45;
  def.muscle.max_active_stress = 4e4;
  def.muscle.passive_stiffness = 5e4;
  def.muscle.optimal_stretch = 1.02;
  piola_material m;
  assert_int_equal(piola_material_init(&def, &m), PIOLA_OK);
  return m;
}

static double *random_fibers(test_rng *rng, int32_t tets) {
  double *a = malloc(sizeof(double) * 3 * (size_t)tets);
  for (int32_t i = 0; i < 3 * tets; ++i) a[i] = test_rng_uniform(rng, -1, 1);
  for (int32_t t = 0; t < tets; ++t) a[3 * t] += 0.01; /* never zero */
  return a;
}

static void fast_loop_matches_reference_with_fibres(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(91);
  piola_tet_mesh mesh = fixture_grid(3, 0.1);
  const int n = 3 * mesh.vertex_count;
  double *fibers = random_fibers(&rng, mesh.tet_count);
  piola_material mats[2] = {muscle(3e4), fixture_material(PIOLA_MODEL_NEOHOOKEAN)};
  int32_t *which = malloc(sizeof(int32_t) * (size_t)mesh.tet_count);
  for (int32_t t = 0; t < mesh.tet_count; ++t) which[t] = t % 5 == 2;
  double *x = malloc(sizeof(double) * (size_t)n), *f = malloc(sizeof(double) * (size_t)n);
  double *g = malloc(sizeof(double) * (size_t)n);
  for (int mixed = 0; mixed < 2; ++mixed) {
    piola_elastic_body *body = fixture_body_with_fibers(&mesh, mats, mixed ? 2 : 1, mixed ? which : NULL, fibers);
    for (int s = 0; s < 4; ++s) {
      for (int i = 0; i < n; ++i) x[i] = mesh.positions[i] * (1.05 + 0.2 * s) + 0.01 * (s + 1) * test_rng_uniform(&rng, -1, 1);
      if (s == 3) /* flatten a layer and invert some tets */
        for (int v = 0; v < 16; ++v) x[3 * v + 2] = 0.12 - 0.1 * (v % 3);
      piola_elastic_body_set_activation(body, 0.3 * s);
      piola_elastic_stats fast, ref;
      assert_int_equal(piola_elastic_body_update(body, x, 0.8, f, &fast), PIOLA_OK);
      assert_int_equal(piola__elastic_body_update_reference(body, x, 0.8, g, &ref), PIOLA_OK);
      const double scale = fixture_max_abs(g, n);
      for (int i = 0; i < n; ++i)
        if (!(fabs(f[i] - g[i]) <= 1e-9 * scale + 1e-12))
          fail_msg("mixed %d sample %d dof %d: fast %.15g, reference %.15g", mixed, s, i, f[i], g[i]);
      assert_close(fast.elastic_energy, ref.elastic_energy, 1e-9 * fabs(ref.elastic_energy));
      if (s == 3) assert_true(fast.inverted_count > 0);
      /* the per-tet energy, computed lazily after an update without stats, counts the fibres */
      const double *e = piola_elastic_body_energy_density(body);
      double *saved = malloc(sizeof(double) * (size_t)mesh.tet_count);
      memcpy(saved, e, sizeof(double) * (size_t)mesh.tet_count);
      assert_int_equal(piola_elastic_body_update(body, x, 0.8, f, NULL), PIOLA_OK);
      e = piola_elastic_body_energy_density(body);
      for (int32_t t = 0; t < mesh.tet_count; ++t)
        assert_close(e[t], saved[t], 1e-9 * (fabs(saved[t]) + 1));
      free(saved);
    }
    piola_elastic_body_destroy(body);
  }
  free(which);
  free(fibers);
  free(x);
  free(f);
  free(g);
  fixture_mesh_free(&mesh);
}

/* f = -dE/dx by central differences of the body's energy, with active fibres pointing
 * every way. Deformations stay above the inversion threshold, where the whole model has a
 * potential. */
static void forces_are_minus_the_energy_gradient(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(92);
  piola_tet_mesh mesh = fixture_grid(2, 0.1);
  const int n = 3 * mesh.vertex_count;
  double *fibers = random_fibers(&rng, mesh.tet_count);
  const piola_material m = muscle(3e4);
  piola_elastic_body *body = fixture_body_with_fibers(&mesh, &m, 1, NULL, fibers);
  double *x = malloc(sizeof(double) * (size_t)n), *f = malloc(sizeof(double) * (size_t)n);
  for (int s = 0; s < 3; ++s) {
    /* a stretch along x (fibres past the toe) plus noise */
    for (int i = 0; i < n; ++i)
      x[i] = mesh.positions[i] * (i % 3 == 0 ? 1.1 + 0.1 * s : 0.95) + 0.01 * test_rng_uniform(&rng, -1, 1);
    piola_elastic_body_set_activation(body, 0.25 + 0.3 * s);
    piola_elastic_stats st;
    assert_int_equal(piola_elastic_body_update(body, x, 1.0, f, &st), PIOLA_OK);
    assert_int_equal(st.inverted_count, 0);
    char what[32];
    snprintf(what, sizeof what, "sample %d", s);
    fixture_check_energy_gradient(body, x, n, f, 1e-7, 1e-5, what);
  }
  piola_elastic_body_destroy(body);
  free(fibers);
  free(x);
  free(f);
  fixture_mesh_free(&mesh);
}

/* Rotating the rest mesh and its fibres by R (material) and the deformed positions by Q
 * (world) rotates the forces by Q: the fibre rotates with the material. Rotating the mesh
 * but not the fibres changes them (the fibres are anisotropic). */
static void forces_rotate_with_world_and_material(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(94);
  piola_tet_mesh mesh = fixture_grid(2, 0.1), turned = fixture_grid(2, 0.1);
  const int n = 3 * mesh.vertex_count;
  double *fibers = random_fibers(&rng, mesh.tet_count);
  double *turned_fibers = malloc(sizeof(double) * 3 * (size_t)mesh.tet_count);
  const double c = cos(0.7), s = sin(0.7), c2 = cos(-1.1), s2 = sin(-1.1);
  const double r[3][3] = {{c, -s, 0}, {s, c, 0}, {0, 0, 1}};   /* material rotation */
  const double q[3][3] = {{1, 0, 0}, {0, c2, -s2}, {0, s2, c2}}; /* world rotation */
  for (int32_t v = 0; v < mesh.vertex_count; ++v)
    for (int i = 0; i < 3; ++i)
      turned.positions[3 * v + i] = r[i][0] * mesh.positions[3 * v] + r[i][1] * mesh.positions[3 * v + 1] +
                                    r[i][2] * mesh.positions[3 * v + 2];
  for (int32_t t = 0; t < mesh.tet_count; ++t)
    for (int i = 0; i < 3; ++i)
      turned_fibers[3 * t + i] = r[i][0] * fibers[3 * t] + r[i][1] * fibers[3 * t + 1] + r[i][2] * fibers[3 * t + 2];
  const piola_material m = muscle(3e4);
  piola_elastic_body *a = fixture_body_with_fibers(&mesh, &m, 1, NULL, fibers);
  piola_elastic_body *b = fixture_body_with_fibers(&turned, &m, 1, NULL, turned_fibers);
  piola_elastic_body *wrong = fixture_body_with_fibers(&turned, &m, 1, NULL, fibers);
  double *x = malloc(sizeof(double) * (size_t)n), *y = malloc(sizeof(double) * (size_t)n);
  double *fa = malloc(sizeof(double) * (size_t)n), *fb = malloc(sizeof(double) * (size_t)n);
  for (int i = 0; i < n; ++i)
    x[i] = mesh.positions[i] * (i % 3 == 1 ? 1.2 : 0.9) + 0.02 * test_rng_uniform(&rng, -1, 1);
  for (int v = 0; v < 3; ++v) x[3 * v + 2] = 0.15; /* a few flattened and inverted tets */
  for (int32_t v = 0; v < mesh.vertex_count; ++v)
    for (int i = 0; i < 3; ++i)
      y[3 * v + i] = q[i][0] * x[3 * v] + q[i][1] * x[3 * v + 1] + q[i][2] * x[3 * v + 2];
  piola_elastic_body_set_activation(a, 0.8);
  piola_elastic_body_set_activation(b, 0.8);
  piola_elastic_body_set_activation(wrong, 0.8);
  piola_elastic_stats sa, sb;
  assert_int_equal(piola_elastic_body_update(a, x, 1.0, fa, &sa), PIOLA_OK);
  assert_int_equal(piola_elastic_body_update(b, y, 1.0, fb, &sb), PIOLA_OK);
  assert_true(sa.inverted_count > 0);
  const double scale = fixture_max_abs(fa, n);
  for (int32_t v = 0; v < mesh.vertex_count; ++v)
    for (int i = 0; i < 3; ++i) {
      const double expect = q[i][0] * fa[3 * v] + q[i][1] * fa[3 * v + 1] + q[i][2] * fa[3 * v + 2];
      assert_close(fb[3 * v + i], expect, 1e-9 * scale);
    }
  assert_close(sb.elastic_energy, sa.elastic_energy, 1e-9 * fabs(sa.elastic_energy));
  assert_int_equal(piola_elastic_body_update(wrong, y, 1.0, fb, NULL), PIOLA_OK);
  double differ = 0;
  for (int32_t v = 0; v < mesh.vertex_count; ++v)
    for (int i = 0; i < 3; ++i)
      differ = fmax(differ, fabs(fb[3 * v + i] - (q[i][0] * fa[3 * v] + q[i][1] * fa[3 * v + 1] +
                                                   q[i][2] * fa[3 * v + 2])));
  assert_true(differ > 1e-3 * scale);
  piola_elastic_body_destroy(a);
  piola_elastic_body_destroy(b);
  piola_elastic_body_destroy(wrong);
  free(fibers);
  free(turned_fibers);
  free(x);
  free(y);
  free(fa);
  free(fb);
  fixture_mesh_free(&mesh);
  fixture_mesh_free(&turned);
}

/* A single tet with its apex pushed through the opposite face, fibres active in every
 * direction: the apex's force is finite and points back through the face. */
static void inverted_tet_with_active_fibres_is_pushed_back(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(93);
  piola_tet_mesh mesh = fixture_single_tet(1.0);
  piola_material_def def = piola_default_material_def();
  def.model = PIOLA_MODEL_MUSCLE;
  def.youngs_modulus = 1e4; /* soft matrix, strong fibres */
  def.poisson_ratio = 0.45;
  def.muscle.max_active_stress = 5e5;
  piola_material m;
  assert_int_equal(piola_material_init(&def, &m), PIOLA_OK);
  const long samples = test_samples(400, 20);
  for (long k = 0; k < samples; ++k) {
    double a[3] = {test_rng_normal(&rng), test_rng_normal(&rng), test_rng_normal(&rng) + 1e-3};
    piola_elastic_body *body = fixture_body_with_fibers(&mesh, &m, 1, NULL, a);
    piola_elastic_body_set_activation(body, test_rng_uniform(&rng, 0.5, 1.0));
    /* below depth ~1 (the size of the tet) the smallest entry of Fhat is the inverted one;
     * deeper, the diagonalization's guess of the inverted direction (paper section 5) no
     * longer points along z, with or without fibres */
    int32_t inverted;
    const double depth = fixture_check_apex_pushed_back(body, &mesh, &rng, a, &inverted);
    if (depth > 0) assert_int_equal(inverted, 1);
    piola_elastic_body_destroy(body);
  }
  fixture_mesh_free(&mesh);
}

static void fibres_are_checked_and_counted_in_the_wave_speed(void **state) {
  (void)state;
  piola_tet_mesh mesh = fixture_grid(1, 1.0);
  const piola_material m = muscle(3e4);
  double *fibers = calloc(3 * (size_t)mesh.tet_count, sizeof(double));
  for (int32_t t = 0; t < mesh.tet_count; ++t) fibers[3 * t] = 2.0;
  fibers[3 * 4] = 0.0; /* tet 4 has a zero fibre */
  piola_elastic_body_def def = piola_default_elastic_body_def();
  def.rest_mesh = &mesh;
  def.materials = &m;
  def.material_count = 1;
  def.fiber_directions = fibers;
  piola_elastic_body *body = NULL;
  assert_int_equal(piola_elastic_body_create(&def, &body), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "tet 4"));
  fibers[3 * 4 + 1] = NAN;
  assert_int_equal(piola_elastic_body_create(&def, &body), PIOLA_ERROR_NOT_FINITE);
  assert_non_null(strstr(piola_last_error(), "tet 4"));
  fibers[3 * 4 + 1] = -3.0;
  assert_int_equal(piola_elastic_body_create(&def, &body), PIOLA_OK);
  /* normalised copy */
  const double *a = piola_elastic_body_fiber_directions(body);
  assert_close(a[0], 1.0, 1e-15);
  assert_close(a[3 * 4 + 1], -1.0, 1e-15);
  const double plain = sqrt((m.lambda + 2 * m.mu) / def.density);
  assert_true(m.fiber_modulus > 0);
  assert_close(piola_elastic_body_max_wave_speed(body),
               sqrt((m.lambda + 2 * m.mu + m.fiber_modulus) / def.density), 1e-12);
  assert_true(piola_elastic_body_max_wave_speed(body) > plain);
  /* activation is clamped */
  piola_elastic_body_set_activation(body, 3.0);
  assert_true(piola_elastic_body_activation(body) == 1.0);
  piola_elastic_body_set_activation(body, NAN);
  assert_true(piola_elastic_body_activation(body) == 0.0);
  piola_elastic_body_destroy(body);
  /* no fibres: none reported */
  def.fiber_directions = NULL;
  assert_int_equal(piola_elastic_body_create(&def, &body), PIOLA_OK);
  assert_null(piola_elastic_body_fiber_directions(body));
  piola_elastic_body_destroy(body);
  free(fibers);
  fixture_mesh_free(&mesh);
}

typedef struct bar_shape {
  double free_end_x;  /* mean x of the free end face, m */
  double mid_width;   /* mean |y - 0.01| + |z - 0.01| over the middle cross-section, m */
  double volume;      /* m^3 */
} bar_shape;

/* A 6 x 2 x 2 cm bar along x with fibres along x, its x = 0 face fixed, no gravity,
 * activation ramped from 0 to `activation` over 0.05 s, run to 0.4 s. */
static bar_shape run_bar(double activation) {
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(6, 2, 2, (piola_vec3){0.01, 0.01, 0.01}, &mesh), PIOLA_OK);
  double *fibers = malloc(sizeof(double) * 3 * (size_t)mesh.tet_count);
  for (int32_t t = 0; t < mesh.tet_count; ++t) fibers[3 * t] = 1, fibers[3 * t + 1] = fibers[3 * t + 2] = 0;
  piola_world_def wdef = piola_default_world_def();
  for (int k = 0; k < 3; ++k) wdef.gravity[k] = piola_track_constant(0);
  piola_world *world;
  assert_int_equal(piola_world_create(&wdef, &world), PIOLA_OK);
  piola_solid_def sdef = piola_default_solid_def();
  sdef.mesh = &mesh;
  sdef.material.model = PIOLA_MODEL_MUSCLE;
  sdef.material.youngs_modulus = 2e4;
  sdef.material.poisson_ratio = 0.45;
  sdef.material.muscle.max_active_stress = 2e4;
  sdef.shear_viscosity = piola_track_constant(5);
  sdef.fiber_directions = fibers;
  const double times[2] = {0.0, 0.05}, values[2] = {0.0, activation};
  assert_int_equal(piola_track_from_keys(times, values, 2, &sdef.activation), PIOLA_OK);
  piola_constraint_def fixed;
  memset(&fixed, 0, sizeof fixed);
  fixed.selector.type = PIOLA_SELECT_BOX;
  fixed.selector.box_min = (piola_vec3){-1e-3, -1, -1};
  fixed.selector.box_max = (piola_vec3){1e-3, 1, 1};
  sdef.constraints = &fixed;
  sdef.constraint_count = 1;
  assert_int_equal(piola_world_add_solid(world, &sdef, NULL), PIOLA_OK);
  assert_int_equal(piola_world_advance_to(world, 0.4, NULL), PIOLA_OK);
  const double *x = piola_world_solid_positions(world, 0);
  bar_shape shape = {0, 0, 0};
  int ends = 0, mids = 0;
  for (int32_t v = 0; v < mesh.vertex_count; ++v) {
    const double *r = mesh.positions + 3 * v;
    if (r[0] > 0.06 - 1e-9) shape.free_end_x += x[3 * v], ++ends;
    if (fabs(r[0] - 0.03) < 1e-9)
      shape.mid_width += fabs(x[3 * v + 1] - 0.01) + fabs(x[3 * v + 2] - 0.01), ++mids;
  }
  shape.free_end_x /= ends;
  shape.mid_width /= mids;
  for (int32_t t = 0; t < mesh.tet_count; ++t) {
    const int32_t *i = mesh.tets + 4 * t;
    double d[3][3];
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) d[c][k] = x[3 * i[c + 1] + k] - x[3 * i[0] + k];
    shape.volume += fabs(d[0][0] * (d[1][1] * d[2][2] - d[1][2] * d[2][1]) -
                         d[0][1] * (d[1][0] * d[2][2] - d[1][2] * d[2][0]) +
                         d[0][2] * (d[1][0] * d[2][1] - d[1][1] * d[2][0])) / 6;
  }
  piola_world_destroy(world);
  free(fibers);
  piola_tet_mesh_free(&mesh);
  return shape;
}

static void activated_bar_shortens_along_its_fibres_and_bulges(void **state) {
  (void)state;
  const bar_shape passive = run_bar(0.0), half = run_bar(0.5), full = run_bar(1.0);
  print_message("bar 6 cm, free end x: passive %.5f, a=0.5 %.5f, a=1 %.5f m; mid width %.5f, "
                "%.5f, %.5f m; volume change at a=1 %.3f%%\n", passive.free_end_x, half.free_end_x,
                full.free_end_x, passive.mid_width, half.mid_width, full.mid_width,
                100 * (full.volume / (0.06 * 0.02 * 0.02) - 1));
  /* passive and unloaded: stays at rest (rest mid width: 4 corners at 0.02, 4 edge mids at
   * 0.01, 1 centre at 0 -> 0.12 / 9) */
  assert_close(passive.free_end_x, 0.06, 1e-9);
  assert_close(passive.mid_width, 0.12 / 9, 1e-9);
  /* activated: shorter along x, wider across, more so at full activation */
  assert_true(half.free_end_x < 0.06 - 1e-4);
  assert_true(full.free_end_x < half.free_end_x - 1e-4);
  assert_true(half.mid_width > passive.mid_width * 1.005);
  assert_true(full.mid_width > half.mid_width);
  /* quasi-incompressible (nu = 0.45): the volume changes far less than the length */
  const double rest_volume = 0.06 * 0.02 * 0.02;
  const double length_change = 1 - full.free_end_x / 0.06;
  const double volume_change = fabs(full.volume / rest_volume - 1);
  assert_true(volume_change < 0.5 * length_change);
}

static void world_checks_activation_and_fibres(void **state) {
  (void)state;
  piola_tet_mesh mesh = fixture_grid(1, 1.0);
  piola_world_def wdef = piola_default_world_def();
  piola_world *world;
  assert_int_equal(piola_world_create(&wdef, &world), PIOLA_OK);
  piola_solid_def sdef = piola_default_solid_def();
  sdef.mesh = &mesh;
  sdef.material.model = PIOLA_MODEL_MUSCLE;
  sdef.activation = piola_track_constant(1.5);
  assert_int_equal(piola_world_add_solid(world, &sdef, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "activation"));
  sdef.activation = piola_track_constant(0.5);
  /* a material out of range names the solid it was meant for, as the other checks do */
  sdef.material.poisson_ratio = 0.5;
  assert_int_equal(piola_world_add_solid(world, &sdef, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "solid 0: material: poisson_ratio must be in"));
  sdef.material.poisson_ratio = 0.3;
  double *fibers = calloc(3 * (size_t)mesh.tet_count, sizeof(double)); /* all zero */
  sdef.fiber_directions = fibers;
  assert_int_equal(piola_world_add_solid(world, &sdef, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "tet 0"));
  for (int32_t t = 0; t < mesh.tet_count; ++t) fibers[3 * t + 2] = 1;
  assert_int_equal(piola_world_add_solid(world, &sdef, NULL), PIOLA_OK);
  assert_true(piola_elastic_body_activation(piola_world_solid_body(world, 0)) == 0.5);
  piola_plasticity_def plastic = piola_default_plasticity_def();
  sdef.plasticity = &plastic;
  assert_int_equal(piola_world_add_solid(world, &sdef, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "plasticity"));
  piola_world_destroy(world);
  free(fibers);
  fixture_mesh_free(&mesh);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(fast_loop_matches_reference_with_fibres),
      cmocka_unit_test(forces_are_minus_the_energy_gradient),
      cmocka_unit_test(forces_rotate_with_world_and_material),
      cmocka_unit_test(inverted_tet_with_active_fibres_is_pushed_back),
      cmocka_unit_test(fibres_are_checked_and_counted_in_the_wave_speed),
      cmocka_unit_test(activated_bar_shortens_along_its_fibres_and_bulges),
      cmocka_unit_test(world_checks_activation_and_fibres),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
