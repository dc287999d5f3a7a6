/* A solid that starts tangled waits to untangle before it takes part in self-collision
 * (docs/contact.md, "A tangled start"; src/sim/world_contact.c).
 *
 * - The surface test (src/contact/surface_intersection.c) agrees with the contact tests' exact
 *   referee, which tests every pair, on random triangle soups, and calls a surface collapsed
 *   to a point tangled.
 * - medit/unit_ball.mesh collapsed to a point, with self_collision, under backward Euler:
 *   the first step raises the "tangled start" warning; while the ball waits its run is the
 *   same, bit for bit, as the run without self_collision (it is in no collision surface);
 *   it joins within two seconds, re-expanded, and stays joined. The same ball from rest
 *   never waits and raises no warning.
 * - A checkpoint written while it waits reads into a world built the same way, which then
 *   runs on frame by frame bit for bit like the writer, waiting and joining in the same
 *   frames.
 * - Bodies placed through each other: the test across bodies agrees with the referee on
 *   random soups split in two; two balls overlapping, and a sheet through a ball, raise the
 *   "through each other" warning naming both; balls apart, or one without self_collision,
 *   raise none. Balls 5 mm apart with a 10 mm thickness raise the "within thickness"
 *   warning with their gap; 0.1 m apart, or through each other, they do not.
 * - An undamped solid collapsed to a point under the explicit step raises the "undamped
 *   tangle" warning (docs/cli.md), and what it says holds: after 1 s it is still tangled, its
 *   energy grown with the default extension and kept by the energy mode. Damped, under
 *   backward Euler, or from rest: no warning. */
#include "test_support.h"
#include "checkpoint_files.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "contact/surface_intersection.h"
#include "contact/triangle_intersection.h"
#include "piola/checkpoint.h"
#include "piola/elastic_body.h"
#include "piola/keyframes.h"
#include "piola/world.h"
#include "real_mesh_scenes.h"
#include "sim/world_internal.h"
#include "triangle_referee.h"

static double uniform(uint64_t *state) {
  *state = *state * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(*state >> 11) * 0x1.0p-53;
}

static void surface_test_agrees_with_the_referee(void **state) {
  (void)state;
  enum { TRIANGLES = 24, VERTICES = 3 * TRIANGLES };
  uint64_t seed = 7;
  int tangled = 0, free_ = 0;
  for (int soup = 0; soup < 400; ++soup) {
    double x[3 * VERTICES];
    int32_t tris[3 * TRIANGLES];
    /* small triangles in a box whose size varies, so that both answers occur */
    const double box = 0.5 + 4.0 * uniform(&seed);
    for (int v = 0; v < VERTICES; ++v) {
      const int anchor = v / 3 * 3; /* a triangle's corners near its first: small triangles */
      for (int d = 0; d < 3; ++d)
        x[3 * v + d] =
            v == anchor ? box * uniform(&seed) : x[3 * anchor + d] + 0.6 * uniform(&seed);
    }
    for (int t = 0; t < TRIANGLES; ++t) {
      for (int c = 0; c < 3; ++c) tris[3 * t + c] = 3 * t + c;
      /* some share a vertex with the one before: such pairs are exempt */
      if (t > 0 && uniform(&seed) < 0.3) tris[3 * t] = 3 * (t - 1) + 1;
    }
    const long pairs = referee_count_intersections_every_pair((judged){x, tris, TRIANGLES});
    const int found = piola__surface_intersects(x, tris, TRIANGLES);
    assert_int_equal(found, pairs > 0);
    tangled += found == 1, free_ += found == 0;
  }
  assert_true(tangled > 20 && free_ > 20); /* both answers were checked */
  /* collapsed to a point: every triangle degenerate, and the surface counts as tangled */
  double point[3 * 6] = {0};
  const int32_t two[6] = {0, 1, 2, 3, 4, 5};
  assert_int_equal(piola__surface_intersects(point, two, 2), 1);
}

