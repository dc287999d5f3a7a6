/* The implicit integrators (src/sim/implicit_step.c) through the public world API:
 *  - the defaults (Newmark stays the default), the names, and invalid parameters refused;
 *  - the scene keys: integrator.type, integrator.dt defaulting to the frame time, a bad type
 *    refused by its key path, free fall in one step; the iteration caps accept their
 *    documented range [1, 1000000] and refuse one more, naming the key;
 *  - backward Euler, free flight: a stretched, spinning block keeps its linear momentum to
 *    1e-10 (damped or not, every isotropic model) at one step per 1/30 s frame, and its total
 *    energy never grows (backward Euler only dissipates);
 *  - a block dropped on the ground at one step per frame comes to rest on it with no node
 *    below it;
 *  - on a 0.5 rad incline a block with mu = 0.2 slides at g (sin - mu cos) within 10%, and one
 *    with mu = 0.8 > tan(0.5) stays put, at 1/120 s and (mu = 0.2, 0.4, 0.8) at 1/30 s;
 *  - two balls meeting with self-collision, equal and head-on or unequal and off-centre,
 *    keep their total momentum; a box dropped on or sliding on a box, both with
 *    self-collision, gains no energy and comes to rest;
 *  - a frame whose every step fails Newton ends, in at most 8 steps; a step whose Newton
 *    converges at its last allowed iteration is converged, not failed; a non-finite
 *    residual ends the step with PIOLA_ERROR_NOT_FINITE. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "block_scenes.h"
#include "piola/mesh.h"
#include "piola/mesh_io.h"
#include "piola/scene.h"
#include "piola/world.h"

static piola_world *make_world(piola_integrator_type type, double gz, double dt) {
  piola_world_def wd = piola_default_world_def();
  wd.gravity[2] = piola_track_constant(gz);
  wd.integrator = type;
  wd.implicit_dt = dt;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  return w;
}

static void free_flight(piola_material_model model, int damped) {
  piola_world *w = make_world(PIOLA_INTEGRATOR_BACKWARD_EULER, 0, 1.0 / 30);
  piola_tet_mesh mesh = block_mesh(3, 2, 2, 0.3, 0.2, 0.2);
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = &mesh;
  sd.material.model = model;
  sd.material.youngs_modulus = 2e5;
  sd.material.poisson_ratio = 0.4;
  sd.shear_viscosity = piola_track_constant(damped ? 20 : 0);
  sd.bulk_viscosity = piola_track_constant(damped ? 10 : 0);
  sd.initial_matrix = (piola_mat3){{{1.3, 0.2, 0}, {0, 0.8, 0.1}, {0.1, 0, 1.1}}};
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  spin_block(w, 0.3, 0);
  double p0[3], l0[3], e0, p1[3], l1[3], e1;
  solid_momenta(w, p0, l0, &e0);
  piola_solid_stats s0 = piola_world_solid_stats(w, 0);
  const double energy0 = e0 + s0.elastic_energy;
  double lnorm0 = sqrt(l0[0] * l0[0] + l0[1] * l0[1] + l0[2] * l0[2]);
  double pnorm0 = sqrt(p0[0] * p0[0] + p0[1] * p0[1] + p0[2] * p0[2]);
  piola_step_stats st = {0};
  double last_energy = energy0;
  for (int f = 1; f <= 15; ++f) {
    memset(&st, 0, sizeof st); /* advance_to adds to it */
    assert_int_equal(piola_world_advance_to(w, f / 30.0, &st), PIOLA_OK);
    if (st.substeps != 1) fail_msg("model %d damped %d frame %d: %d steps, %d Newton failures, %d Newton iterations", (int)model, damped, f, (int)st.substeps, (int)st.newton_failures, (int)st.newton_iterations);
    assert_true(st.newton_iterations >= 1);
    solid_momenta(w, p1, l1, &e1);
    for (int k = 0; k < 3; ++k) assert_close(p1[k], p0[k], 1e-10 * pnorm0);
    piola_solid_stats s1 = piola_world_solid_stats(w, 0);
    double energy = e1 + s1.elastic_energy;
    /* backward Euler dissipates: the energy never grows (rounding and the Newton tolerance
     * allowed) */
    assert_true(energy <= last_energy * (1 + 1e-6) + 1e-9);
    last_energy = energy;
  }
  assert_true(lnorm0 > 0);
  block_mesh_free(&mesh);
  piola_world_destroy(w);
}

