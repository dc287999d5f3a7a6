/* Every example in examples/, solids and shells, runs with "backward_euler" at one step per
 * frame (the default integrator.dt): the first frames (more with PIOLA_TEST_SCALE >= 1),
 * and at every frame
 *  - every coordinate and velocity of every solid and shell is finite;
 *  - no free node of a solid or a shell is inside an analytic obstacle of the scene (signed
 *    distance >= -1e-6 m; mesh obstacles are not checked here);
 *  - no free node of the shell coupled one way to a solid (collide_with_solids: the cape)
 *    is inside that solid by more than 1% of its longest boundary edge (inside: by the side
 *    of the closest boundary triangle, as the coupling decides);
 *  - where no external force acts (ball_recovers: zero gravity, no obstacle, no constraint)
 *    each solid's linear momentum stays zero;
 *  - solids_stack through the torus's impact on the ball (frame 7 of 60 fps; 12 frames, only
 *    at PIOLA_TEST_SCALE >= 1): at most 2% of the tets inverted in any frame. The collision
 *    pass stops only the surface nodes; before the implicit step re-solved the bodies behind
 *    it (implicit_step.c, self_collide_and_resolve) the interiors ran through their surfaces
 *    and 416 of the 2,952 tets (14%) were inverted at frame 10 (measured since: at most 28,
 *    at frame 8). */
#include "test_support.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "piola/scene.h"
#include "piola/shell_body.h"
#include "piola/world_shells.h"

/* The scene text with "type": "backward_euler" in its integrator object. */
static char *backward_euler_text(const char *path) {
  char *text = test_read_text(path);
  const char *key = "\"integrator\": {";
  const char *insert = "\"type\": \"backward_euler\", ";
  char *at = strstr(text, key);
  size_t cut;
  char *out = malloc(strlen(text) + 128);
  if (at) {
    cut = (size_t)(at - text) + strlen(key);
    memcpy(out, text, cut);
    strcpy(out + cut, insert);
  } else {
    at = strchr(text, '{');
    assert_non_null(at);
    cut = (size_t)(at - text) + 1;
    memcpy(out, text, cut);
    strcpy(out + cut, "\"integrator\": {\"type\": \"backward_euler\"}, ");
  }
  strcat(out, text + cut);
  free(text);
  return out;
}

/* Squared distance from p to triangle (a, b, c) and the closest point cp: the minimum over
 * the face (when p projects inside it) and the three edges. */
static double closest_on_triangle(const double *p, const double *a, const double *b,
                                  const double *c, double cp[3]) {
  double best = INFINITY;
  const double *ends[3][2] = {{a, b}, {b, c}, {c, a}};
  for (int e = 0; e < 3; ++e) {
    const double *u = ends[e][0], *v = ends[e][1];
    const double d[3] = {v[0] - u[0], v[1] - u[1], v[2] - u[2]};
    const double dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    double s = dd > 0 ? ((p[0] - u[0]) * d[0] + (p[1] - u[1]) * d[1] + (p[2] - u[2]) * d[2]) / dd : 0;
    s = fmin(1.0, fmax(0.0, s));
    const double q[3] = {u[0] + s * d[0], u[1] + s * d[1], u[2] + s * d[2]};
    const double d2 = (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]);
    if (d2 < best) best = d2, memcpy(cp, q, sizeof q);
  }
  const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double w[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]};
  const double d11 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
  const double d12 = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2];
  const double d22 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
  const double w1 = w[0] * e1[0] + w[1] * e1[1] + w[2] * e1[2], w2 = w[0] * e2[0] + w[1] * e2[1] + w[2] * e2[2];
  const double det = d11 * d22 - d12 * d12;
  if (det > 0) {
    const double s = (d22 * w1 - d12 * w2) / det, t = (d11 * w2 - d12 * w1) / det;
    if (s >= 0 && t >= 0 && s + t <= 1) {
      const double q[3] = {a[0] + s * e1[0] + t * e2[0], a[1] + s * e1[1] + t * e2[1],
                           a[2] + s * e1[2] + t * e2[2]};
      const double d2 = (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]);
      if (d2 < best) best = d2, memcpy(cp, q, sizeof q);
    }
  }
  return best;
}

/* Fails when a free shell node (x, n nodes) lies inside solid k of w by more than 1% of the
 * solid's longest boundary edge: inside by the side of the closest boundary triangle, as
 * the coupling decides (docs/shells.md), searched over every boundary triangle. */