static void surfaces_cross_agrees_with_the_referee(void **state) {
  (void)state;
  enum { TRIANGLES = 24, VERTICES = 3 * TRIANGLES, HALF = TRIANGLES / 2 };
  uint64_t seed = 11;
  int crossed = 0, apart = 0;
  for (int soup = 0; soup < 400; ++soup) {
    double x[3 * VERTICES];
    int32_t tris[3 * TRIANGLES], group[TRIANGLES];
    const double box = 0.5 + 4.0 * uniform(&seed);
    for (int v = 0; v < VERTICES; ++v) {
      const int anchor = v / 3 * 3;
      for (int d = 0; d < 3; ++d)
        x[3 * v + d] =
            v == anchor ? box * uniform(&seed) : x[3 * anchor + d] + 0.6 * uniform(&seed);
    }
    /* two bodies, each over its own vertices; inside each, some share a vertex */
    for (int t = 0; t < TRIANGLES; ++t) {
      for (int c = 0; c < 3; ++c) tris[3 * t + c] = 3 * t + c;
      if (t % HALF > 0 && uniform(&seed) < 0.3) tris[3 * t] = 3 * (t - 1) + 1;
      group[t] = t / HALF;
    }
    const judged first = {x, tris, HALF}, second = {x, tris + 3 * HALF, HALF};
    const judged both[2] = {first, second};
    const long across = referee_count_intersections(both, 2) -
                        referee_count_intersections(&first, 1) -
                        referee_count_intersections(&second, 1);
    int32_t pair[2] = {-1, -1};
    const int found = piola__surfaces_cross(x, tris, group, TRIANGLES, pair);
    assert_int_equal(found, across > 0);
    if (found == 1) {
      assert_true(pair[0] < HALF && pair[1] >= HALF);
      const double *p[3] = {x + 3 * tris[3 * pair[0]], x + 3 * tris[3 * pair[0] + 1],
                            x + 3 * tris[3 * pair[0] + 2]};
      const double *q[3] = {x + 3 * tris[3 * pair[1]], x + 3 * tris[3 * pair[1] + 1],
                            x + 3 * tris[3 * pair[1] + 2]};
      assert_int_not_equal(piola__triangles_intersect(p, q), 0); /* the pair it names */
    }
    crossed += found == 1, apart += found == 0;
  }
  assert_true(crossed > 20 && apart > 20);
}

/* Two unit balls (radius 1 m) with their centres `gap` apart along x, the second with
 * self_collision or without, and (sheet) a sheet through the first ball's equator. */
static piola_world *two_bodies_world(const piola_tet_mesh *mesh, double gap, int second_collides,
                                     int sheet) {
  piola_world_def wd = piola_default_world_def();
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_tet_mesh moved = *mesh;
  double *x = malloc(sizeof(double) * 3 * (size_t)mesh->vertex_count);
  assert_non_null(x);
  for (int32_t i = 0; i < 3 * mesh->vertex_count; ++i)
    x[i] = mesh->positions[i] + (i % 3 == 0 ? gap : 0);
  moved.positions = x;
  piola_solid_def sd = piola_default_solid_def();
  sd.self_collision.enabled = 1;
  sd.self_collision.thickness = 0.01;
  sd.mesh = mesh, sd.name = "first";
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  sd.mesh = &moved, sd.name = "second", sd.self_collision.enabled = second_collides;
  if (gap < 1e3) assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  free(x);
  if (sheet) {
    piola_tri_mesh rectangle;
    /* 3 m square in z = 0, centred on the origin: through the first ball's equator */
    assert_int_equal(piola_tri_mesh_rectangle(3, 3, 4, 4, &rectangle), PIOLA_OK);
    piola_shell_def hd = piola_default_shell_def();
    hd.mesh = &rectangle, hd.name = "sheet";
    hd.self_collision.enabled = 1;
    hd.self_collision.thickness = 0.01;
    assert_int_equal(piola_world_add_shell(w, &hd, NULL), PIOLA_OK);
    piola_tri_mesh_free(&rectangle);
  }
  return w;
}