static void free_flight_momentum(void **state) {
  (void)state;
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model) {
    if (model == PIOLA_MODEL_MUSCLE) continue; /* needs fibres; tested in the scenes */
    free_flight((piola_material_model)model, 0);
    free_flight((piola_material_model)model, 1);
  }
}

static piola_obstacle_def plane(piola_vec3 normal, double friction) {
  piola_obstacle_def g = piola_default_obstacle_def();
  g.type = PIOLA_OBSTACLE_PLANE;
  g.center = (piola_vec3){0, 0, 0};
  g.axis = normal;
  g.friction = friction;
  return g;
}

static void drop_on_ground(void **state) {
  (void)state;
  piola_world *w = make_world(PIOLA_INTEGRATOR_BACKWARD_EULER, -9.81, 1.0 / 30);
  piola_tet_mesh mesh = block_mesh(3, 3, 2, 0.3, 0.3, 0.2);
  for (int32_t i = 0; i < mesh.vertex_count; ++i) mesh.positions[3 * i + 2] += 0.3;
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = &mesh;
  sd.material.youngs_modulus = 1e5;
  sd.shear_viscosity = piola_track_constant(5);
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  piola_obstacle_def g = plane((piola_vec3){0, 0, 1}, 0.5);
  assert_int_equal(piola_world_add_obstacle(w, &g, NULL), PIOLA_OK);
  piola_step_stats st = {0};
  int32_t n = piola_elastic_body_vertex_count(piola_world_solid_body(w, 0));
  for (int f = 1; f <= 60; ++f) {
    assert_int_equal(piola_world_advance_to(w, f / 30.0, &st), PIOLA_OK);
    const double *x = piola_world_solid_positions(w, 0);
    for (int32_t i = 0; i < n; ++i) assert_true(x[3 * i + 2] >= -1e-9);
  }
  /* at rest on the ground: slow, bottom on the plane, squashed by its weight only slightly */
  double p[3], l[3], ke;
  solid_momenta(w, p, l, &ke);
  const double *x = piola_world_solid_positions(w, 0);
  double zmin = INFINITY, zmax = -INFINITY;
  for (int32_t i = 0; i < n; ++i) zmin = fmin(zmin, x[3 * i + 2]), zmax = fmax(zmax, x[3 * i + 2]);
  assert_true(zmin < 1e-6);
  assert_true(zmax > 0.19 && zmax < 0.21);
  if (!(ke < 1e-4)) fail_msg("kinetic energy %g", ke);
  block_mesh_free(&mesh);
  piola_world_destroy(w);
}

/* A block on an incline of angle theta: with friction mu < tan(theta) it slides with
 * acceleration g (sin - mu cos); with mu > tan(theta) it stays. */
static double incline_slide_at(double theta, double mu, double dt, int cells) {
  piola_world *w = make_world(PIOLA_INTEGRATOR_BACKWARD_EULER, -9.81, dt);
  piola_tet_mesh mesh = block_mesh(2 * cells, 2 * cells, cells, 0.2, 0.2, 0.1);
  /* rotate the block onto the plane through the origin with normal (sin, 0, cos) */
  const double c = cos(theta), s = sin(theta);
  for (int32_t i = 0; i < mesh.vertex_count; ++i) {
    double *p = mesh.positions + 3 * i;
    double px = p[0] - 0.1, pz = p[2];
    p[0] = c * px + s * pz;
    p[2] = -s * px + c * pz;
  }
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = &mesh;
  sd.material.youngs_modulus = 1e6;
  sd.shear_viscosity = piola_track_constant(20);
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  piola_obstacle_def g = plane((piola_vec3){s, 0, c}, mu);
  assert_int_equal(piola_world_add_obstacle(w, &g, NULL), PIOLA_OK);
  piola_step_stats st = {0};
  const double t_end = 0.5;
  assert_int_equal(piola_world_advance_to(w, t_end, &st), PIOLA_OK);
  double p[3], l[3], ke;
  solid_momenta(w, p, l, &ke);
  double mass = 0;
  const double *m = piola_elastic_body_masses(piola_world_solid_body(w, 0));
  for (int32_t i = 0; i < mesh.vertex_count; ++i) mass += m[i];
  /* velocity along the slope (down-slope direction (c, 0, -s)) divided by the time */
  double along = (p[0] * c - p[2] * s) / mass;
  block_mesh_free(&mesh);
  piola_world_destroy(w);
  return along / t_end;
}

static double incline_slide(double theta, double mu) {
  return incline_slide_at(theta, mu, 1.0 / 120, 1);
}

