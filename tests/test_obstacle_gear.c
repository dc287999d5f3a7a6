/* The gear obstacle: teeth and gaps where the profile says, exact distance to its outline
 * (the nearest-teeth search agrees with a search over every edge), and two equal gears
 * placed as docs/obstacles.md says interlock without overlapping. */
#include <math.h>
#include <stdlib.h>

#include "test_support.h"

#include "math/mat3.h"
#include "piola/obstacle.h"
#include "sim/obstacle_internal.h"

static piola_obstacle *make(const piola_obstacle_def *def) {
  piola_obstacle *o = NULL;
  piola_status s = piola_obstacle_create(def, &o);
  if (s != PIOLA_OK) fail_msg("obstacle_create: %s", piola_last_error());
  return o;
}

static piola_obstacle_def gear_def(int teeth) {
  piola_obstacle_def d = piola_default_obstacle_def();
  d.type = PIOLA_OBSTACLE_GEAR;
  d.radius = 0.1;
  d.tooth_depth = 0.02;
  d.tooth_count = teeth;
  d.half_length = 0.03;
  return d;
}

static double phi(const piola_obstacle *o, double t, vec3 p) {
  return piola_obstacle_signed_distance(o, t, p, NULL, NULL);
}

static vec3 polar(double r, double angle, double z) {
  return vec3_make(r * cos(angle), r * sin(angle), z);
}

static void teeth_are_inside_and_gaps_outside(void **state) {
  (void)state;
  for (int teeth = 3; teeth <= 40; teeth += 37 / 4) {
    piola_obstacle_def d = gear_def(teeth);
    piola_obstacle *o = make(&d);
    double period = 2 * M_PI / teeth, tip = 0.1, root = 0.08;
    for (int j = 0; j < teeth; ++j) {
      for (int k = 1; k < 10; ++k) {
        double r = root + (tip - root) * k / 10.0;
        /* In tooth j (on its centre line), between root and tip: inside. */
        double in_tooth = phi(o, 0, polar(r, j * period, 0.01));
        assert_true(in_tooth < 0);
        /* In the gap after tooth j, same radius: outside. */
        double in_gap = phi(o, 0, polar(r, (j + 0.5) * period, 0.01));
        assert_true(in_gap > 0);
      }
      /* Just below a tooth tip on its centre line: the tip land (a polygon chord through the
       * tip vertex, tilted by less than 2 degrees) is the nearest surface. */
      assert_close(phi(o, 0, polar(tip - 2e-4, j * period, 0)), -2e-4, 2e-4 * 1e-3);
      /* Just above a tip: the same outside. */
      assert_close(phi(o, 0, polar(tip + 0.005, j * period, 0)), 0.005, 1e-15);
      /* Far away along a tooth: distance to the tip. */
      assert_close(phi(o, 0, polar(2.0, j * period, 0)), 2.0 - tip, 1e-12);
      /* Above the gear face inside the hub: the axial distance. */
      assert_close(phi(o, 0, polar(0.03, j * period, 0.05)), 0.02, 1e-15);
      /* The profile function: tips on tooth centres, roots in the gap centres. */
      assert_close(piola__gear_profile_radius(&o->shape.gear, j * period), tip, 1e-15);
      assert_close(piola__gear_profile_radius(&o->shape.gear, (j + 0.5) * period), root, 1e-15);
    }
    /* The centre is inside by the hub: at least the face distance, at most the root radius. */
    assert_close(phi(o, 0, vec3_make(0, 0, 0)), -0.03, 1e-15);
    piola_obstacle_destroy(o);
  }
}

static double brute_outline_distance(const piola__gear_shape *g, double x, double y) {
  double best = INFINITY;
  for (int32_t i = 0; i < g->vertex_count; ++i) {
    int32_t j = (i + 1) % g->vertex_count;
    double ax = g->outline[2 * i], ay = g->outline[2 * i + 1];
    double ex = g->outline[2 * j] - ax, ey = g->outline[2 * j + 1] - ay;
    double s = fmax(0, fmin(1, ((x - ax) * ex + (y - ay) * ey) / (ex * ex + ey * ey)));
    best = fmin(best, hypot(x - ax - s * ex, y - ay - s * ey));
  }
  /* Inside by the crossing number (even-odd) over all edges: independent of the star test. */
  int crossings = 0;
  for (int32_t i = 0; i < g->vertex_count; ++i) {
    int32_t j = (i + 1) % g->vertex_count;
    double ax = g->outline[2 * i], ay = g->outline[2 * i + 1];
    double bx = g->outline[2 * j], by = g->outline[2 * j + 1];
    if ((ay > y) != (by > y) && x < ax + (y - ay) * (bx - ax) / (by - ay)) ++crossings;
  }
  return crossings % 2 ? -best : best;
}