static void check_outside_solid(const char *file, int frame, const piola_world *w, int32_t k,
                                const double *x, const uint8_t *flags, int32_t n) {
  const piola_elastic_body *b = piola_world_solid_body(w, k);
  piola_tet_mesh mesh = {.vertex_count = piola_elastic_body_vertex_count(b),
                         .positions = (double *)piola_world_solid_positions(w, k),
                         .tet_count = piola_elastic_body_tet_count(b),
                         .tets = (int32_t *)piola_elastic_body_tets(b)};
  piola_tri_mesh surface;
  assert_int_equal(piola_tet_mesh_boundary(&mesh, &surface), PIOLA_OK);
  const double *sx = mesh.positions;
  double reach = 0;
  for (int32_t t = 0; t < surface.triangle_count; ++t)
    for (int c = 0; c < 3; ++c) {
      const double *p = sx + 3 * surface.triangles[3 * t + c];
      const double *q = sx + 3 * surface.triangles[3 * t + (c + 1) % 3];
      reach = fmax(reach, sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                               (p[2] - q[2]) * (p[2] - q[2])));
    }
  for (int32_t i = 0; i < n; ++i) {
    if (flags && flags[i]) continue;
    const double *p = x + 3 * i;
    double best = INFINITY, side = 0;
    for (int32_t t = 0; t < surface.triangle_count; ++t) {
      const int32_t *tri = surface.triangles + 3 * t;
      const double *a = sx + 3 * tri[0], *bb = sx + 3 * tri[1], *c = sx + 3 * tri[2];
      double cp[3] = {0, 0, 0};
      const double d2 = closest_on_triangle(p, a, bb, c, cp);
      if (!(d2 < best)) continue;
      const double e1[3] = {bb[0] - a[0], bb[1] - a[1], bb[2] - a[2]};
      const double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      const double nrm[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                             e1[0] * e2[1] - e1[1] * e2[0]};
      best = d2;
      side = (p[0] - cp[0]) * nrm[0] + (p[1] - cp[1]) * nrm[1] + (p[2] - cp[2]) * nrm[2];
    }
    if (side < 0 && sqrt(best) > 0.01 * reach)
      fail_msg("%s frame %d: shell vertex %d is %g m inside solid %d", file, frame, (int)i,
               sqrt(best), (int)k);
  }
  piola_tri_mesh_free(&surface);
}

/* Fails unless vertex i of solid or shell s (kind), at xi, is outside (or within 1e-6 m of)
 * each analytic obstacle of the scene at time t (NULL entries: mesh obstacles, not measured). */
static void check_outside_obstacles(const char *file, int f, const char *kind, int32_t s, int32_t i,
                                    const double *xi, piola_obstacle *const *obstacles, int32_t no,
                                    double t) {
  piola_vec3 q = {xi[0], xi[1], xi[2]};
  for (int32_t o = 0; o < no; ++o) {
    if (!obstacles[o]) continue;
    double phi = piola_obstacle_signed_distance(obstacles[o], t, q, NULL, NULL);
    if (!(phi >= -1e-6))
      fail_msg("%s frame %d: %s %d vertex %d is %g m inside obstacle %d", file, f, kind, (int)s,
               (int)i, -phi, (int)o);
  }
}

