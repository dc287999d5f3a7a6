/* Continuous collision detection of single pairs: the coplanarity-cubic solver must find
 * every crossing in constructed cases (interior, edge, vertex, edge-edge, grazing, parallel,
 * degenerate, roots exactly at the ends of the step) and in random ones. */
#include "test_support.h"

#include <math.h>

#include "contact/ccd.h"
#include "contact/proximity.h"

static const double EPS = 1e-6;

static void set4(vec3 out[4], vec3 a, vec3 b, vec3 c, vec3 d) {
  out[0] = a, out[1] = b, out[2] = c, out[3] = d;
}

static const vec3 ZERO = {0, 0, 0};

/* Static unit triangle in z = 0 with the point moving through it. */
static int vf_static_triangle(vec3 p, vec3 dp, piola__ccd_hit *hit) {
  vec3 x[4], d[4];
  set4(x, p, (vec3){0, 0, 0}, (vec3){1, 0, 0}, (vec3){0, 1, 0});
  set4(d, dp, ZERO, ZERO, ZERO);
  return piola__ccd_point_triangle(x, d, EPS, hit);
}

static void point_through_interior(void **state) {
  (void)state;
  piola__ccd_hit hit;
  assert_int_equal(vf_static_triangle((vec3){0.2, 0.3, 1.0}, (vec3){0, 0, -2.0}, &hit), 1);
  assert_close(hit.s, 0.5, 1e-12);
  assert_close(hit.w[0], 1.0, 0);
  assert_close(hit.w[1], -0.5, 1e-9);
  assert_close(hit.w[2], -0.2, 1e-9);
  assert_close(hit.w[3], -0.3, 1e-9);
  /* The point starts above: the normal points up, to the point's side. */
  assert_close(hit.normal.z, 1.0, 1e-12);
  /* From below, it points down. */
  assert_int_equal(vf_static_triangle((vec3){0.2, 0.3, -1.0}, (vec3){0, 0, 3.0}, &hit), 1);
  assert_close(hit.s, 1.0 / 3.0, 1e-12);
  assert_close(hit.normal.z, -1.0, 1e-12);
}

static void point_through_edge_and_vertex(void **state) {
  (void)state;
  piola__ccd_hit hit;
  assert_int_equal(vf_static_triangle((vec3){0.5, 0.0, 1.0}, (vec3){0, 0, -4.0}, &hit), 1);
  assert_close(hit.s, 0.25, 1e-12);
  assert_int_equal(vf_static_triangle((vec3){0.5, 0.5, 1.0}, (vec3){0, 0, -4.0}, &hit), 1);
  assert_close(hit.s, 0.25, 1e-12);
  assert_int_equal(vf_static_triangle((vec3){0.0, 0.0, 1.0}, (vec3){0, 0, -4.0}, &hit), 1);
  assert_close(hit.s, 0.25, 1e-12);
  /* Oblique path through vertex (1, 0, 0). */
  assert_int_equal(vf_static_triangle((vec3){0.0, -1.0, 1.0}, (vec3){2.0, 2.0, -2.0}, &hit), 1);
  assert_close(hit.s, 0.5, 1e-12);
  /* Just outside each of those: no collision. */
  assert_int_equal(vf_static_triangle((vec3){0.5, -1e-4, 1.0}, (vec3){0, 0, -4.0}, &hit), 0);
  assert_int_equal(vf_static_triangle((vec3){0.5001, 0.5001, 1.0}, (vec3){0, 0, -4.0}, &hit), 0);
  assert_int_equal(vf_static_triangle((vec3){-1e-4, -1e-4, 1.0}, (vec3){0, 0, -4.0}, &hit), 0);
  /* Stopping short of the plane, or moving away from it. */
  assert_int_equal(vf_static_triangle((vec3){0.2, 0.2, 1.0}, (vec3){0, 0, -0.999}, &hit), 0);
  assert_int_equal(vf_static_triangle((vec3){0.2, 0.2, 1.0}, (vec3){0, 0, 1.0}, &hit), 0);
}