/* The warning of kind after the first step, or NULL. */
static char *warning_after_a_step(piola_world *w, piola_warning_kind kind) {
  assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
  const char *text = piola_world_warning(w, kind);
  char *copy = text ? strdup(text) : NULL;
  piola_world_destroy(w);
  return copy;
}

/* The warning after the first step, or NULL. */
static char *through_each_other_after_a_step(piola_world *w) {
  assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
  const char *text = piola_world_warning(w, PIOLA_WARNING_BODIES_CROSS);
  char *copy = text ? strdup(text) : NULL;
  piola_world_destroy(w);
  return copy;
}

static void bodies_through_each_other_are_named(void **state) {
  (void)state;
  piola_tet_mesh mesh = real_mesh_read("medit/unit_ball.mesh");
  char *overlap = through_each_other_after_a_step(two_bodies_world(&mesh, 1.2, 1, 0));
  assert_non_null(overlap);
  assert_non_null(strstr(overlap, "solid 'first' and solid 'second' start through each other"));
  free(overlap);
  /* apart by a tenth of a radius: nothing to report */
  assert_null(through_each_other_after_a_step(two_bodies_world(&mesh, 2.1, 1, 0)));
  /* overlapping, but the second is in no collision surface: nothing collides, nothing holds */
  assert_null(through_each_other_after_a_step(two_bodies_world(&mesh, 1.2, 0, 0)));
  /* a sheet through the one ball */
  char *sheet = through_each_other_after_a_step(two_bodies_world(&mesh, 1e9, 1, 1));
  assert_non_null(sheet);
  assert_non_null(strstr(sheet, "solid 'first' and shell 'sheet'"));
  free(sheet);

  /* apart, but closer than their thickness (0.01 m): the other warning, with the gap */
  char *close =
      warning_after_a_step(two_bodies_world(&mesh, 2.005, 1, 0), PIOLA_WARNING_WITHIN_THICKNESS);
  assert_non_null(close);
  assert_non_null(strstr(close, "solid 'second' and solid 'first' start 0.005 m apart") ||
                  strstr(close, "solid 'first' and solid 'second' start 0.005 m apart"));
  assert_non_null(strstr(close, "closer than their collision thickness 0.01 m"));
  free(close);
  /* a tenth of a radius apart, or through each other (the crossing's own warning): none */
  assert_null(
      warning_after_a_step(two_bodies_world(&mesh, 2.1, 1, 0), PIOLA_WARNING_WITHIN_THICKNESS));
  assert_null(
      warning_after_a_step(two_bodies_world(&mesh, 1.2, 1, 0), PIOLA_WARNING_WITHIN_THICKNESS));
  piola_tet_mesh_free(&mesh);
}

/* The ball under backward Euler, no gravity, collapsed to a point (collapse) or at rest,
 * with self_collision or without. */
static piola_world *ball_world(const piola_tet_mesh *mesh, int collapse, int self_collision) {
  piola_world_def wd = piola_default_world_def();
  wd.integrator = PIOLA_INTEGRATOR_BACKWARD_EULER;
  wd.implicit_dt = 1.0 / 30;
  for (int k = 0; k < 3; ++k) wd.gravity[k] = piola_track_constant(0);
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = mesh;
  sd.material.youngs_modulus = 1e5;
  sd.shear_viscosity = piola_track_constant(20);
  sd.bulk_viscosity = piola_track_constant(20);
  if (collapse) memset(&sd.initial_matrix, 0, sizeof sd.initial_matrix);
  sd.self_collision.enabled = self_collision;
  sd.self_collision.thickness = 0.01;
  if (piola_world_add_solid(w, &sd, NULL) != PIOLA_OK) fail_msg("%s", piola_last_error());
  return w;
}

static int waits(const piola_world *w) { return w->bodies[0].collision_waits; }

static double solid_diagonal(const piola_world *w) {
  return piola__bounding_diagonal(piola_elastic_body_vertex_count(piola_world_solid_body(w, 0)),
                                  piola_world_solid_positions(w, 0));
}