static void incline_friction(void **state) {
  (void)state;
  const double theta = 0.5, g = 9.81;
  double a = incline_slide(theta, 0.2);
  double expected = g * (sin(theta) - 0.2 * cos(theta));
  assert_true(fabs(a - expected) <= 0.1 * expected);
  double stuck = incline_slide(theta, 0.8); /* tan(0.5) = 0.546 */
  assert_true(fabs(stuck) <= 0.02 * g);
  /* one step per 1/30 s frame on a finer block, whose contact nodes hold a sixth of its mass:
   * friction node by node stuck it for every mu from 0.1 up (implicit_step.c,
   * body_may_slide); mu = 0.4 is near the cone (tan 0.5 = 0.546) */
  const double mus[3] = {0.2, 0.4, 0.8};
  for (int k = 0; k < 3; ++k) {
    const double slid = incline_slide_at(theta, mus[k], 1.0 / 30, 2);
    const double exact = fmax(0.0, g * (sin(theta) - mus[k] * cos(theta)));
    if (!(fabs(slid - exact) <= 0.1 * exact + 0.02 * g))
      fail_msg("mu = %g at 1/30 s: %g m/s^2 along the slope, expected %g", mus[k], slid, exact);
  }
}

/* Friction acts after the Newton solve. On a mesh with slivers at the contact its moves are
 * many times their altitude, and before the step was solved again around them (implicit_step.c,
 * friction_moves_deform) Gmsh's bunny resting on a frictional plane kept up to 16 tets
 * inverted at its feet, 5 still after 1 s (docs/time-stepping.md, "Friction after the
 * solve"). Dropped from 1 cm onto a plane with friction 0.5, no tet may invert. */
static void friction_on_slivers_inverts_nothing(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  memset(&mesh, 0, sizeof mesh);
  const char *path = test_data_path("gmsh/bunny.msh");
  if (piola_tet_mesh_read(path, &mesh) != PIOLA_OK) fail_msg("%s: %s", path, piola_last_error());
  /* y-up to z-up (a quarter turn about x), the lowest node 1 cm above the plane */
  double zmin = INFINITY;
  for (int32_t i = 0; i < mesh.vertex_count; ++i) {
    double *p = mesh.positions + 3 * i;
    const double y = p[1], z = p[2];
    p[1] = -z, p[2] = y;
    zmin = fmin(zmin, p[2]);
  }
  for (int32_t i = 0; i < mesh.vertex_count; ++i) mesh.positions[3 * i + 2] += 0.01 - zmin;
  piola_world *w = make_world(PIOLA_INTEGRATOR_BACKWARD_EULER, -9.81, 1.0 / 30);
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = &mesh;
  sd.material.model = PIOLA_MODEL_NEOHOOKEAN;
  sd.material.youngs_modulus = 1e6;
  sd.material.poisson_ratio = 0.45;
  sd.shear_viscosity = piola_track_constant(5);
  sd.bulk_viscosity = piola_track_constant(5);
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  piola_obstacle_def g = plane((piola_vec3){0, 0, 1}, 0.5);
  assert_int_equal(piola_world_add_obstacle(w, &g, NULL), PIOLA_OK);
  const int frames = test_scale() >= 1.0 ? 12 : 3;
  for (int f = 1; f <= frames; ++f) {
    piola_step_stats st = {0};
    assert_int_equal(piola_world_advance_to(w, f / 30.0, &st), PIOLA_OK);
    const piola_solid_stats s = piola_world_solid_stats(w, 0);
    if (s.inverted_count != 0) fail_msg("frame %d: %d tets inverted", f, (int)s.inverted_count);
    const double *x = piola_world_solid_positions(w, 0);
    for (int32_t i = 0; i < 3 * mesh.vertex_count; ++i) assert_true(isfinite(x[i]));
    for (int32_t i = 0; i < mesh.vertex_count; ++i) assert_true(x[3 * i + 2] >= -1e-9);
  }
  piola_world_destroy(w);
  piola_tet_mesh_free(&mesh);
}

/* The total momentum of the world's solids (kg m/s) and their mass (kg). */
static double solids_momentum(const piola_world *w, double p[3]) {
  double mass = 0;
  p[0] = p[1] = p[2] = 0;
  for (int32_t b = 0; b < piola_world_solid_count(w); ++b) {
    const piola_elastic_body *body = piola_world_solid_body(w, b);
    const double *m = piola_elastic_body_masses(body);
    const double *v = piola_world_solid_velocities(w, b);
    for (int32_t i = 0; i < piola_elastic_body_vertex_count(body); ++i) {
      mass += m[i];
      for (int k = 0; k < 3; ++k) p[k] += m[i] * v[3 * i + k];
    }
  }
  return mass;
}