static void edges_crossing(void **state) {
  (void)state;
  vec3 x[4], d[4];
  piola__ccd_hit hit;
  set4(x, (vec3){0, -1, 1}, (vec3){0, 1, 1}, (vec3){-1, 0, 0}, (vec3){1, 0, 0});
  set4(d, (vec3){0, 0, -2}, (vec3){0, 0, -2}, ZERO, ZERO);
  assert_int_equal(piola__ccd_edge_edge(x, d, EPS, &hit), 1);
  assert_close(hit.s, 0.5, 1e-12);
  for (int k = 0; k < 4; ++k) assert_close(fabs(hit.w[k]), 0.5, 1e-9);
  assert_close(hit.normal.z, 1.0, 1e-12);
  /* Both edges moving, crossing near an endpoint of one (a = 0.99). */
  set4(x, (vec3){0.98, -1, 1}, (vec3){0.98, 1, 1}, (vec3){-1, 0, -1}, (vec3){1, 0, -1});
  set4(d, (vec3){0, 0, -1}, (vec3){0, 0, -1}, (vec3){0, 0, 1}, (vec3){0, 0, 1});
  assert_int_equal(piola__ccd_edge_edge(x, d, EPS, &hit), 1);
  assert_close(hit.s, 1.0, 1e-12);
  assert_close(-hit.w[3], 0.99, 1e-9);
  /* Passing beside the end of the other edge: no collision. */
  set4(x, (vec3){1.01, -1, 1}, (vec3){1.01, 1, 1}, (vec3){-1, 0, 0}, (vec3){1, 0, 0});
  set4(d, (vec3){0, 0, -2}, (vec3){0, 0, -2}, ZERO, ZERO);
  assert_int_equal(piola__ccd_edge_edge(x, d, EPS, &hit), 0);
}

/* The coplanarity function touches zero at s = 1/2 without changing sign. */
static void grazing_contact(void **state) {
  (void)state;
  vec3 x[4], d[4];
  piola__ccd_hit hit;
  /* Triangle (0,0,0), (1,0,0), (0,1,1-2s); point (0.3, 0.3+0.4s, 0.5-s): f = 0.8 (s-1/2)^2. */
  set4(x, (vec3){0.3, 0.3, 0.5}, (vec3){0, 0, 0}, (vec3){1, 0, 0}, (vec3){0, 1, 1});
  set4(d, (vec3){0, 0.4, -1.0}, ZERO, ZERO, (vec3){0, 0, -2});
  assert_int_equal(piola__ccd_point_triangle(x, d, EPS, &hit), 1);
  assert_close(hit.s, 0.5, 1e-6);
  assert_true(hit.distance < EPS);
  double times[8];
  vec3 u[3] = {{1, 0, 0}, {0, 1, 1}, {0.3, 0.3, 0.5}}, du[3] = {ZERO, {0, 0, -2}, {0, 0.4, -1}};
  int n = piola__coplanarity_times(u, du, times);
  int near_half = 0;
  for (int i = 0; i < n; ++i) near_half |= fabs(times[i] - 0.5) < 1e-9;
  assert_true(near_half);
  /* The same with the point lifted by 1e-3: it passes above the triangle. */
  x[0].z += 1e-3;
  assert_int_equal(piola__ccd_point_triangle(x, d, EPS, &hit), 0);
}

static void parallel_motion(void **state) {
  (void)state;
  piola__ccd_hit hit;
  /* A point gliding parallel to the triangle's plane, above it. */
  assert_int_equal(vf_static_triangle((vec3){-1, 0.2, 0.5}, (vec3){3, 0, 0}, &hit), 0);
  /* ... and in its plane, entering it through an edge at s = 1/3. */
  assert_int_equal(vf_static_triangle((vec3){-1, 0.2, 0.0}, (vec3){3, 0, 0}, &hit), 1);
  assert_close(hit.s, 1.0 / 3.0, 1e-9);
  /* Parallel edges in one plane driven into each other (f is zero for the whole step). */
  vec3 x[4], d[4];
  set4(x, (vec3){0, 0, 1}, (vec3){1, 0, 1}, (vec3){0.5, 0, 0}, (vec3){1.5, 0, 0});
  set4(d, (vec3){0, 0, -2}, (vec3){0, 0, -2}, ZERO, ZERO);
  assert_int_equal(piola__ccd_edge_edge(x, d, EPS, &hit), 1);
  assert_close(hit.s, 0.5, 1e-9);
  /* Parallel edges in different planes: never closer than 1. */
  set4(x, (vec3){0, 1, 1}, (vec3){1, 1, 1}, (vec3){0, 0, 0}, (vec3){1, 0, 0});
  assert_int_equal(piola__ccd_edge_edge(x, d, EPS, &hit), 0);
  /* Edges sliding along each other on one line, end to end. */
  set4(x, (vec3){-2, 0, 0}, (vec3){-1, 0, 0}, (vec3){0, 0, 0}, (vec3){1, 0, 0});
  set4(d, (vec3){2, 0, 0}, (vec3){2, 0, 0}, ZERO, ZERO);
  assert_int_equal(piola__ccd_edge_edge(x, d, EPS, &hit), 1);
  assert_close(hit.s, 0.5, 1e-9);
}

