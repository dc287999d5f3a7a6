/* Quasistatics (piola_world_def.integrator = PIOLA_INTEGRATOR_QUASISTATIC):
 *  - a cantilever (L = 1 m, square 0.1 m section, nu = 0, clamped at x = 0) under a small
 *    distributed load (its own weight at a reduced gravity; there is no point-load API)
 *    deflects at the tip by Euler-Bernoulli's q L^4 / (8 E I) within 3%, taking the
 *    Richardson extrapolation of a 40x4x4 and an 80x8x8 mesh as the fine-mesh answer
 *    (measured 0.998 of the theory; shear adds 0.8% by Timoshenko's beam at L/h = 10), and
 *    the error of the two meshes falls by 3-5x from one to the other (the h^2 rate of linear
 *    tets, which the extrapolation assumes). Below PIOLA_TEST_SCALE 1 (the sanitizer pass)
 *    the meshes are 20x2x2 and 40x4x4, still short of that rate (error ratio 2.6), and the
 *    check is 10% (measured 0.923).
 *    Refinement study (tip / theory): 20x2x2 0.555, 30x3x3 0.734, 40x4x4 0.831, 60x6x6
 *    0.920, 80x8x8 0.956 (a 10x1x1 mesh: 0.66 of the theory after extrapolation, and too
 *    stiff for a large deflection at the large load);
 *  - a large load (tip deflection over 5% of the length, the section's rotation 0.1 rad) gives the same equilibrium whether
 *    it is reached in one step or in four load increments (gravity keyed linearly from 0),
 *    to 1e-6 of the deflection: the answer is the equilibrium, not the path; and whether its
 *    Newton systems are solved with Eisenstat and Walker's forcing or to the fixed
 *    linear_tolerance, to the same 1e-6;
 *  - a soft bar swung by a turning gravity (the quasistatic bar of
 *    tests/scripts/run_resume_examples.py) reaches the equilibrium of its first load
 *    increment without a failed Newton step. On the residual norm alone the line search
 *    accepted 1/1024 of the first Newton steps and that increment failed 12 times in the
 *    scene's run (52,164 times, in 13,042 halved steps, on this test's mesh): the direction
 *    of the projected Hessian decreases the potential, not always |g| (implicit_step.c);
 *  - a failed step's warning gives its own integrator's rule for what it keeps, and its
 *    advice tells a held bar (ramp the load) from a free block (nothing holds it);
 *  - a block pressed by a box obstacle that then stops stays where its last step left it:
 *    the steps after take no Newton iteration. Its contact nodes lie on the box's face at
 *    that equilibrium; not held from the start of a step, they were pushed into the box by
 *    the first iteration and projected onto its side faces, and the block jumped between
 *    states (elastic energy 0.60-0.81 J, tets inverted, 13-19 iterations a frame);
 *  - that potential, elastic energy (piola__elastic_body_total_energy) minus gravity's
 *    work, is the function the quasistatic residual is the gradient of: its central
 *    difference along a random direction at a bent, stretched state equals -(f + M g) . d
 *    to 1e-6, and the energy is the update's own statistic. */
#include "test_support.h"
#include "test_elastic_body_fixtures.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "force/elastic_body_internal.h"
#include "piola/mesh.h"
#include "piola/scene.h"
#include "piola/threads.h"
#include "piola/world_bodies.h"
#include "piola/world.h"

typedef struct beam {
  int nx, ny;
  double length, side;
} beam;

/* A neo-Hookean bar of b's grid along x (1000 kg/m^3), its end at x = 0 held. */
static void add_clamped_bar(piola_world *w, const beam *b, double youngs_modulus, double poisson_ratio) {
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(b->nx, b->ny, b->ny,
                                           (piola_vec3){b->length / b->nx, b->side / b->ny,
                                                        b->side / b->ny},
                                           &mesh),
                   PIOLA_OK);
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = &mesh;
  sd.material.model = PIOLA_MODEL_NEOHOOKEAN;
  sd.material.youngs_modulus = youngs_modulus;
  sd.material.poisson_ratio = poisson_ratio;
  sd.density = 1000;
  piola_constraint_def clamp;
  memset(&clamp, 0, sizeof clamp);
  clamp.selector.type = PIOLA_SELECT_BOX;
  clamp.selector.box_min = (piola_vec3){-1, -1, -1};
  clamp.selector.box_max = (piola_vec3){1e-9, 1, 1};
  sd.constraints = &clamp;
  sd.constraint_count = 1;
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  free(mesh.positions);
  free(mesh.tets);
}