static void run_checked(const char *file, int frames, int free_momentum, double max_inverted_fraction,
                        int coupled_shells) {
  char path[1024], dir[1024];
  snprintf(path, sizeof path, "%s/examples/%s", PIOLA_SOURCE_DIR, file);
  snprintf(dir, sizeof dir, "%s/examples", PIOLA_SOURCE_DIR);
  char *text = backward_euler_text(path);
  piola_scene_desc *desc = NULL;
  if (piola_scene_parse_string(text, dir, file, &desc) != PIOLA_OK) fail_msg("%s: %s", file, piola_last_error());
  piola_scene *scene = NULL;
  if (piola_scene_build(desc, &scene) != PIOLA_OK) fail_msg("%s: %s", file, piola_last_error());
  piola_world *w = piola_scene_world(scene);
  const double fps = piola_scene_fps(scene);
  /* the scene's analytic obstacles, to measure penetration */
  int32_t no = piola_scene_desc_obstacle_count(desc);
  piola_obstacle **obstacles = calloc((size_t)no + 1, sizeof *obstacles);
  for (int32_t o = 0; o < no; ++o) {
    piola_obstacle_def def = piola_scene_desc_obstacle(desc, o, NULL);
    if (def.type == PIOLA_OBSTACLE_MESH) continue;
    assert_int_equal(piola_obstacle_create(&def, &obstacles[o]), PIOLA_OK);
  }
  if (frames > piola_scene_frames(scene)) frames = piola_scene_frames(scene);
  for (int f = 1; f <= frames; ++f) {
    piola_step_stats st;
    memset(&st, 0, sizeof st);
    if (piola_world_advance_to(w, f / fps, &st) != PIOLA_OK)
      fail_msg("%s frame %d: %s", file, f, piola_last_error());
    if (st.newton_failures == 0) assert_int_equal(st.substeps, 1);
    const double t = piola_world_time(w);
    int32_t inverted = 0, tets = 0;
    for (int32_t s = 0; s < piola_world_solid_count(w); ++s) {
      inverted += piola_world_solid_stats(w, s).inverted_count;
      tets += piola_elastic_body_tet_count(piola_world_solid_body(w, s));
    }
    if (max_inverted_fraction >= 0) {
      print_message("%s frame %d: %d of %d tets inverted\n", file, f, (int)inverted, (int)tets);
      if (!(inverted <= max_inverted_fraction * tets))
        fail_msg("%s frame %d: %d of %d tets inverted", file, f, (int)inverted, (int)tets);
    }
    for (int32_t s = 0; s < piola_world_solid_count(w); ++s) {
      const piola_elastic_body *b = piola_world_solid_body(w, s);
      const int32_t n = piola_elastic_body_vertex_count(b);
      const double *x = piola_world_solid_positions(w, s), *v = piola_world_solid_velocities(w, s);
      const uint8_t *flags = piola_world_solid_constraint_flags(w, s);
      const double *m = piola_elastic_body_masses(b);
      double p[3] = {0, 0, 0}, scale = 0;
      for (int32_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k) {
          if (!isfinite(x[3 * i + k]) || !isfinite(v[3 * i + k]))
            fail_msg("%s frame %d: solid %d vertex %d not finite", file, f, (int)s, (int)i);
          p[k] += m[i] * v[3 * i + k];
          scale += m[i] * fabs(v[3 * i + k]);
        }
        if (flags && flags[i]) continue;
        check_outside_obstacles(file, f, "solid", s, i, x + 3 * i, obstacles, no, t);
      }
      if (free_momentum)
        for (int k = 0; k < 3; ++k)
          if (!(fabs(p[k]) <= 1e-9 * (scale + 1e-12)))
            fail_msg("%s frame %d: solid %d momentum %g (scale %g)", file, f, (int)s, p[k], scale);
    }
    for (int32_t s = 0; s < piola_world_shell_count(w); ++s) {
      const piola_shell_body *b = piola_world_shell_body(w, s);
      const int32_t n = piola_shell_body_vertex_count(b);
      const double *x = piola_world_shell_positions(w, s), *v = piola_world_shell_velocities(w, s);
      const uint8_t *flags = piola_world_shell_constraint_flags(w, s);
      for (int32_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k)
          if (!isfinite(x[3 * i + k]) || !isfinite(v[3 * i + k]))
            fail_msg("%s frame %d: shell %d vertex %d not finite", file, f, (int)s, (int)i);
        if (flags && flags[i]) continue;
        check_outside_obstacles(file, f, "shell", s, i, x + 3 * i, obstacles, no, t);
      }
      if (coupled_shells)
        for (int32_t k = 0; k < piola_world_solid_count(w); ++k)
          check_outside_solid(file, f, w, k, x, flags, n);
    }
  }
  for (int32_t o = 0; o < no; ++o) piola_obstacle_destroy(obstacles[o]);
  free(obstacles);
  piola_scene_destroy(scene);
  piola_scene_desc_destroy(desc);
  free(text);
}

static void run(const char *file, int frames, int free_momentum) {
  run_checked(file, frames, free_momentum, -1, 0);
}

static int frames_light(void) { return (int)test_samples(6, 2); }
static int frames_heavy(void) { return test_scale() >= 1.0 ? 2 : 0; }