/* The nearest-teeth search with its bound is exact: it matches all edges with the even-odd
 * inside test, near the teeth and far away, for few and many teeth. */
static void distance_matches_search_over_all_edges(void **state) {
  (void)state;
  const int counts[] = {3, 4, 5, 7, 12, 31};
  for (size_t c = 0; c < sizeof counts / sizeof *counts; ++c) {
    piola_obstacle_def d = gear_def(counts[c]);
    d.axis = vec3_make(0, 0.6, 0.8);
    d.center = vec3_make(0.2, -0.1, 0.05);
    piola_obstacle *o = make(&d);
    const piola__gear_shape *g = &o->shape.gear;
    test_rng rng = test_rng_seeded(40 + c);
    for (long s = 0; s < test_samples(2000, 100); ++s) {
      double scale = s % 4 == 0 ? 1.0 : 0.13;
      double x = test_rng_uniform(&rng, -scale, scale), y = test_rng_uniform(&rng, -scale, scale);
      double h = test_rng_uniform(&rng, -0.02, 0.02); /* within the faces: pure 2D distance */
      vec3 p = vec3_add(d.center, vec3_add(vec3_add(vec3_scale(g->e1, x), vec3_scale(g->e2, y)),
                                           vec3_scale(g->axis, h)));
      double expected = brute_outline_distance(g, x, y);
      double dh = fabs(h) - d.half_length;
      expected = expected <= 0 ? fmax(expected, dh) : expected;
      assert_close(phi(o, 0, p), expected, 1e-14);
    }
    piola_obstacle_destroy(o);
  }
}

/* Gear B at centre distance 2 radius - tooth_depth from gear A, turned by pi + pi / N about
 * its own axis so that a gap faces A's tooth 0. A turns by theta and B by -theta: at every
 * sampled angle returns the deepest point inside both (m), 0 if they do not overlap.
 * facing = 1 turns B by pi only, so that a tooth faces A's tooth 0 (a wrong placement). */
static double worst_overlap(int teeth, double clearance, int facing, int angle_steps) {
  piola_obstacle_def a = gear_def(teeth), b = gear_def(teeth);
  double distance = 2 * a.radius - a.tooth_depth + clearance;
  b.center = vec3_make(distance, 0, 0);
  a.motion.kind = b.motion.kind = PIOLA_MOTION_POSE;
  b.motion.pivot = b.center;
  double period = 2 * M_PI / teeth;
  double worst = 0;
  for (int step = 0; step < angle_steps; ++step) {
    double theta = period * step / angle_steps;
    a.motion.angle = piola_track_constant(theta);
    b.motion.angle = piola_track_constant(M_PI + (facing ? 0 : period / 2) - theta);
    piola_obstacle *ga = make(&a), *gb = make(&b);
    /* Sample the meshing region between the centres. */
    for (int i = 0; i <= 60; ++i)
      for (int j = 0; j <= 60; ++j) {
        vec3 p = vec3_make(0.07 + (distance - 0.14) * i / 60.0, -0.04 + 0.08 * j / 60.0, 0.0);
        double da = phi(ga, 0, p), db = phi(gb, 0, p);
        worst = fmax(worst, fmin(-da, -db));
      }
    piola_obstacle_destroy(ga);
    piola_obstacle_destroy(gb);
  }
  return worst;
}

static void equal_gears_interlock(void **state) {
  (void)state;
  const int counts[] = {8, 13, 20};
  for (size_t c = 0; c < sizeof counts / sizeof *counts; ++c) {
    /* In the documented placement the teeth sit in the gaps: at most touching. */
    assert_close(worst_overlap(counts[c], 0.0, 0, 1), 0, 1e-12);
    /* Turning in opposite directions at equal speed they stay clear, given a clearance of a
     * tenth of the tooth depth (trapezoidal teeth are not conjugate profiles). */
    assert_close(worst_overlap(counts[c], 0.002, 0, test_samples(16, 4)), 0, 1e-12);
  }
  /* The check can fail: pushed 2 mm closer, or with a tooth facing a tooth, they overlap. */
  assert_true(worst_overlap(12, -0.002, 0, 1) > 2e-4);
  assert_true(worst_overlap(12, 0.0, 1, 1) > 5e-3);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(teeth_are_inside_and_gaps_outside),
      cmocka_unit_test(distance_matches_search_over_all_edges),
      cmocka_unit_test(equal_gears_interlock),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