static piola_world *cantilever(const beam *b, piola_track gz, double dt, double tolerance,
                               piola_linear_forcing forcing) {
  piola_world_def wd = piola_default_world_def();
  wd.linear_forcing = forcing;
  wd.gravity[2] = gz;
  wd.integrator = PIOLA_INTEGRATOR_QUASISTATIC;
  wd.implicit_dt = dt;
  wd.newton_tolerance = tolerance;
  wd.newton_max_iterations = 1000;
  wd.linear_max_iterations = 20000;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  add_clamped_bar(w, b, 1e6, 0.0);
  return w;
}

/* Mean vertical displacement of the nodes at the free end. */
static double tip_deflection(const piola_world *w, const beam *b) {
  const piola_elastic_body *body = piola_world_solid_body(w, 0);
  const double *x = piola_world_solid_positions(w, 0);
  const double *x0 = piola_elastic_body_rest_positions(body);
  double sum = 0;
  int count = 0;
  for (int32_t i = 0; i < piola_elastic_body_vertex_count(body); ++i)
    if (x0[3 * i] > b->length - 1e-9) sum += x[3 * i + 2] - x0[3 * i + 2], count++;
  return sum / count;
}

/* Tip deflection (m, downwards) of the cantilever with ny elements across the section. */
static double small_load_tip(int ny, double g, int *newton) {
  beam b = {10 * ny, ny, 1.0, 0.1};
  piola_world *w = cantilever(&b, piola_track_constant(-g), 1.0, 1e-10, PIOLA_FORCING_EISENSTAT_WALKER);
  piola_step_stats st;
  memset(&st, 0, sizeof st);
  assert_int_equal(piola_world_advance_to(w, 1.0, &st), PIOLA_OK);
  assert_true(st.newton_iterations >= 1);
  *newton = st.newton_iterations;
  double tip = -tip_deflection(w, &b);
  piola_world_destroy(w);
  return tip;
}

/* Linear tets are too stiff in bending (the error falls as h^2 once the section has 4
 * elements across), so the fine-mesh answer is the Richardson extrapolation of two meshes,
 * h and h / 2: (4 d(h/2) - d(h)) / 3. */
static void small_load_matches_euler_bernoulli(void **state) {
  (void)state;
  const int full = test_scale() >= 1.0;
  const int ny = full ? 4 : 2;
  const double g = 0.01; /* m/s^2: small deflection */
  const double q = 1000 * g * 0.1 * 0.1;                  /* N/m */
  const double inertia = pow(0.1, 4) / 12.0;              /* m^4 */
  const double theory = q / (8 * 1e6 * inertia);          /* L = 1 m */
  int n1, n2;
  const double coarse = small_load_tip(ny, g, &n1), finer = small_load_tip(2 * ny, g, &n2);
  const double extrapolated = (4 * finer - coarse) / 3;
  const double error_ratio = (theory - coarse) / (theory - finer);
  print_message("cantilever: tip %.6g m (%d across), %.6g m (%d across), extrapolated %.6g m; "
                "Euler-Bernoulli %.6g m (ratio %.4f); error ratio %.3f; %d and %d Newton "
                "iterations\n",
                coarse, ny, finer, 2 * ny, extrapolated, theory, extrapolated / theory,
                error_ratio, n1, n2);
  assert_true(coarse < finer && finer < theory * 1.01); /* converging from the stiff side */
  if (full) {
    assert_true(error_ratio >= 3.0 && error_ratio <= 5.0);
    assert_true(fabs(extrapolated - theory) <= 0.03 * theory);
  } else {
    assert_true(fabs(extrapolated - theory) <= 0.10 * theory);
  }
}

