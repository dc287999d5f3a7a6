/* Self-collision inside the world step: a torus dropped onto a ball resting on the ground,
 * both elastic solids with self_collision enabled. At every frame no boundary triangle of
 * either solid may intersect another (exact referee, pairs sharing a vertex excepted); with
 * self-collision off the same scene does interpenetrate, so the check has teeth. */
#include "test_support.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <omp.h>

#include "contact/triangle_intersection.h"
#include "piola/mesh_io.h"
#include "piola/world.h"

typedef struct part {
  piola_tet_mesh mesh;
  piola_tri_mesh boundary;
} part;

static void load_part(part *p, const char *file, double size, const double centre[3]) {
  memset(p, 0, sizeof(*p));
  if (piola_tet_mesh_read(test_data_path(file), &p->mesh) != PIOLA_OK)
    fail_msg("%s: %s", file, piola_last_error());
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (int32_t i = 0; i < p->mesh.vertex_count; ++i)
    for (int k = 0; k < 3; ++k) {
      lo[k] = fmin(lo[k], p->mesh.positions[3 * i + k]);
      hi[k] = fmax(hi[k], p->mesh.positions[3 * i + k]);
    }
  double extent = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
  for (int32_t i = 0; i < p->mesh.vertex_count; ++i)
    for (int k = 0; k < 3; ++k) {
      double *x = &p->mesh.positions[3 * i + k];
      *x = (*x - 0.5 * (lo[k] + hi[k])) * size / extent + centre[k];
    }
  assert_int_equal(piola_tet_mesh_boundary(&p->mesh, &p->boundary), PIOLA_OK);
}

/* Intersecting boundary triangle pairs over both solids (positions from the world). */
static long count_intersections(const piola_world *w, const part parts[2]) {
  long hits = 0;
  for (int a_solid = 0; a_solid < 2; ++a_solid)
    for (int b_solid = a_solid; b_solid < 2; ++b_solid) {
      const double *xa = piola_world_solid_positions(w, a_solid);
      const double *xb = piola_world_solid_positions(w, b_solid);
      const piola_tri_mesh *ba = &parts[a_solid].boundary, *bb = &parts[b_solid].boundary;
      for (int32_t s = 0; s < ba->triangle_count; ++s)
        for (int32_t t = a_solid == b_solid ? s + 1 : 0; t < bb->triangle_count; ++t) {
          const int32_t *ta = ba->triangles + 3 * s, *tb = bb->triangles + 3 * t;
          if (a_solid == b_solid) {
            int shared = 0;
            for (int i = 0; i < 3; ++i)
              for (int j = 0; j < 3; ++j) shared |= ta[i] == tb[j];
            if (shared) continue;
          }
          const double *p[3] = {xa + 3 * ta[0], xa + 3 * ta[1], xa + 3 * ta[2]};
          const double *q[3] = {xb + 3 * tb[0], xb + 3 * tb[1], xb + 3 * tb[2]};
          int r = piola__triangles_intersect(p, q);
          assert_true(r >= 0);
          hits += r;
        }
    }
  return hits;
}

/* Runs the scene; returns the largest number of intersecting pairs seen at a frame. */
static long drop_torus_on_ball(int self_collision, int frames, piola_step_stats *total) {
  part parts[2];
  const double ball_at[3] = {0, 0, 0.101}, torus_at[3] = {0.02, 0.0, 0.26};
  load_part(&parts[0], "medit/unit_ball.mesh", 0.2, ball_at);
  load_part(&parts[1], "gmsh/torus.msh", 0.2, torus_at);
  piola_world_def wd = piola_default_world_def();
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_obstacle_def ground = piola_default_obstacle_def();
  ground.friction = 0.5;
  assert_int_equal(piola_world_add_obstacle(w, &ground, NULL), PIOLA_OK);
  for (int i = 0; i < 2; ++i) {
    piola_solid_def sd = piola_default_solid_def();
    sd.mesh = &parts[i].mesh;
    sd.material.youngs_modulus = 2e5;
    sd.shear_viscosity = piola_track_constant(2.0);
    sd.self_collision.enabled = self_collision != 0;
    sd.self_collision.thickness = 2e-3;
    sd.self_collision.friction = 0.3;
    if (i == 1) sd.velocity = (piola_vec3){0, 0, -3.0};
    assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  }
  assert_int_equal(count_intersections(w, parts), 0);
  long worst = 0;
  memset(total, 0, sizeof(*total));
  for (int f = 1; f <= frames; ++f) {
    assert_int_equal(piola_world_advance_to(w, 0.005 * f, total), PIOLA_OK);
    long bad = count_intersections(w, parts);
    if (bad > worst) worst = bad;
    if (self_collision && bad)
      fail_msg("frame %d: %ld intersecting boundary triangle pairs", f, bad);
  }
  piola_world_destroy(w);
  for (int i = 0; i < 2; ++i)
    piola_tet_mesh_free(&parts[i].mesh), piola_tri_mesh_free(&parts[i].boundary);
  return worst;
}

static void torus_dropped_on_ball_does_not_pass_through(void **state) {
  (void)state;
  const int frames = (int)test_samples(10, 8);
  piola_step_stats with, without;
  long worst = drop_torus_on_ball(1, frames, &with);
  assert_int_equal(worst, 0);
  assert_true(with.contacts + with.impacts > 0);
  /* The same scene without self-collision: the torus sinks into the ball. */
  long worst_off = drop_torus_on_ball(0, frames, &without);
  assert_true(worst_off > 0);
  assert_true(without.contacts + without.impacts + without.impact_zones == 0);
}

static void bad_self_collision_parameters_are_rejected(void **state) {
  (void)state;
  part p;
  const double at[3] = {0, 0, 0.2};
  load_part(&p, "gmsh/torus.msh", 0.2, at);
  piola_world_def wd = piola_default_world_def();
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = &p.mesh;
  sd.self_collision.enabled = true;
  sd.self_collision.thickness = 0.0;
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  sd.self_collision.thickness = 1e-3, sd.self_collision.friction = -1.0;
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  piola_world_destroy(w);
  piola_tet_mesh_free(&p.mesh), piola_tri_mesh_free(&p.boundary);
}

int main(void) {
  /* One thread: the world's parallel force loop and solves spin-wait badly on an
   * oversubscribed machine, and results do not depend on the thread count (the collision
   * module's own test checks that). */
  omp_set_num_threads(1);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(torus_dropped_on_ball_does_not_pass_through),
      cmocka_unit_test(bad_self_collision_parameters_are_rejected),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