static void degenerate_primitives(void **state) {
  (void)state;
  vec3 x[4], d[4];
  piola__ccd_hit hit;
  /* Zero-area triangle (three collinear vertices) crossed by a point. */
  set4(x, (vec3){0.5, 0, 1}, (vec3){0, 0, 0}, (vec3){1, 0, 0}, (vec3){2, 0, 0});
  set4(d, (vec3){0, 0, -2}, ZERO, ZERO, ZERO);
  assert_int_equal(piola__ccd_point_triangle(x, d, EPS, &hit), 1);
  assert_close(hit.s, 0.5, 1e-9);
  /* ... and missed by one. */
  x[0].y = 0.1;
  assert_int_equal(piola__ccd_point_triangle(x, d, EPS, &hit), 0);
  /* Triangle collapsed to a point. */
  set4(x, (vec3){0, 0, 1}, (vec3){0, 0, 0}, (vec3){0, 0, 0}, (vec3){0, 0, 0});
  assert_int_equal(piola__ccd_point_triangle(x, d, EPS, &hit), 1);
  assert_close(hit.s, 0.5, 1e-9);
  /* Zero-length edge through an edge. */
  set4(x, (vec3){0.5, 0, 1}, (vec3){0.5, 0, 1}, (vec3){0, 0, 0}, (vec3){1, 0, 0});
  set4(d, (vec3){0, 0, -2}, (vec3){0, 0, -2}, ZERO, ZERO);
  assert_int_equal(piola__ccd_edge_edge(x, d, EPS, &hit), 1);
  assert_close(hit.s, 0.5, 1e-9);
  /* No motion at all: apart means no collision, touching means one at s = 0. */
  set4(d, ZERO, ZERO, ZERO, ZERO);
  assert_int_equal(vf_static_triangle((vec3){0.2, 0.2, 0.1}, ZERO, &hit), 0);
  assert_int_equal(vf_static_triangle((vec3){0.2, 0.2, 0.0}, ZERO, &hit), 1);
  assert_close(hit.s, 0.0, 0);
}

static void roots_at_the_ends(void **state) {
  (void)state;
  piola__ccd_hit hit;
  /* Starting on the triangle and leaving it. */
  assert_int_equal(vf_static_triangle((vec3){0.2, 0.2, 0.0}, (vec3){0, 0, 1}, &hit), 1);
  assert_close(hit.s, 0.0, 0);
  /* Arriving exactly at the end of the step. */
  assert_int_equal(vf_static_triangle((vec3){0.2, 0.2, 1.0}, (vec3){0, 0, -1}, &hit), 1);
  assert_close(hit.s, 1.0, 1e-15);
  /* Edges meeting exactly at s = 1. */
  vec3 x[4], d[4];
  set4(x, (vec3){0, -1, 0.25}, (vec3){0, 1, 0.25}, (vec3){-1, 0, 0}, (vec3){1, 0, 0});
  set4(d, (vec3){0, 0, -0.25}, (vec3){0, 0, -0.25}, ZERO, ZERO);
  assert_int_equal(piola__ccd_edge_edge(x, d, EPS, &hit), 1);
  assert_close(hit.s, 1.0, 1e-15);
}

static vec3 random_vec(test_rng *rng, double scale) {
  return (vec3){scale * test_rng_uniform(rng, -1, 1), scale * test_rng_uniform(rng, -1, 1),
                scale * test_rng_uniform(rng, -1, 1)};
}

static double coplanarity(const vec3 x[4], const vec3 d[4], double s) {
  vec3 p[4];
  for (int k = 0; k < 4; ++k) p[k] = vec3_add(x[k], vec3_scale(d[k], s));
  return vec3_dot(vec3_cross(vec3_sub(p[2], p[1]), vec3_sub(p[3], p[1])), vec3_sub(p[0], p[1]));
}

/* Random moving triangles and points: whenever the coplanarity function changes sign over the
 * step and the point is well inside the triangle at that time, a collision must be reported,
 * no later than that time; when sampled distances stay large, none may be. */