static void large_load_independent_of_increments(void **state) {
  (void)state;
  beam b = {20, 2, 1.0, 0.1};
  /* gravity ramps from 0 at t = 0 to its full value at t = 1 s */
  const double times[2] = {0, 1}, values[2] = {0, -0.8};
  piola_track ramp;
  assert_int_equal(piola_track_from_keys(times, values, 2, &ramp), PIOLA_OK);
  piola_world *one = cantilever(&b, ramp, 1.0, 1e-9, PIOLA_FORCING_EISENSTAT_WALKER);
  piola_world *four = cantilever(&b, ramp, 0.25, 1e-9, PIOLA_FORCING_EISENSTAT_WALKER);
  piola_step_stats st1, st4;
  memset(&st1, 0, sizeof st1);
  memset(&st4, 0, sizeof st4);
  assert_int_equal(piola_world_advance_to(one, 1.0, &st1), PIOLA_OK);
  assert_int_equal(piola_world_advance_to(four, 1.0, &st4), PIOLA_OK);
  assert_int_equal(st4.substeps, 4);
  const double tip = -tip_deflection(four, &b);
  assert_true(tip > 0.05 * b.length); /* a large deflection indeed */
  const double *x1 = piola_world_solid_positions(one, 0), *x4 = piola_world_solid_positions(four, 0);
  double diff = 0;
  for (int32_t i = 0; i < 3 * piola_elastic_body_vertex_count(piola_world_solid_body(one, 0)); ++i)
    diff = fmax(diff, fabs(x1[i] - x4[i]));
  print_message("large load: tip %.6g m, one step vs four increments differ by %.3g m "
                "(%d and %d Newton iterations)\n",
                tip, diff, (int)st1.newton_iterations, (int)st4.newton_iterations);
  assert_true(diff <= 1e-6 * tip);
  piola_world_destroy(one);
  piola_world_destroy(four);
}

/* Quasistatic steps use Eisenstat and Walker's forcing too (loose linear solves while Newton
 * is far off, never looser than 0.1 after a step the line search shortened): the large-load
 * equilibrium in one step equals the one every system solved to linear_tolerance reaches,
 * to the same 1e-6 of the deflection (the Newton test is the same; only the path differs). */
static void large_load_independent_of_forcing(void **state) {
  (void)state;
  beam b = {20, 2, 1.0, 0.1};
  piola_world *adaptive = cantilever(&b, piola_track_constant(-0.8), 1.0, 1e-9,
                                     PIOLA_FORCING_EISENSTAT_WALKER);
  piola_world *fixed = cantilever(&b, piola_track_constant(-0.8), 1.0, 1e-9, PIOLA_FORCING_FIXED);
  piola_step_stats sa, sf;
  memset(&sa, 0, sizeof sa);
  memset(&sf, 0, sizeof sf);
  assert_int_equal(piola_world_advance_to(adaptive, 1.0, &sa), PIOLA_OK);
  assert_int_equal(piola_world_advance_to(fixed, 1.0, &sf), PIOLA_OK);
  assert_int_equal(sa.newton_failures, 0);
  assert_int_equal(sf.newton_failures, 0);
  const double tip = -tip_deflection(fixed, &b);
  assert_true(tip > 0.05 * b.length);
  const double *xa = piola_world_solid_positions(adaptive, 0);
  const double *xf = piola_world_solid_positions(fixed, 0);
  double diff = 0;
  const int32_t n = piola_elastic_body_vertex_count(piola_world_solid_body(fixed, 0));
  for (int32_t i = 0; i < 3 * n; ++i) diff = fmax(diff, fabs(xa[i] - xf[i]));
  print_message("large load: Eisenstat-Walker vs fixed forcing differ by %.3g m (%d and %d "
                "Newton, %d and %d CG iterations)\n",
                diff, (int)sa.newton_iterations, (int)sf.newton_iterations,
                (int)sa.linear_iterations, (int)sf.linear_iterations);
  assert_true(diff <= 1e-6 * tip);
  piola_world_destroy(adaptive);
  piola_world_destroy(fixed);
}

/* The quasistatic bar of run_resume_examples.py: 0.5 m x 0.08 m x 0.08 m, neo-Hookean
 * E = 20 kPa, nu = 0.3, clamped at x = 0, gravity (0, 0 -> 15, -5 -> -40) m/s^2 over 0.4 s;
 * one increment of 1/30 s, the run's first frame. */
/* The soft bar below (0.5 m, E = 20 kPa, nu = 0.3, clamped) in a world of wd (quasistatic
 * unless wd names backward Euler) after its first step of 1/30 s, the step's statistics in
 * *st. */