static void ball_recovers(void **state) { (void)state; run("ball_recovers.json", frames_light(), 1); }
static void squeezed_solid(void **state) { (void)state; run("squeezed_solid.json", frames_light(), 0); }
static void torus_puddle(void **state) { (void)state; run("torus_puddle.json", frames_light(), 0); }
static void solids_stack(void **state) { (void)state; run("solids_stack.json", frames_light(), 0); }
static void solids_stack_impact(void **state) {
  (void)state;
  if (test_scale() >= 1.0) run_checked("solids_stack.json", 12, 0, 0.02, 0);
}
static void muscle_spindle(void **state) { (void)state; run("muscle_spindle.json", frames_light(), 0); }
static void muscle_spindle_hanging(void **state) {
  (void)state;
  run("muscle_spindle_hanging.json", frames_light(), 0);
}
static void plastic_control(void **state) { (void)state; run("plastic_control.json", frames_light(), 0); }
static void plastic_bar_bend(void **state) { (void)state; run("plastic_bar_bend.json", frames_heavy(), 0); }
static void arm_flex(void **state) { (void)state; run("arm_flex.json", frames_heavy(), 0); }
static void gears(void **state) { (void)state; run("gears.json", frames_heavy(), 0); }
/* Through the nip (18 frames): friction's move after the solve, along an obstacle's tangent
 * plane, left a ball node 0.4 mm inside a gear tooth at frame 17 before every step's end
 * projected the nodes out of the obstacles (docs/time-stepping.md, "The step's end"). */
static void gears_through_the_nip(void **state) {
  (void)state;
  run("gears.json", test_scale() >= 1.0 ? 18 : 0, 0);
}
static void armadillo_incline(void **state) { (void)state; run("armadillo_incline.json", frames_heavy(), 0); }
static void plastic_sphere_gears(void **state) {
  (void)state;
  run("plastic_sphere_gears.json", frames_heavy(), 0);
}

static void cloth_on_sphere(void **state) { (void)state; run("cloth_on_sphere.json", frames_light(), 0); }
static void dented_torus_shell(void **state) { (void)state; run("dented_torus_shell.json", frames_light(), 0); }
/* A stiff cloth (E = 1 MPa, 0.5 mm) dropped onto a sphere with friction 0.5, one step per
 * 1/30 s frame: friction's moves after the solve, each below the altitude rule's, stored up
 * to 0.41 J of stretch in a body that started with 0.23 J (kinetic, elastic and gravity's
 * together) and gained energy from frame to frame. Now its energy falls in every frame. */
static void cloth_on_a_frictional_sphere_gains_no_energy(void **state) {
  (void)state;
  if (test_scale() < 1.0) return;
  static const char scene[] =
      "{\"fps\": 30, \"integrator\": {\"type\": \"backward_euler\", \"newton_max_iterations\": "
      "200},"
      " \"shells\": [{\"mesh\": {\"generate\": \"rectangle\", \"size\": [0.6, 0.6],"
      " \"resolution\": [24, 24]}, \"transform\": {\"translate\": [0, 0, 0.32]},"
      " \"thickness\": 0.0005, \"density\": 400, \"material\": {\"model\": \"corotated\","
      " \"youngs_modulus\": 1e6, \"poisson_ratio\": 0.3}, \"damping\": {\"shear\": 1, \"bulk\": 1},"
      " \"bending\": {\"stiffness\": 1e-6, \"damping\": 1e-7}}],"
      " \"obstacles\": [{\"type\": \"sphere\", \"center\": [0, 0, 0.1], \"radius\": 0.2, "
      "\"friction\": 0.5},"
      " {\"type\": \"plane\", \"point\": [0, 0, 0], \"normal\": [0, 0, 1], \"friction\": 0.5}]}";
  piola_scene_desc *desc = NULL;
  if (piola_scene_parse_string(scene, ".", "cloth.json", &desc) != PIOLA_OK)
    fail_msg("%s", piola_last_error());
  piola_scene *built = NULL;
  if (piola_scene_build(desc, &built) != PIOLA_OK) fail_msg("%s", piola_last_error());
  piola_world *w = piola_scene_world(built);
  /* kinetic energy from the stats; gravity's potential from the lumped masses */
  const double *mass = piola_shell_body_masses(piola_world_shell_body(w, 0));
  const int32_t nodes = piola_shell_body_vertex_count(piola_world_shell_body(w, 0));
  double last = INFINITY, peak = 0;
  for (int f = 0; f <= 7; ++f) {
    if (f > 0 && piola_world_advance_to(w, f / 30.0, NULL) != PIOLA_OK)
      fail_msg("frame %d: %s", f, piola_last_error());
    const double *x = piola_world_shell_positions(w, 0);
    const piola_world_shell_stats st = piola_world_shell_get_stats(w, 0);
    double energy = st.kinetic_energy + st.membrane_energy + st.bending_energy;
    for (int32_t i = 0; i < nodes; ++i) energy += mass[i] * 9.81 * x[3 * i + 2];
    print_message("cloth on a frictional sphere, frame %d: energy %.6f J, elastic %.6f J\n", f,
                  energy, st.membrane_energy + st.bending_energy);
    assert_true(energy <= last * (1 + 1e-9));
    last = energy;
    peak = fmax(peak, st.membrane_energy + st.bending_energy);
  }
  assert_true(peak < 0.02);
  piola_scene_destroy(built);
  piola_scene_desc_destroy(desc);
}