/* The first solid's mean x velocity (m/s). */
static double first_solid_velocity_x(const piola_world *w) {
  const piola_elastic_body *body = piola_world_solid_body(w, 0);
  const double *m = piola_elastic_body_masses(body), *v = piola_world_solid_velocities(w, 0);
  double p = 0, mass = 0;
  for (int32_t i = 0; i < piola_elastic_body_vertex_count(body); ++i)
    p += m[i] * v[3 * i], mass += m[i];
  return p / mass;
}

/* Two balls meeting with self-collision, no gravity, one step per 1/30 s frame. Each meets
 * the other's surface inside its own solve, taking the other as fixed, so their holds'
 * forces are not equal and opposite, and the collision pass's solves behind pushed surfaces
 * are not either: the total must still not change (implicit_step.c,
 * keep_solid_contact_momentum and self_collide_and_resolve). Before, two equal balls meeting
 * head-on came apart with 8% of one ball's momentum left over. Head-on and equal; then
 * unequal (scales 0.1 and 0.07 m), at unequal speeds and off-centre. */
static void colliding_bodies_keep_their_momentum(void **state) {
  (void)state;
  const char *ball = test_data_path("medit/unit_ball.mesh");
  const double second_scale[2] = {0.1, 0.07}, second_speed[2] = {-0.5, -0.2};
  const double offset[2] = {0, 0.03};
  for (int c = 0; c < 2; ++c) {
    char json[2048];
    snprintf(
        json, sizeof json,
        "{\"fps\": 30, \"gravity\": [0, 0, 0], \"integrator\": {\"type\": \"backward_euler\"},"
        " \"solids\": [{\"mesh\": \"%s\", \"transform\": {\"scale\": 0.1, \"translate\": "
        "[-0.12, 0, 0]}, \"velocity\": [0.5, 0, 0], \"material\": {\"youngs_modulus\": 1e5},"
        " \"self_collision\": {\"thickness\": 0.002}}, {\"mesh\": \"%s\", \"transform\": "
        "{\"scale\": %g, \"translate\": [0.12, %g, 0]}, \"velocity\": [%g, 0, 0], "
        "\"material\": {\"youngs_modulus\": 1e5}, \"self_collision\": {\"thickness\": 0.002}}]}",
        ball, ball, second_scale[c], offset[c], second_speed[c]);
    piola_scene *scene = NULL;
    if (piola_scene_load_string(json, NULL, NULL, &scene) != PIOLA_OK)
      fail_msg("%s", piola_last_error());
    piola_world *w = piola_scene_world(scene);
    double p0[3];
    const double mass = solids_momentum(w, p0);
    for (int f = 1; f <= 8; ++f) {
      piola_step_stats st = {0};
      assert_int_equal(piola_world_advance_to(w, f / 30.0, &st), PIOLA_OK);
      double p[3];
      (void)solids_momentum(w, p);
      /* to 1e-9 of the momentum of both bodies at 1 m/s */
      for (int k = 0; k < 3; ++k)
        if (!(fabs(p[k] - p0[k]) <= 1e-9 * mass))
          fail_msg("case %d, frame %d: momentum[%d] %g kg m/s, at the start %g", c, f, k, p[k],
                   p0[k]);
    }
    /* they met: the first ball, at 0.5 m/s before, no longer moves on at that speed */
    const double vx = first_solid_velocity_x(w);
    if (!(vx < 0.3)) fail_msg("case %d: the first ball still moves at %g m/s", c, vx);
    piola_scene_destroy(scene);
  }
}

/* Newmark stays the default, and untouched: two worlds stepped alike give identical bits. */
static void newmark_default(void **state) {
  (void)state;
  piola_world_def wd = piola_default_world_def();
  assert_int_equal(wd.integrator, PIOLA_INTEGRATOR_NEWMARK);
  piola_integrator_type t;
  assert_true(piola_integrator_type_from_name("backward_euler", &t));
  assert_int_equal(t, PIOLA_INTEGRATOR_BACKWARD_EULER);
  assert_true(piola_integrator_type_from_name("quasistatic", &t));
  assert_int_equal(t, PIOLA_INTEGRATOR_QUASISTATIC);
  assert_false(piola_integrator_type_from_name("implicit", &t));
  /* invalid implicit parameters are refused by name */
  wd.implicit_dt = 0;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_ERROR_INVALID_ARGUMENT);
  wd = piola_default_world_def();
  wd.linear_tolerance = 1.5;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_ERROR_INVALID_ARGUMENT);
}