static void collapsed_ball_waits_then_joins(void **state) {
  (void)state;
  piola_tet_mesh mesh = real_mesh_read("medit/unit_ball.mesh");
  const double rest = real_mesh_diagonal(&mesh);
  piola_world *a = ball_world(&mesh, 1, 1), *b = ball_world(&mesh, 1, 0);
  piola_world *r = ball_world(&mesh, 0, 1);
  char file[4096];
  checkpoint_temp_file(file, sizeof file, "piola_tangled_start");
  const uint64_t key = piola_world_scene_key(a, NULL, 0);
  enum { FRAMES = 60, AFTER = 6 };
  int joined_at = -1, saved = 0, waited[FRAMES + AFTER + 1] = {0};
  for (int frame = 1; frame <= FRAMES && joined_at < 0; ++frame) {
    assert_int_equal(piola_world_advance_to(a, frame / 30.0, NULL), PIOLA_OK);
    assert_true(real_mesh_solid_finite(a));
    if (frame == 1) {
      const char *text = piola_world_warning(a, PIOLA_WARNING_TANGLED_START);
      assert_non_null(text);
      assert_non_null(strstr(text, "starts tangled"));
      assert_true(waits(a));
      assert_int_equal(piola_world_checkpoint_write(a, file, key, frame), PIOLA_OK);
      saved = frame;
    }
    waited[frame] = waits(a);
    if (waits(a)) { /* in no collision surface: the run without self_collision */
      assert_int_equal(piola_world_advance_to(b, frame / 30.0, NULL), PIOLA_OK);
      checkpoint_same_solid_state(a, b);
    } else {
      joined_at = frame;
    }
  }
  if (joined_at < 0) fail_msg("the collapsed ball still waits after 2 s");
  if (getenv("PIOLA_TEST_VERBOSE"))
    print_message("joined in frame %d, diagonal %.4g of rest %.4g\n", joined_at, solid_diagonal(a),
                  rest);
  assert_true(solid_diagonal(a) > 0.9 * rest); /* re-expanded */
  for (int frame = joined_at + 1; frame <= joined_at + AFTER; ++frame) {
    assert_int_equal(piola_world_advance_to(a, frame / 30.0, NULL), PIOLA_OK);
    assert_false(waits(a)); /* joined for good */
  }

  /* the checkpoint of frame 1, read into a world built the same way: frame by frame, as the
   * writer went on, it waits and joins in the same frames, with the same bits */
  piola_world *c = ball_world(&mesh, 1, 1);
  int32_t frame = -1;
  assert_int_equal(piola_world_checkpoint_read(c, file, key, &frame), PIOLA_OK);
  assert_int_equal(frame, saved);
  assert_true(waits(c));
  for (int f = saved + 1; f <= joined_at + AFTER; ++f) {
    assert_int_equal(piola_world_advance_to(c, f / 30.0, NULL), PIOLA_OK);
    assert_int_equal(waits(c), waited[f]);
  }
  checkpoint_same_solid_state(a, c);
  unlink(file);

  /* from rest: never waits, no warning */
  assert_int_equal(piola_world_advance_to(r, 3.0 / 30, NULL), PIOLA_OK);
  assert_false(waits(r));
  assert_null(piola_world_warning(r, PIOLA_WARNING_TANGLED_START));
  piola_world_destroy(a), piola_world_destroy(b), piola_world_destroy(c), piola_world_destroy(r);
  piola_tet_mesh_free(&mesh);
}

/* Medit's unit ball scaled to a 2 m diagonal, corotated at E = 20 kPa, collapsed to a point,
 * with the model's default extension or the energy mode, the viscosity (Pa s, shear and bulk)
 * and integrator given. */
static piola_world *collapsed_world(const piola_tet_mesh *mesh, piola_inversion_mode mode,
                                    double viscosity, piola_integrator_type integrator) {
  static const piola_mat3 point = {{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}};
  real_mesh_scramble scene = {.material = real_mesh_material_def(PIOLA_MODEL_COROTATED, 2e4, 0.3),
                              .viscosity = viscosity,
                              .integrator = integrator,
                              .start_matrix = &point};
  scene.material.inversion_mode = mode;
  piola_world *w = real_mesh_scramble_world(mesh, &scene);
  if (!w) fail_msg("%s", piola_last_error());
  return w;
}