/* Friction's move after the solve is solved again for shells where it is large against a
 * triangle or raises the body's energy, and acts on the velocities alone where that solve
 * stores energy too (docs/time-stepping.md, "Friction after the solve"): the move alone
 * locked strain into the dented torus as it landed, its elastic energy peaking at 1.86 J in
 * 20 frames (Newmark: 0.034 J); solved again only for large moves 0.38 J; now 0.036 J. */
static void dented_torus_shell_friction_locks_no_strain(void **state) {
  (void)state;
  if (test_scale() < 1.0) return;
  char path[1024], dir[1024];
  snprintf(path, sizeof path, "%s/examples/dented_torus_shell.json", PIOLA_SOURCE_DIR);
  snprintf(dir, sizeof dir, "%s/examples", PIOLA_SOURCE_DIR);
  char *text = backward_euler_text(path);
  piola_scene_desc *desc = NULL;
  if (piola_scene_parse_string(text, dir, "dented_torus_shell.json", &desc) != PIOLA_OK)
    fail_msg("%s", piola_last_error());
  piola_scene *scene = NULL;
  if (piola_scene_build(desc, &scene) != PIOLA_OK) fail_msg("%s", piola_last_error());
  piola_world *w = piola_scene_world(scene);
  double peak = 0;
  for (int f = 1; f <= 20; ++f) {
    if (piola_world_advance_to(w, f / piola_scene_fps(scene), NULL) != PIOLA_OK)
      fail_msg("frame %d: %s", f, piola_last_error());
    const piola_world_shell_stats st = piola_world_shell_get_stats(w, 0);
    peak = fmax(peak, st.membrane_energy + st.bending_energy);
  }
  print_message("dented torus shell, backward Euler: peak elastic energy %g J\n", peak);
  assert_true(peak < 0.1);
  piola_scene_destroy(scene);
  piola_scene_desc_destroy(desc);
  free(text);
}
static void cloth_cape_on_body(void **state) {
  (void)state;
  run_checked("cloth_cape_on_body.json", (int)frames_light(), 0, -1, 1);
}
static void cloth_folds(void **state) { (void)state; run("cloth_folds.json", frames_light(), 0); }
static void cloth_on_jelly(void **state) { (void)state; run("cloth_on_jelly.json", frames_light(), 0); }

int main(void) {
  piola_set_thread_count(1);
  omp_set_num_threads(1);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(ball_recovers),
      cmocka_unit_test(squeezed_solid),
      cmocka_unit_test(torus_puddle),
      cmocka_unit_test(solids_stack),
      cmocka_unit_test(solids_stack_impact),
      cmocka_unit_test(muscle_spindle),
      cmocka_unit_test(muscle_spindle_hanging),
      cmocka_unit_test(plastic_control),
      cmocka_unit_test(plastic_bar_bend),
      cmocka_unit_test(arm_flex),
      cmocka_unit_test(gears),
      cmocka_unit_test(gears_through_the_nip),
      cmocka_unit_test(armadillo_incline),
      cmocka_unit_test(plastic_sphere_gears),
      cmocka_unit_test(cloth_on_sphere),
      cmocka_unit_test(dented_torus_shell),
      cmocka_unit_test(dented_torus_shell_friction_locks_no_strain),
      cmocka_unit_test(cloth_on_a_frictional_sphere_gains_no_energy),
      cmocka_unit_test(cloth_cape_on_body),
      cmocka_unit_test(cloth_folds),
      cmocka_unit_test(cloth_on_jelly),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