static piola_world *soft_bar_first_increment(piola_world_def wd, piola_step_stats *st) {
  if (wd.integrator == PIOLA_INTEGRATOR_NEWMARK) wd.integrator = PIOLA_INTEGRATOR_QUASISTATIC;
  wd.implicit_dt = 1.0 / 30.0;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  add_clamped_bar(w, &(beam){.nx = 13, .ny = 2, .length = 0.5, .side = 0.08}, 2e4, 0.3);
  memset(st, 0, sizeof *st);
  assert_int_equal(piola_world_advance_to(w, 1.0 / 30.0, st), PIOLA_OK);
  return w;
}

static void soft_bar_increment_without_failed_newton(void **state) {
  (void)state;
  piola_world_def wd = piola_default_world_def();
  const double times[2] = {0, 0.4}, gy[2] = {0, 15}, gz[2] = {-5, -40};
  assert_int_equal(piola_track_from_keys(times, gy, 2, &wd.gravity[1]), PIOLA_OK);
  assert_int_equal(piola_track_from_keys(times, gz, 2, &wd.gravity[2]), PIOLA_OK);
  piola_step_stats st;
  piola_world *w = soft_bar_first_increment(wd, &st);
  const piola_elastic_body *body = piola_world_solid_body(w, 0);
  const double *x = piola_world_solid_positions(w, 0);
  const double *x0 = piola_elastic_body_rest_positions(body);
  double tip = 0;
  for (int32_t i = 0; i < piola_elastic_body_vertex_count(body); ++i)
    if (x0[3 * i] > 0.5 - 1e-9) tip = fmax(tip, x0[3 * i + 2] - x[3 * i + 2]);
  print_message("soft bar: first increment in %d step(s), %d Newton iterations, %d failed, "
                "tip down %.4g m\n",
                (int)st.substeps, (int)st.newton_iterations, (int)st.newton_failures, tip);
  assert_true(tip > 0.1); /* a large deflection: the bar hangs */
  assert_int_equal(st.newton_failures, 0);
  assert_int_equal(st.substeps, 1); /* no halved increment */
  piola_world_destroy(w);
}

/* A clamped bar whose step fails (Newton allowed one iteration, far from its tolerance): the
 * warning names the step and, the bar being held by a constrained node, advises ramping the
 * load (time-stepping.md, "Quasistatics"), not the advice for a body with no equilibrium. */
static void held_bar_failure_advises_a_ramp(void **state) {
  (void)state;
  piola_world_def wd = piola_default_world_def();
  wd.newton_max_iterations = 1;
  piola_step_stats st;
  piola_world *w = soft_bar_first_increment(wd, &st);
  assert_true(st.newton_failures > 0);
  const char *text = piola_world_warning(w, PIOLA_WARNING_NEWTON_FAILED);
  assert_non_null(text);
  assert_non_null(strstr(text, "quasistatic step"));
  assert_non_null(strstr(text, "ramped: keyframe gravity (or the activation"));
  assert_null(strstr(text, "no equilibrium"));
  /* what a failed step keeps: the quasistatic rule only */
  assert_non_null(strstr(text, "(unless it moved a node further than the body's size"));
  assert_null(strstr(text, "backward Euler"));
  assert_null(strstr(text, "held more energy"));
  piola_world_destroy(w);
}

/* The same bar and failure under backward Euler: the warning gives backward Euler's rule
 * for what a failed step keeps, not the quasistatic one, and no quasistatic advice. */
static void backward_euler_failure_names_its_own_rule(void **state) {
  (void)state;
  piola_world_def wd = piola_default_world_def();
  wd.integrator = PIOLA_INTEGRATOR_BACKWARD_EULER;
  wd.newton_max_iterations = 1;
  piola_step_stats st;
  piola_world *w = soft_bar_first_increment(wd, &st);
  assert_true(st.newton_failures > 0);
  const char *text = piola_world_warning(w, PIOLA_WARNING_NEWTON_FAILED);
  assert_non_null(text);
  assert_non_null(strstr(text, "backward Euler step"));
  assert_non_null(strstr(text, "(unless it held more energy than the step's start"));
  assert_null(strstr(text, "quasistatic"));
  assert_null(strstr(text, "moved a node further"));
  piola_world_destroy(w);
}

