/* A quasistatic body with no equilibrium (docs/time-stepping.md, "Quasistatics"):
 * tetgen/armadillo_4k (1.37 m diagonal, corotated, E = 100 kPa) released 0.3 m above a
 * frictionless plane. Held by contacts alone it may slide and topple, so its Newton steps
 * fail. A failed step's last try keeps its last accepted iterate, and every accepted iterate
 * lowers the residual norm or the potential (elastic energy minus gravity's work), so after
 * the frame the potential is below the start's, the body did not leave the region above
 * the plane it started over, and the NEWTON_FAILED warning names it and says that a body
 * held by contacts alone has no equilibrium. Before, a line search
 * that found no decrease left the last rejected trial in place (1/2048 of a Newton step
 * that the vanishing regularization made 1e38 m long) and the last try kept it: the body
 * ended 1e10 m away, no warning.
 *
 * medit/unit_ball.mesh (radius 1 m, E = 100 kPa) resting on a frictionless plane: it may
 * slide and turn along the plane at no cost, so -K + mu M is singular there but for mu. A
 * step along those free directions is as long as the regularization is small; the full
 * steps shrank it to 1e-22 of its first value and the ball ended its first frame 1e6 m away,
 * its second 1e11 m. No Newton iteration may now move a node further than the body's size,
 * and a failed step whose iterate did is not kept: after every frame each node is within the
 * ball's bounding diagonal of where it started, over the plane. Its first try (the whole of
 * its weight on one point of the plane at once) fails; its retry, whose load is the same,
 * goes on from where that try stopped and converges (since 2026-12-08; before, every try
 * failed and the last was kept, with a warning), and the next frames, at rest, take no
 * Newton iteration. The mesh's first vertex is in no tet (held, massless). */
#include "test_support.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "piola/elastic_body.h"
#include "piola/threads.h"
#include "piola/world.h"
#include "real_mesh_scenes.h"

#define DIAGONAL 1.37

static void armadillo_on_frictionless_plane(void **state) {
  (void)state;
  piola_world_def wd = piola_default_world_def();
  wd.gravity[1] = piola_track_constant(-9.81);
  wd.gravity[2] = piola_track_constant(0);
  wd.integrator = PIOLA_INTEGRATOR_QUASISTATIC;
  wd.implicit_dt = 1.0 / 30;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_tet_mesh mesh = real_mesh_scaled("tetgen/armadillo_4k.node", DIAGONAL);
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int32_t v = 0; v < mesh.vertex_count; ++v)
    for (int k = 0; k < 3; ++k)
      lo[k] = fmin(lo[k], mesh.positions[3 * v + k]), hi[k] = fmax(hi[k], mesh.positions[3 * v + k]);
  piola_solid_def sd = piola_default_solid_def();
  sd.name = "armadillo";
  sd.mesh = &mesh;
  sd.material = real_mesh_material_def(PIOLA_MODEL_COROTATED, 1e5, 0.3);
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  piola_obstacle_def g = piola_default_obstacle_def();
  g.type = PIOLA_OBSTACLE_PLANE;
  g.center = (piola_vec3){0, lo[1] - 0.3, 0};
  g.axis = (piola_vec3){0, 1, 0};
  g.friction = 0;
  assert_int_equal(piola_world_add_obstacle(w, &g, NULL), PIOLA_OK);

  const int32_t n = mesh.vertex_count;
  const piola_elastic_body *body = piola_world_solid_body(w, 0);
  const double *mass = piola_elastic_body_masses(body);
  /* the potential at the start: no elastic energy, and gravity's work counted from there */
  const double *x = piola_world_solid_positions(w, 0);
  double height0 = 0;
  for (int32_t i = 0; i < n; ++i) height0 += mass[i] * x[3 * i + 1];

  piola_step_stats st = {0};
  assert_int_equal(piola_world_advance_to(w, 1.0 / 30, &st), PIOLA_OK);
  assert_true(real_mesh_solid_finite(w));
  x = piola_world_solid_positions(w, 0);
  double height = 0;
  for (int32_t i = 0; i < n; ++i) {
    height += mass[i] * x[3 * i + 1];
    /* over the plane it started above, and not beyond its start's extent on it */
    assert_true(x[3 * i + 1] >= g.center.y - 1e-9);
    for (int k = 0; k < 3; k += 2)
      if (!(x[3 * i + k] >= lo[k] - DIAGONAL && x[3 * i + k] <= hi[k] + DIAGONAL))
        fail_msg("vertex %d at %g along axis %d, started within [%g, %g]", (int)i, x[3 * i + k], k,
                 lo[k], hi[k]);
  }
  const double elastic = piola_world_solid_stats(w, 0).elastic_energy;
  const double potential = elastic + 9.81 * (height - height0);
  if (!(potential <= 1e-9))
    fail_msg("potential %g J (elastic %g J) above the start's 0 after %d Newton failures", potential,
             elastic, (int)st.newton_failures);
  /* the scene has no equilibrium in its first frame: the run says so, naming the solid */
  assert_true(st.newton_failures > 0);
  const char *text = piola_world_warning(w, PIOLA_WARNING_NEWTON_FAILED);
  assert_non_null(text);
  assert_non_null(strstr(text, "'armadillo'"));
  /* held by the plane alone: the advice is a support, not a ramp of the load */
  assert_non_null(strstr(text, "held by obstacle contacts alone has no equilibrium"));
  assert_null(strstr(text, "ramped"));
  piola_tet_mesh_free(&mesh);
  piola_world_destroy(w);
}