/* The "undamped tangle" warning, and what it says: undamped, the collapsed ball does not
 * settle under the explicit step; with the default extension its energy grows, in the energy
 * mode it stays. */
static void undamped_tangle_is_warned(void **state) {
  (void)state;
  piola_tet_mesh mesh = real_mesh_scaled("medit/unit_ball.mesh", 2.0);
  piola_world *linear =
      collapsed_world(&mesh, PIOLA_INVERSION_MODEL_DEFAULT, 0, PIOLA_INTEGRATOR_NEWMARK);
  piola_world *energy = collapsed_world(&mesh, PIOLA_INVERSION_ENERGY, 0, PIOLA_INTEGRATOR_NEWMARK);
  /* 1 s at 20 frames per second (0.25 s under PIOLA_TEST_SCALE below 1) */
  const int frames = test_scale() < 1 ? 5 : 20;
  double start[2] = {0, 0}, last[2] = {0, 0};
  for (int frame = 1; frame <= frames; ++frame) {
    piola_world *w[2] = {linear, energy};
    for (int k = 0; k < 2; ++k) {
      if (frame == 1) start[k] = real_mesh_total_energy(w[k]);
      assert_int_equal(piola_world_advance_to(w[k], frame / 20.0, NULL), PIOLA_OK);
      assert_true(real_mesh_solid_finite(w[k]));
      last[k] = real_mesh_total_energy(w[k]);
      /* still tangled: no damping took the energy that would let it untangle */
      assert_true(piola_world_solid_stats(w[k], 0).inverted_count > 50);
    }
  }
  if (getenv("PIOLA_TEST_VERBOSE"))
    print_message("energy %.4g -> %.4g J (linear), %.4g -> %.4g J (energy mode)\n", start[0],
                  last[0], start[1], last[1]);
  assert_true(fabs(last[1] - start[1]) < 0.01 * start[1]); /* the energy mode keeps it */
  assert_true(last[0] > start[0]);                         /* the default extension adds to it */
  const char *text = piola_world_warning(linear, PIOLA_WARNING_UNDAMPED_TANGLE);
  assert_non_null(text);
  assert_non_null(strstr(text, "solid 'solid0' starts tangled"));
  assert_non_null(strstr(text, "not the gradient of an energy"));
  text = piola_world_warning(energy, PIOLA_WARNING_UNDAMPED_TANGLE);
  assert_non_null(text);
  assert_null(strstr(text, "not the gradient of an energy")); /* the energy mode's is */
  piola_world_destroy(linear), piola_world_destroy(energy);

  /* damped, or under backward Euler, or from rest: nothing to warn of */
  piola_world *quiet[3] = {
      collapsed_world(&mesh, PIOLA_INVERSION_MODEL_DEFAULT, 20, PIOLA_INTEGRATOR_NEWMARK),
      collapsed_world(&mesh, PIOLA_INVERSION_MODEL_DEFAULT, 0, PIOLA_INTEGRATOR_BACKWARD_EULER),
      NULL};
  real_mesh_scramble rest = {.material = real_mesh_material_def(PIOLA_MODEL_COROTATED, 2e4, 0.3)};
  quiet[2] = real_mesh_scramble_world(&mesh, &rest);
  for (int k = 0; k < 3; ++k) {
    assert_non_null(quiet[k]);
    assert_int_equal(piola_world_advance_to(quiet[k], 1.0 / 30, NULL), PIOLA_OK);
    assert_null(piola_world_warning(quiet[k], PIOLA_WARNING_UNDAMPED_TANGLE));
    piola_world_destroy(quiet[k]);
  }
  piola_tet_mesh_free(&mesh);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(surface_test_agrees_with_the_referee),
      cmocka_unit_test(collapsed_ball_waits_then_joins),
      cmocka_unit_test(surfaces_cross_agrees_with_the_referee),
      cmocka_unit_test(bodies_through_each_other_are_named),
      cmocka_unit_test(undamped_tangle_is_warned),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