/* A free block in gravity (no constrained node, no obstacle) has no equilibrium: the advice
 * says nothing holds it, not that obstacle contacts alone do. */
static void free_block_failure_says_nothing_holds_it(void **state) {
  (void)state;
  piola_world_def wd = piola_default_world_def();
  wd.integrator = PIOLA_INTEGRATOR_QUASISTATIC;
  wd.implicit_dt = 1.0 / 30.0;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(2, 2, 2, (piola_vec3){0.05, 0.05, 0.05}, &mesh),
                   PIOLA_OK);
  piola_solid_def sd = piola_default_solid_def();
  sd.name = "block";
  sd.mesh = &mesh;
  sd.material.youngs_modulus = 1e5;
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  piola_step_stats st = {0};
  assert_int_equal(piola_world_advance_to(w, 1.0 / 30.0, &st), PIOLA_OK);
  assert_true(st.newton_failures > 0);
  const char *text = piola_world_warning(w, PIOLA_WARNING_NEWTON_FAILED);
  assert_non_null(text);
  assert_non_null(strstr(text, "'block'"));
  assert_non_null(strstr(text,
                         "A quasistatic body with nothing holding it (no fixed, driven or bone "
                         "node, no obstacle contact) has no equilibrium under gravity"));
  assert_null(strstr(text, "obstacle contacts alone"));
  piola_world_destroy(w);
  free(mesh.positions);
  free(mesh.tets);
}

/* Pi(x) = sum V0 psi - sum m_i g . x_i after an update at x. */
/* A 0.2 x 0.2 x 0.1 m block fixed at its bottom, pressed 1 cm by a box obstacle over five
 * frames, then held: the next frames change nothing. */
static void pressed_block_stays_when_the_press_stops(void **state) {
  (void)state;
  const char *json =
      "{\"fps\": 30, \"gravity\": [0, 0, 0], \"integrator\": {\"type\": \"quasistatic\"},"
      " \"solids\": [{\"name\": \"block\", \"mesh\": {\"generate\": \"box\", \"center\": [0, 0, "
      "0.05], \"half_extents\": [0.1, 0.1, 0.05], \"cell_size\": 0.025},"
      " \"material\": {\"model\": \"neohookean\", \"youngs_modulus\": 1e5, \"poisson_ratio\": 0.4},"
      " \"fixed\": [{\"box\": [[-1, -1, -1], [1, 1, 0.0005]]}]}],"
      " \"obstacles\": [{\"type\": \"box\", \"center\": [0.03, 0.02, 0.13], \"half_extents\": "
      "[0.04, 0.03, 0.03], \"motion\": {\"translation\": [0, 0, {\"keys\": [[0, 0], "
      "[0.16666666666666666, -0.01]]}]}}]}";
  piola_scene *scene = NULL;
  if (piola_scene_load_string(json, ".", NULL, &scene) != PIOLA_OK)
    fail_msg("%s", piola_last_error());
  piola_world *w = piola_scene_world(scene);
  assert_int_equal(piola_world_advance_to(w, 5.0 / 30, NULL), PIOLA_OK);
  const piola_body_id block = piola_world_body_of(w, PIOLA_BODY_SOLID, 0);
  const int32_t n = piola_world_body_node_count(w, block);
  double *pressed = malloc(sizeof(double) * 3 * (size_t)n);
  memcpy(pressed, piola_world_body_positions(w, block), sizeof(double) * 3 * (size_t)n);
  double depth = 0; /* the press reached the block */
  for (int32_t i = 0; i < n; ++i) depth = fmax(depth, 0.1 - pressed[3 * i + 2]);
  assert_true(depth > 0.005);
  for (int f = 6; f <= 8; ++f) {
    piola_step_stats st;
    memset(&st, 0, sizeof st);
    assert_int_equal(piola_world_advance_to(w, f / 30.0, &st), PIOLA_OK);
    assert_int_equal(st.newton_iterations, 0);
    assert_int_equal(st.newton_failures, 0);
    const double *x = piola_world_body_positions(w, block);
    for (int32_t j = 0; j < 3 * n; ++j) assert_close(x[j], pressed[j], 1e-12);
  }
  free(pressed);
  piola_scene_destroy(scene);
}