static void random_point_triangle_crossings(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(7);
  const long n = test_samples(20000, 500);
  long crossings = 0, misses = 0;
  for (long it = 0; it < n; ++it) {
    vec3 x[4], d[4];
    for (int k = 0; k < 4; ++k) x[k] = random_vec(&rng, 1.0), d[k] = random_vec(&rng, 1.5);
    piola__ccd_hit hit;
    int found = piola__ccd_point_triangle(x, d, EPS, &hit);
    /* Ground truth: the first sign change on a fine grid, refined by bisection. */
    const int grid = 400;
    double truth = -1.0;
    for (int i = 0; i < grid && truth < 0.0; ++i) {
      double lo = (double)i / grid, hi = (double)(i + 1) / grid;
      double flo = coplanarity(x, d, lo), fhi = coplanarity(x, d, hi);
      if ((flo < 0) == (fhi < 0)) continue;
      for (int b = 0; b < 80; ++b) {
        double mid = 0.5 * (lo + hi), fm = coplanarity(x, d, mid);
        if ((fm < 0) == (flo < 0))
          lo = mid, flo = fm;
        else
          hi = mid;
      }
      double s = 0.5 * (lo + hi), bary[3];
      vec3 p[4];
      for (int k = 0; k < 4; ++k) p[k] = vec3_add(x[k], vec3_scale(d[k], s));
      piola__point_triangle_closest(p[0], p[1], p[2], p[3], bary);
      /* Well inside: plane crossing through the interior (distance to each edge line). */
      double margin = 1.0;
      for (int k = 0; k < 3; ++k) margin = fmin(margin, bary[k]);
      vec3 n3 = vec3_cross(vec3_sub(p[2], p[1]), vec3_sub(p[3], p[1]));
      if (margin > 0.02 && vec3_norm(n3) > 0.05) truth = s;
    }
    if (truth >= 0.0) {
      ++crossings;
      assert_int_equal(found, 1);
      assert_true(hit.s <= truth + 1e-9);
      assert_true(hit.distance < EPS);
    }
    if (found) continue;
    /* Not found: the pair never came within EPS on a fine grid of times. */
    double closest = INFINITY;
    for (int i = 0; i <= 200; ++i) {
      double s = i / 200.0, bary[3];
      vec3 p[4];
      for (int k = 0; k < 4; ++k) p[k] = vec3_add(x[k], vec3_scale(d[k], s));
      closest = fmin(closest, piola__point_triangle_closest(p[0], p[1], p[2], p[3], bary));
    }
    misses += closest < 1e-12;
  }
  assert_int_equal(misses, 0);
  assert_true(crossings > n / 50);
}

/* Random edge pairs: every crossing of two edges through each other is found. */
static void random_edge_edge_crossings(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(11);
  const long n = test_samples(20000, 500);
  long crossings = 0;
  for (long it = 0; it < n; ++it) {
    vec3 x[4], d[4];
    for (int k = 0; k < 4; ++k) x[k] = random_vec(&rng, 1.0), d[k] = random_vec(&rng, 1.5);
    piola__ccd_hit hit;
    int found = piola__ccd_edge_edge(x, d, EPS, &hit);
    /* First grid interval where f = ((x1-x0) x (x3-x2)) . (x2-x0) changes sign. */
    const int grid = 400;
    for (int i = 0; i < grid; ++i) {
      double lo = (double)i / grid, hi = (double)(i + 1) / grid;
      double sa, sb;
      vec3 p[4], q[4];
      for (int k = 0; k < 4; ++k) {
        p[k] = vec3_add(x[k], vec3_scale(d[k], lo));
        q[k] = vec3_add(x[k], vec3_scale(d[k], hi));
      }
      double flo =
          vec3_dot(vec3_cross(vec3_sub(p[1], p[0]), vec3_sub(p[3], p[2])), vec3_sub(p[2], p[0]));
      double fhi =
          vec3_dot(vec3_cross(vec3_sub(q[1], q[0]), vec3_sub(q[3], q[2])), vec3_sub(q[2], q[0]));
      if ((flo < 0) == (fhi < 0)) continue;
      double dist = piola__segment_segment_closest(q[0], q[1], q[2], q[3], &sa, &sb);
      /* Crossing with both closest points well inside their edges, and not near-parallel. */
      vec3 cr = vec3_cross(vec3_sub(q[1], q[0]), vec3_sub(q[3], q[2]));
      if (sa > 0.02 && sa < 0.98 && sb > 0.02 && sb < 0.98 &&
          vec3_norm(cr) >
              0.05 * vec3_norm(vec3_sub(q[1], q[0])) * vec3_norm(vec3_sub(q[3], q[2])) &&
          sqrt(dist) < 1e-2) {
        ++crossings;
        assert_int_equal(found, 1);
        assert_true(hit.s <= hi + 1e-9);
        break;
      }
    }
  }
  assert_true(crossings > n / 100);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(point_through_interior),
      cmocka_unit_test(point_through_edge_and_vertex),
      cmocka_unit_test(edges_crossing),
      cmocka_unit_test(grazing_contact),
      cmocka_unit_test(parallel_motion),
      cmocka_unit_test(degenerate_primitives),
      cmocka_unit_test(roots_at_the_ends),
      cmocka_unit_test(random_point_triangle_crossings),
      cmocka_unit_test(random_edge_edge_crossings),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