/* A 0.1 m box (about 1 kg) released 3 mm above a box resting on the ground, moving along x
 * at `speed` (m/s), both with self_collision, one step per 1/30 s frame for 12 frames.
 * Returns the largest energy of the two (kinetic plus elastic, J) over the frames, and the
 * last frame's in *last.
 *
 * The solve after the collision pass has no halving loop around it, so a try of it that
 * fails is kept like a last try: this scene stopped at frame 3 with an empty message (the
 * re-solve handed a failed try back to be halved, PIOLA_ERROR_NOT_CONVERGED). And the pass
 * with the holds of that solve on both boxes fixed dents no force balanced: 3.4 J of elastic
 * energy in the first frame, 19.5 J in the second, and 92 J for the sliding box. Each box
 * now meets the other's surface inside its own solve (solid_contacts.c). */
static double box_on_a_box(double speed, double *last) {
  char json[2048];
  snprintf(json, sizeof json,
           "{\"fps\": 30, \"frames\": 6, \"integrator\": {\"type\": \"backward_euler\"},"
           " \"solids\": ["
           "  {\"name\": \"base\", \"mesh\": {\"generate\": \"box\","
           "   \"half_extents\": [0.3, 0.15, 0.05], \"cell_size\": 0.025},"
           "   \"transform\": {\"translate\": [0.15, 0, 0.05]},"
           "   \"material\": {\"youngs_modulus\": 1e6}, \"damping\": {\"shear\": 20, \"bulk\": 20},"
           "   \"self_collision\": {\"thickness\": 0.002, \"friction\": 0.5}},"
           "  {\"name\": \"slider\", \"mesh\": {\"generate\": \"box\","
           "   \"half_extents\": [0.05, 0.05, 0.05], \"cell_size\": 0.025},"
           "   \"transform\": {\"translate\": [0, 0, 0.153]}, \"velocity\": [%g, 0, 0],"
           "   \"material\": {\"youngs_modulus\": 1e6}, \"damping\": {\"shear\": 20, \"bulk\": 20},"
           "   \"self_collision\": {\"thickness\": 0.002, \"friction\": 0.5}}],"
           " \"obstacles\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 0, 1],"
           "   \"friction\": 1}]}",
           speed);
  piola_scene *scene = NULL;
  if (piola_scene_load_string(json, NULL, NULL, &scene) != PIOLA_OK)
    fail_msg("%s", piola_last_error());
  piola_world *w = piola_scene_world(scene);
  const int frames = 12; /* the sliding box stops within them, also in the sanitizer pass */
  double most = 0;
  for (int f = 1; f <= frames; ++f) {
    if (piola_world_advance_to(w, f / 30.0, NULL) != PIOLA_OK)
      fail_msg("frame %d: %s (%s)", f, piola_last_error(), "the run stopped");
    double energy = 0;
    for (int32_t b = 0; b < 2; ++b) {
      const piola_solid_stats st = piola_world_solid_stats(w, b);
      if (!isfinite(st.kinetic_energy) || !isfinite(st.elastic_energy))
        fail_msg("frame %d: solid %d has a non-finite energy", f, (int)b);
      energy += st.kinetic_energy + st.elastic_energy;
    }
    most = fmax(most, energy);
    *last = energy;
  }
  piola_scene_destroy(scene);
  return most;
}

static void box_on_a_box_gains_no_energy(void **state) {
  (void)state;
  /* dropped: 0.03 J of gravity's work to release, and the boxes' weight on their supports */
  double last;
  const double dropped = box_on_a_box(0, &last);
  print_message("box dropped on a box: at most %.3g J, %.3g J at the end\n", dropped, last);
  if (!(dropped < 0.1)) fail_msg("the dropped box reached %g J", dropped);
  /* sliding at 1 m/s: 0.42 J of motion, which friction takes, to rest in about 0.2 s (0.6 J
   * at most in a frame while it lands and stops) */
  const double sliding = box_on_a_box(1.0, &last);
  print_message("box sliding on a box: at most %.3g J, %.3g J at the end\n", sliding, last);
  if (!(sliding < 1.0)) fail_msg("the sliding box reached %g J", sliding);
  if (!(last < 0.05)) fail_msg("the sliding box ended with %g J", last);
}