static void ball_resting_on_frictionless_plane(void **state) {
  (void)state;
  piola_world_def wd = piola_default_world_def();
  wd.integrator = PIOLA_INTEGRATOR_QUASISTATIC;
  wd.implicit_dt = 1.0 / 30;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_tet_mesh mesh = real_mesh_read("medit/unit_ball.mesh");
  piola_solid_def sd = piola_default_solid_def();
  sd.name = "ball";
  sd.mesh = &mesh;
  sd.material = real_mesh_material_def(PIOLA_MODEL_NEOHOOKEAN, 1e5, 0.3);
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  double bottom = INFINITY;
  for (int32_t v = 0; v < mesh.vertex_count; ++v) bottom = fmin(bottom, mesh.positions[3 * v + 2]);
  piola_obstacle_def g = piola_default_obstacle_def();
  g.type = PIOLA_OBSTACLE_PLANE;
  g.center = (piola_vec3){0, 0, bottom};
  g.axis = (piola_vec3){0, 0, 1};
  g.friction = 0;
  assert_int_equal(piola_world_add_obstacle(w, &g, NULL), PIOLA_OK);
  const double size = 2 * sqrt(3.0); /* the bounding diagonal of a unit ball */
  piola_step_stats st = {0};
  for (int frame = 1; frame <= 3; ++frame) {
    piola_step_stats this_frame = {0};
    assert_int_equal(piola_world_advance_to(w, frame / 30.0, &this_frame), PIOLA_OK);
    st.newton_failures += this_frame.newton_failures;
    if (frame > 1) assert_int_equal(this_frame.newton_iterations, 0); /* at rest */
    assert_true(real_mesh_solid_finite(w));
    const double *x = piola_world_solid_positions(w, 0);
    for (int32_t i = 0; i < mesh.vertex_count; ++i) {
      double d2 = 0;
      for (int k = 0; k < 3; ++k) d2 += pow(x[3 * i + k] - mesh.positions[3 * i + k], 2);
      if (!(sqrt(d2) <= size))
        fail_msg("frame %d: vertex %d moved %g m (the ball's size %g m)", frame, (int)i, sqrt(d2),
                 size);
      assert_true(x[3 * i + 2] >= bottom - 1e-9);
    }
  }
  /* the first try fails, and its retry, from where it stopped, converges */
  assert_true(st.newton_failures > 0);
  assert_null(piola_world_warning(w, PIOLA_WARNING_NEWTON_FAILED));
  piola_tet_mesh_free(&mesh);
  piola_world_destroy(w);
}

int main(void) {
  piola_set_thread_count(1);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(armadillo_on_frictionless_plane),
      cmocka_unit_test(ball_resting_on_frictionless_plane),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