static double potential_at(piola_elastic_body *body, const double *x, const double g[3],
                           double *forces) {
  piola_elastic_stats stats;
  assert_int_equal(piola_elastic_body_update(body, x, 1.0, forces, &stats), PIOLA_OK);
  const double energy = piola__elastic_body_total_energy(body);
  assert_true(fabs(energy - stats.elastic_energy) <= 1e-12 * fabs(stats.elastic_energy));
  const double *m = piola_elastic_body_masses(body);
  double work = 0;
  for (int32_t i = 0; i < piola_elastic_body_vertex_count(body); ++i)
    work += m[i] * (g[0] * x[3 * i] + g[1] * x[3 * i + 1] + g[2] * x[3 * i + 2]);
  return energy - work;
}

static void potential_gradient_is_the_residual(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(8, 2, 2, (piola_vec3){0.5 / 8, 0.04, 0.04}, &mesh),
                   PIOLA_OK);
  piola_material material = fixture_material(PIOLA_MODEL_NEOHOOKEAN);
  piola_elastic_body *body = fixture_body(&mesh, &material);
  const int32_t n = piola_elastic_body_vertex_count(body);
  const double *x0 = piola_elastic_body_rest_positions(body);
  double *x = malloc(sizeof(double) * 3 * (size_t)n), *d = malloc(sizeof(double) * 3 * (size_t)n);
  double *f = malloc(sizeof(double) * 3 * (size_t)n), *scratch = malloc(sizeof(double) * 3 * (size_t)n);
  const double g[3] = {0, 7.5, -22.5};
  uint64_t seed = 12345;
  for (int32_t i = 0; i < 3 * n; ++i) {
    /* bent down along x and stretched 10%, every coordinate nudged by up to 2 mm; d random */
    const double xi = x0[3 * (i / 3)];
    double v = x0[i] * (i % 3 == 0 ? 1.1 : 1.0) - (i % 3 == 2 ? 0.4 * xi * xi : 0.0);
    seed = seed * 6364136223846793005ull + 1442695040888963407ull;
    v += 0.004 * ((double)(seed >> 11) / 9007199254740992.0 - 0.5);
    x[i] = v;
    seed = seed * 6364136223846793005ull + 1442695040888963407ull;
    d[i] = (double)(seed >> 11) / 9007199254740992.0 - 0.5;
  }
  (void)potential_at(body, x, g, f);
  const double *m = piola_elastic_body_masses(body);
  double slope = 0; /* g . d with the residual g = -(f + M g) */
  for (int32_t i = 0; i < 3 * n; ++i) slope -= (f[i] + m[i / 3] * g[i % 3]) * d[i];
  const double h = 1e-6;
  for (int32_t i = 0; i < 3 * n; ++i) scratch[i] = x[i] + h * d[i];
  const double plus = potential_at(body, scratch, g, f);
  for (int32_t i = 0; i < 3 * n; ++i) scratch[i] = x[i] - h * d[i];
  const double minus = potential_at(body, scratch, g, f);
  const double difference = (plus - minus) / (2 * h);
  print_message("potential: slope %.9g, central difference %.9g\n", slope, difference);
  assert_true(fabs(difference - slope) <= 1e-6 * fabs(slope));
  free(x), free(d), free(f), free(scratch);
  piola_elastic_body_destroy(body);
  fixture_mesh_free(&mesh);
}

int main(void) {
  /* results do not depend on the thread count; one thread spares the thousands of CG
   * iterations a barrier each, which on a loaded machine can wait a scheduler slice */
  piola_set_thread_count(1);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(large_load_independent_of_increments),
      cmocka_unit_test(large_load_independent_of_forcing),
      cmocka_unit_test(small_load_matches_euler_bernoulli),
      cmocka_unit_test(soft_bar_increment_without_failed_newton),
      cmocka_unit_test(held_bar_failure_advises_a_ramp),
      cmocka_unit_test(backward_euler_failure_names_its_own_rule),
      cmocka_unit_test(free_block_failure_says_nothing_holds_it),
      cmocka_unit_test(pressed_block_stays_when_the_press_stops),
      cmocka_unit_test(potential_gradient_is_the_residual),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