/* A stiff box (E = 1 MPa) on a plane with friction 0.5, a ball and a lid dropped onto it,
 * every pair with friction 0.5, one step per 1/60 s frame for 1 s. Friction's moves after
 * the solve stopped the box's bottom nodes where its step had slid them, and the strain they
 * locked in reached 3.57 J in single frames, twice the scene's energy at the start (2.06 J
 * with gravity's potential); the total energy rose to 4.6 J. Now such moves are solved
 * again (docs/time-stepping.md, "Friction after the solve"): the scene's energy never rises
 * above its start, and its elastic energy under 0.6 J (0.37 J at most here). */
static void friction_on_a_stack_locks_no_strain(void **state) {
  (void)state;
  if (test_scale() < 1.0) return;
  const char *json =
      "{\"fps\": 60, \"integrator\": {\"type\": \"backward_euler\"}, \"solids\": ["
      " {\"name\": \"base\", \"mesh\": {\"generate\": \"box\", \"half_extents\": [0.08, 0.08, "
      "0.03],"
      "  \"cell_size\": 0.02}, \"transform\": {\"translate\": [0, 0, 0.035]},"
      "  \"material\": {\"model\": \"neohookean\", \"youngs_modulus\": 1e6, \"poisson_ratio\": "
      "0.3},"
      "  \"damping\": {\"shear\": 5, \"bulk\": 5},"
      "  \"self_collision\": {\"thickness\": 0.002, \"friction\": 0.5}},"
      " {\"name\": \"ball\", \"mesh\": {\"generate\": \"sphere\", \"radius\": 0.05, \"cell_size\": "
      "0.02},"
      "  \"transform\": {\"translate\": [0.01, 0, 0.125]},"
      "  \"material\": {\"model\": \"neohookean\", \"youngs_modulus\": 5e4, \"poisson_ratio\": "
      "0.3},"
      "  \"damping\": {\"shear\": 5, \"bulk\": 5},"
      "  \"self_collision\": {\"thickness\": 0.002, \"friction\": 0.5}},"
      " {\"name\": \"lid\", \"mesh\": {\"generate\": \"box\", \"half_extents\": [0.06, 0.06, 0.02],"
      "  \"cell_size\": 0.02}, \"transform\": {\"translate\": [0, 0.01, 0.21]},"
      "  \"material\": {\"model\": \"neohookean\", \"youngs_modulus\": 2e4, \"poisson_ratio\": "
      "0.3},"
      "  \"damping\": {\"shear\": 5, \"bulk\": 5},"
      "  \"self_collision\": {\"thickness\": 0.002, \"friction\": 0.5}}],"
      " \"obstacles\": [{\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 0, 1],"
      "  \"friction\": 0.5}]}";
  piola_scene *scene = NULL;
  if (piola_scene_load_string(json, NULL, NULL, &scene) != PIOLA_OK)
    fail_msg("%s", piola_last_error());
  piola_world *w = piola_scene_world(scene);
  double start = 0, most = 0, elastic_most = 0;
  for (int f = 0; f <= 60; ++f) {
    if (f > 0 && piola_world_advance_to(w, f / 60.0, NULL) != PIOLA_OK)
      fail_msg("frame %d: %s", f, piola_last_error());
    double energy = 0, elastic = 0;
    for (int32_t b = 0; b < 3; ++b) {
      const piola_solid_stats st = piola_world_solid_stats(w, b);
      const double *x = piola_world_solid_positions(w, b);
      const double *mass = piola_elastic_body_masses(piola_world_solid_body(w, b));
      energy += st.kinetic_energy + st.elastic_energy;
      elastic += st.elastic_energy;
      for (int32_t i = 0; i < piola_elastic_body_vertex_count(piola_world_solid_body(w, b)); ++i)
        energy += mass[i] * 9.81 * x[3 * i + 2];
    }
    if (f == 0) start = energy;
    most = fmax(most, energy);
    elastic_most = fmax(elastic_most, elastic);
  }
  print_message(
      "stack with friction: energy %.4f J at the start, at most %.4f J; elastic at "
      "most %.4f J\n",
      start, most, elastic_most);
  if (!(most <= start)) fail_msg("the stack's energy rose from %g J to %g J", start, most);
  if (!(elastic_most < 0.6)) fail_msg("the stack held %g J of elastic energy", elastic_most);
  piola_scene_destroy(scene);
}

/* The scene keys: integrator.type picks the integrator, integrator.dt defaults to the frame
 * time, and a bad value is refused with its key path. */
static void scene_keys(void **state) {
  (void)state;
  const char *good = "{\"fps\": 24, \"frames\": 1, \"integrator\": {\"type\": \"backward_euler\"},"
                     " \"solids\": [{\"mesh\": {\"generate\": \"box\", \"half_extents\": [0.1, 0.1, 0.1], \"cell_size\": 0.1}}]}";
  piola_scene *scene = NULL;
  if (piola_scene_load_string(good, NULL, NULL, &scene) != PIOLA_OK) fail_msg("%s", piola_last_error());
  assert_close(piola_world_stable_dt(piola_scene_world(scene)), 1.0 / 24, 1e-15);
  piola_step_stats st;
  memset(&st, 0, sizeof st);
  assert_int_equal(piola_world_advance_to(piola_scene_world(scene), 1.0 / 24, &st), PIOLA_OK);
  assert_int_equal(st.substeps, 1);
  /* free fall in one backward Euler step: every node moved by -g dt^2 (the first guess is
   * exact, so Newton needs no iteration) */
  const piola_world *w = piola_scene_world(scene);
  const double *x = piola_world_solid_positions(w, 0);
  const double *x0 = piola_elastic_body_rest_positions(piola_world_solid_body(w, 0));
  for (int32_t i = 0; i < piola_elastic_body_vertex_count(piola_world_solid_body(w, 0)); ++i)
    assert_close(x[3 * i + 2] - x0[3 * i + 2], -9.81 / (24.0 * 24.0), 1e-12);
  piola_scene_destroy(scene);
  const char *with_dt = "{\"fps\": 24, \"frames\": 1, \"integrator\": {\"type\": \"quasistatic\", \"dt\": 0.01},"
                        " \"solids\": [{\"mesh\": {\"generate\": \"box\", \"half_extents\": [0.1, 0.1, 0.1], \"cell_size\": 0.1}}]}";
  if (piola_scene_load_string(with_dt, NULL, NULL, &scene) != PIOLA_OK) fail_msg("%s", piola_last_error());
  assert_close(piola_world_stable_dt(piola_scene_world(scene)), 0.01, 1e-15);
  piola_scene_destroy(scene);
  /* the iteration caps take the documented range [1, 1000000] (scene-format.md) */
  const char *caps[] = {"newton_max_iterations", "linear_max_iterations", "cg_max_iterations"};
  for (int c = 0; c < 3; ++c)
    for (int over = 0; over <= 1; ++over) {
      char json[512];
      snprintf(json, sizeof json,
               "{\"frames\": 0, \"integrator\": {\"type\": \"backward_euler\", \"%s\": %d},"
               " \"solids\": [{\"mesh\": {\"generate\": \"box\", \"half_extents\": [0.1, 0.1, 0.1], \"cell_size\": 0.1}}]}",
               caps[c], 1000000 + over);
      piola_status loaded = piola_scene_load_string(json, NULL, NULL, &scene);
      if (!over) {
        if (loaded != PIOLA_OK) fail_msg("%s = 1000000 refused: %s", caps[c], piola_last_error());
        piola_scene_destroy(scene);
      } else {
        assert_int_equal(loaded, PIOLA_ERROR_INVALID_ARGUMENT);
        assert_non_null(strstr(piola_last_error(), caps[c]));
      }
    }
  const char *bad = "{\"integrator\": {\"type\": \"implicit\"}, \"solids\": []}";
  assert_int_equal(piola_scene_load_string(bad, NULL, NULL, &scene), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "integrator.type"));
}

/* The block MESH collapsed to a point, stepped with newton_max_iterations as given; returns
 * the world after one frame of 1/30 s, its stats in *st. */
static piola_world *collapsed_block_frame(const piola_tet_mesh *mesh, int32_t newton_max_iterations,
                                          piola_step_stats *st) {
  piola_world_def wd = piola_default_world_def();
  wd.gravity[2] = piola_track_constant(0);
  wd.integrator = PIOLA_INTEGRATOR_BACKWARD_EULER;
  wd.implicit_dt = 1.0 / 30;
  wd.newton_max_iterations = newton_max_iterations;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = mesh;
  sd.material.youngs_modulus = 2e5;
  sd.initial_matrix = (piola_mat3){{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}};
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  memset(st, 0, sizeof *st);
  assert_int_equal(piola_world_advance_to(w, 1.0 / 30, st), PIOLA_OK);
  assert_true(piola_world_time(w) == 1.0 / 30);
  return w;
}

/* A frame whose every step fails Newton ends in at most 8 steps: each failing step is
 * halved at least once and at most three times (until halving stops helping, or the
 * third) and then kept at its best iterate, never shorter than dt / 8. Before,
 * the steps after the first halved what was left of the frame, shrinking geometrically, and
 * the frame never ended once they fell below the rounding of the time (found by a scene of
 * docs/scene-format.md with "newton_max_iterations": 1: a collapsed ball ran for ever). */
static void failing_steps_finish_the_frame(void **state) {
  (void)state;
  piola_tet_mesh mesh = block_mesh(3, 2, 2, 0.3, 0.2, 0.2);
  piola_step_stats st;
  piola_world *w = collapsed_block_frame(&mesh, 1, &st);
  assert_true(st.substeps >= 2 && st.substeps <= 8);
  assert_true(st.newton_failures >= 2 * st.substeps && st.newton_failures <= 4 * st.substeps);
  piola_world_destroy(w);
  block_mesh_free(&mesh);
}

/* A state whose forces overflow (a block stretched 1000 times, every stress scaled by 1e300)
 * ends the step with PIOLA_ERROR_NOT_FINITE, the world left at its last good state: before,
 * the last try failed on its non-finite residual and the step was halved for ever (a scene
 * scrambled by 1e300 m ran until killed; such a start is now refused when the solid is
 * added). */
static void non_finite_residual_fails_the_step(void **state) {
  (void)state;
  piola_world *w = make_world(PIOLA_INTEGRATOR_BACKWARD_EULER, 0, 1.0 / 30);
  piola_tet_mesh mesh = block_mesh(2, 2, 2, 0.2, 0.2, 0.2);
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = &mesh;
  /* stretched 1000 times with every stress scaled by 1e300: the residual overflows (a
   * stretch of 1e200 is now refused when the solid is added, world_solids.c) */
  sd.initial_matrix = (piola_mat3){{{1e3, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  sd.stiffness_scale = piola_track_constant(1e300);
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  piola_step_stats st;
  memset(&st, 0, sizeof st);
  assert_int_equal(piola_world_advance_to(w, 1.0 / 30, &st), PIOLA_ERROR_NOT_FINITE);
  assert_non_null(strstr(piola_last_error(), "non-finite"));
  assert_true(piola_world_time(w) == 0);
  piola_world_destroy(w);
  block_mesh_free(&mesh);
}

/* An iterate that converges at the last allowed Newton iteration is a converged step: the
 * test runs once more after the last iteration (before, the step counted as failed, was
 * undone and redone at half the size). */
static void newton_may_converge_at_its_last_iteration(void **state) {
  (void)state;
  piola_tet_mesh mesh = block_mesh(3, 2, 2, 0.3, 0.2, 0.2);
  piola_step_stats free_st, capped_st;
  piola_world *free_run = collapsed_block_frame(&mesh, 30, &free_st);
  assert_int_equal(free_st.substeps, 1);
  assert_int_equal(free_st.newton_failures, 0);
  assert_true(free_st.newton_iterations >= 2);
  piola_world *capped = collapsed_block_frame(&mesh, free_st.newton_iterations, &capped_st);
  assert_int_equal(capped_st.substeps, 1);
  assert_int_equal(capped_st.newton_failures, 0);
  assert_int_equal(capped_st.newton_iterations, free_st.newton_iterations);
  const double *a = piola_world_solid_positions(free_run, 0), *b = piola_world_solid_positions(capped, 0);
  for (int32_t j = 0; j < 3 * piola_elastic_body_vertex_count(piola_world_solid_body(capped, 0)); ++j)
    assert_true(a[j] == b[j]);
  piola_world_destroy(free_run);
  piola_world_destroy(capped);
  block_mesh_free(&mesh);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(newmark_default),
      cmocka_unit_test(scene_keys),
      cmocka_unit_test(free_flight_momentum),
      cmocka_unit_test(drop_on_ground),
      cmocka_unit_test(incline_friction),
      cmocka_unit_test(colliding_bodies_keep_their_momentum),
      cmocka_unit_test(friction_on_slivers_inverts_nothing),
      cmocka_unit_test(failing_steps_finish_the_frame),
      cmocka_unit_test(newton_may_converge_at_its_last_iteration),
      cmocka_unit_test(non_finite_residual_fails_the_step),
      cmocka_unit_test(box_on_a_box_gains_no_energy),
      cmocka_unit_test(friction_on_a_stack_locks_no_strain),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
