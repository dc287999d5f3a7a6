/* Obstacle shapes: signed distances against analytic values, normals against the finite-
 * difference gradient, the eikonal property, moving obstacles, and validation. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "test_support.h"

#include "math/mat3.h"
#include "piola/obstacle.h"

static piola_obstacle *make(const piola_obstacle_def *def) {
  piola_obstacle *o = NULL;
  piola_status s = piola_obstacle_create(def, &o);
  if (s != PIOLA_OK) fail_msg("obstacle_create: %s", piola_last_error());
  return o;
}

static double phi(const piola_obstacle *o, double x, double y, double z) {
  return piola_obstacle_signed_distance(o, 0.0, vec3_make(x, y, z), NULL, NULL);
}

static void plane_distances(void **state) {
  (void)state;
  piola_obstacle_def d = piola_default_obstacle_def();
  d.type = PIOLA_OBSTACLE_PLANE;
  d.center = vec3_make(0, 0, 1);
  piola_obstacle *o = make(&d);
  assert_close(phi(o, 5, 5, 3), 2, 1e-15);
  assert_close(phi(o, -3, 2, 1), 0, 1e-15);
  assert_close(phi(o, 0, 0, -1), -2, 1e-15);
  vec3 n;
  piola_obstacle_signed_distance(o, 0, vec3_make(1, 1, -4), &n, NULL);
  assert_close(n.z, 1, 0);
  piola_obstacle_destroy(o);
  /* A tilted plane. */
  d.axis = vec3_make(0, 0.6, 0.8);
  d.center = vec3_make(0, 0, 0);
  o = make(&d);
  assert_close(phi(o, 7, 3, 4), 0.6 * 3 + 0.8 * 4, 1e-14);
  assert_close(phi(o, 0, -1, -2), -0.6 - 1.6, 1e-14);
  piola_obstacle_destroy(o);
}

static void sphere_distances(void **state) {
  (void)state;
  piola_obstacle_def d = piola_default_obstacle_def();
  d.type = PIOLA_OBSTACLE_SPHERE;
  d.center = vec3_make(1, 0, 0);
  d.radius = 1;
  piola_obstacle *o = make(&d);
  assert_close(phi(o, 3, 0, 0), 1, 1e-15);
  assert_close(phi(o, 1.5, 0, 0), -0.5, 1e-15);
  assert_close(phi(o, 1, 1, 0), 0, 1e-15);
  assert_close(phi(o, 1, 0, 0), -1, 1e-15);
  assert_close(phi(o, 1 + 3, 4, 0), 4, 1e-15);
  piola_obstacle_destroy(o);
}

static void box_distances(void **state) {
  (void)state;
  piola_obstacle_def d = piola_default_obstacle_def();
  d.type = PIOLA_OBSTACLE_BOX;
  d.half_extents = vec3_make(1, 2, 3);
  piola_obstacle *o = make(&d);
  assert_close(phi(o, 2, 0, 0), 1, 1e-15);         /* off a face */
  assert_close(phi(o, 0, 0, 0), -1, 1e-15);        /* centre: nearest face x */
  assert_close(phi(o, 0, 1.5, 0), -0.5, 1e-15);    /* nearest face y */
  assert_close(phi(o, 2, 3, 0), sqrt(2), 1e-15);   /* off an edge */
  assert_close(phi(o, -2, 3, -4), sqrt(3), 1e-15); /* off a corner */
  assert_close(phi(o, 1, 0.5, 0.5), 0, 1e-15);     /* on a face */
  vec3 n;
  piola_obstacle_signed_distance(o, 0, vec3_make(0.1, -1.9, 0), &n, NULL);
  assert_close(n.y, -1, 0);
  piola_obstacle_destroy(o);
}

static void cylinder_distances(void **state) {
  (void)state;
  piola_obstacle_def d = piola_default_obstacle_def();
  d.type = PIOLA_OBSTACLE_CYLINDER;
  d.radius = 1;
  d.half_length = 2;
  piola_obstacle *o = make(&d);
  assert_close(phi(o, 3, 0, 0), 2, 1e-15);
  assert_close(phi(o, 0, 0, 0), -1, 1e-15);
  assert_close(phi(o, 0, 0, 3), 1, 1e-15);
  assert_close(phi(o, 0, 2, 3), sqrt(2), 1e-15);
  assert_close(phi(o, 0.5, 0, 1.9), -0.1, 1e-15);
  assert_close(phi(o, 0.6, 0.8, 0.3), 0, 1e-15);
  piola_obstacle_destroy(o);
  /* Along the x axis. */
  d.axis = vec3_make(1, 0, 0);
  o = make(&d);
  assert_close(phi(o, 3, 0, 0), 1, 1e-15);
  assert_close(phi(o, 0, 0, 3), 2, 1e-15);
  piola_obstacle_destroy(o);
}

static void capsule_distances(void **state) {
  (void)state;
  piola_obstacle_def d = piola_default_obstacle_def();
  d.type = PIOLA_OBSTACLE_CAPSULE;
  d.axis = vec3_make(1, 0, 0);
  d.radius = 0.5;
  d.half_length = 1;
  piola_obstacle *o = make(&d);
  assert_close(phi(o, 0, 2, 0), 1.5, 1e-15);
  assert_close(phi(o, 3, 0, 0), 1.5, 1e-15);
  assert_close(phi(o, 0, 0, 0), -0.5, 1e-15);
  assert_close(phi(o, 1 + 3, 0, 4), 4.5, 1e-15);
  assert_close(phi(o, -1.5, 0, 0), 0, 1e-15);
  piola_obstacle_destroy(o);
}

static void torus_distances(void **state) {
  (void)state;
  piola_obstacle_def d = piola_default_obstacle_def();
  d.type = PIOLA_OBSTACLE_TORUS;
  d.radius = 2;
  d.minor_radius = 0.5;
  piola_obstacle *o = make(&d);
  assert_close(phi(o, 2, 0, 0), -0.5, 1e-15);
  assert_close(phi(o, 0, 0, 0), 1.5, 1e-15);
  assert_close(phi(o, 0, -2, 1), 0.5, 1e-15);
  assert_close(phi(o, 3, 0, 0), 0.5, 1e-15);
  assert_close(phi(o, 0, 2.5, 0), 0, 1e-15);
  assert_close(phi(o, 0, 0, 5), sqrt(4 + 25) - 0.5, 1e-14);
  piola_obstacle_destroy(o);
}

/* A closed cube surface of 12 triangles, outward (or inward if flip). */
static void cube_mesh(piola_tri_mesh *m, vec3 lo, vec3 hi, int flip) {
  static const int32_t tris[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                   2, 3, 7, 2, 7, 6, 1, 2, 6, 1, 6, 5, 0, 4, 7, 0, 7, 3};
  m->vertex_count = 8;
  m->positions = malloc(sizeof(double) * 24);
  m->triangle_count = 12;
  m->triangles = malloc(sizeof(int32_t) * 36);
  for (int i = 0; i < 8; ++i) {
    /* vertex bits: 0 (lo,lo,lo), 1 (hi,lo,lo), 2 (hi,hi,lo), 3 (lo,hi,lo), 4..7 the same at hi z */
    int xb = (i == 1 || i == 2 || i == 5 || i == 6), yb = (i == 2 || i == 3 || i == 6 || i == 7),
        zb = i >= 4;
    m->positions[3 * i] = xb ? hi.x : lo.x;
    m->positions[3 * i + 1] = yb ? hi.y : lo.y;
    m->positions[3 * i + 2] = zb ? hi.z : lo.z;
  }
  memcpy(m->triangles, tris, sizeof tris);
  if (flip)
    for (int t = 0; t < 12; ++t) {
      int32_t a = m->triangles[3 * t + 1];
      m->triangles[3 * t + 1] = m->triangles[3 * t + 2];
      m->triangles[3 * t + 2] = a;
    }
}

static void free_mesh(piola_tri_mesh *m) {
  free(m->positions);
  free(m->triangles);
}

/* A triangulated box is the box: the mesh obstacle's exact distance must equal the analytic
 * box distance everywhere, inside and out, whichever way the surface is wound. */
static void mesh_cube_equals_box(void **state) {
  (void)state;
  vec3 lo = vec3_make(-1, -2, -3), hi = vec3_make(1, 2, 3);
  piola_obstacle_def bd = piola_default_obstacle_def();
  bd.type = PIOLA_OBSTACLE_BOX;
  bd.half_extents = vec3_make(1, 2, 3);
  piola_obstacle *box = make(&bd);
  for (int flip = 0; flip < 2; ++flip) {
    piola_tri_mesh cube;
    cube_mesh(&cube, lo, hi, flip);
    piola_obstacle_def md = piola_default_obstacle_def();
    md.type = PIOLA_OBSTACLE_MESH;
    md.mesh = &cube;
    piola_obstacle *mesh = make(&md);
    free_mesh(&cube); /* the obstacle keeps its own copy */
    test_rng rng = test_rng_seeded(3 + flip);
    for (long s = 0; s < test_samples(2000, 100); ++s) {
      vec3 p = vec3_make(test_rng_uniform(&rng, -3, 3), test_rng_uniform(&rng, -4, 4),
                         test_rng_uniform(&rng, -5, 5));
      vec3 nb, nm;
      double db = piola_obstacle_signed_distance(box, 0, p, &nb, NULL);
      double dm = piola_obstacle_signed_distance(mesh, 0, p, &nm, NULL);
      assert_close(dm, db, 1e-12);
      assert_close(vec3_norm(vec3_sub(nm, nb)), 0, 1e-9);
    }
    piola_obstacle_destroy(mesh);
  }
  piola_obstacle_destroy(box);
}

/* The octahedron |x| + |y| + |z| <= 1 (8 triangles, outward): inside a convex solid the
 * distance is that to the nearest face plane, (|x| + |y| + |z| - 1) / sqrt(3); outside it is
 * at least that. */
static void mesh_octahedron_matches_its_face_planes(void **state) {
  (void)state;
  double positions[18] = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
  int32_t triangles[24];
  int t = 0;
  for (int sx = 0; sx < 2; ++sx)
    for (int sy = 0; sy < 2; ++sy)
      for (int sz = 0; sz < 2; ++sz) {
        int32_t a = sx, b = 2 + sy, c = 4 + sz;
        /* Outward when (a, b, c) has the orientation of the octant's sign product. */
        int positive = ((sx == 0) + (sy == 0) + (sz == 0)) % 2 == 1;
        triangles[3 * t] = a;
        triangles[3 * t + 1] = positive ? b : c;
        triangles[3 * t + 2] = positive ? c : b;
        ++t;
      }
  piola_tri_mesh octa = {6, positions, 8, triangles};
  piola_obstacle_def d = piola_default_obstacle_def();
  d.type = PIOLA_OBSTACLE_MESH;
  d.mesh = &octa;
  piola_obstacle *o = make(&d);
  test_rng rng = test_rng_seeded(21);
  for (long k = 0; k < test_samples(2000, 100); ++k) {
    vec3 p = vec3_make(test_rng_uniform(&rng, -1.5, 1.5), test_rng_uniform(&rng, -1.5, 1.5),
                       test_rng_uniform(&rng, -1.5, 1.5));
    double plane = (fabs(p.x) + fabs(p.y) + fabs(p.z) - 1) / sqrt(3.0);
    vec3 n;
    double dist = piola_obstacle_signed_distance(o, 0, p, &n, NULL);
    if (plane < 0) {
      assert_close(dist, plane, 1e-14);
      /* The normal of the nearest face: (sign x, sign y, sign z) / sqrt 3. */
      assert_close(fabs(n.x), 1 / sqrt(3.0), 1e-12);
      assert_close(fabs(n.y), 1 / sqrt(3.0), 1e-12);
    } else {
      assert_true(dist >= plane - 1e-14);
    }
    assert_close(phi(o, p.x - dist * n.x, p.y - dist * n.y, p.z - dist * n.z), 0, 1e-14);
  }
  assert_close(phi(o, 0, 0, 0), -1 / sqrt(3.0), 1e-15);
  assert_close(phi(o, 0, 0, 3), 2, 1e-15); /* off a vertex */
  piola_obstacle_destroy(o);
}

static piola_obstacle_def random_def(piola_obstacle_type type, piola_tri_mesh *cube) {
  piola_obstacle_def d = piola_default_obstacle_def();
  d.type = type;
  d.center = vec3_make(0.1, -0.2, 0.3);
  d.axis = vec3_make(0.48, 0.6, 0.64); /* unit */
  d.radius = 1.0;
  d.minor_radius = 0.3;
  d.half_length = 0.7;
  d.half_extents = vec3_make(0.5, 0.8, 1.1);
  d.tooth_count = 9;
  d.tooth_depth = 0.25;
  d.mesh = cube;
  return d;
}

/* |grad phi| = 1 and the normal is grad phi (central differences, h = 1e-6 m), at random
 * points of every shape; the chance of a sample within h of the medial set is ~1e-5. Also
 * projecting with x - phi n lands on the surface. */
static void normals_are_gradients_and_eikonal(void **state) {
  (void)state;
  piola_tri_mesh cube;
  cube_mesh(&cube, vec3_make(-0.5, -0.7, -0.9), vec3_make(0.6, 0.8, 1.0), 0);
  for (int type = 0; type < PIOLA_OBSTACLE_TYPE_COUNT; ++type) {
    piola_obstacle_def d = random_def((piola_obstacle_type)type, &cube);
    piola_obstacle *o = make(&d);
    test_rng rng = test_rng_seeded(100 + (uint64_t)type);
    long n = test_samples(type == PIOLA_OBSTACLE_MESH ? 300 : 1000, 50);
    for (long s = 0; s < n; ++s) {
      vec3 p = vec3_make(test_rng_uniform(&rng, -2, 2), test_rng_uniform(&rng, -2, 2),
                         test_rng_uniform(&rng, -2, 2));
      vec3 normal;
      double d0 = piola_obstacle_signed_distance(o, 0, p, &normal, NULL);
      double h = 1e-6, g[3];
      for (int k = 0; k < 3; ++k) {
        vec3 e = vec3_make(k == 0, k == 1, k == 2);
        g[k] = (piola_obstacle_signed_distance(o, 0, vec3_add(p, vec3_scale(e, h)), NULL, NULL) -
                piola_obstacle_signed_distance(o, 0, vec3_sub(p, vec3_scale(e, h)), NULL, NULL)) /
               (2 * h);
      }
      vec3 grad = vec3_make(g[0], g[1], g[2]);
      if (fabs(vec3_norm(grad) - 1) > 1e-5 || vec3_norm(vec3_sub(grad, normal)) > 1e-5)
        fail_msg("type %d at (%g, %g, %g): phi %g, normal (%g, %g, %g), fd gradient (%g, %g, %g)",
                 type, p.x, p.y, p.z, d0, normal.x, normal.y, normal.z, g[0], g[1], g[2]);
      vec3 q = vec3_sub(p, vec3_scale(normal, d0));
      double on = piola_obstacle_signed_distance(o, 0, q, NULL, NULL);
      if (fabs(on) > 1e-12)
        fail_msg("type %d: projection of (%g, %g, %g) is %g off", type, p.x, p.y, p.z, on);
    }
    piola_obstacle_destroy(o);
  }
  free_mesh(&cube);
}

/* |phi(a) - phi(b)| <= |a - b|: a distance, not just an implicit function. */
static void distances_are_one_lipschitz(void **state) {
  (void)state;
  piola_tri_mesh cube;
  cube_mesh(&cube, vec3_make(-0.5, -0.7, -0.9), vec3_make(0.6, 0.8, 1.0), 0);
  for (int type = 0; type < PIOLA_OBSTACLE_TYPE_COUNT; ++type) {
    piola_obstacle_def d = random_def((piola_obstacle_type)type, &cube);
    piola_obstacle *o = make(&d);
    test_rng rng = test_rng_seeded(200 + (uint64_t)type);
    for (long s = 0; s < test_samples(1000, 50); ++s) {
      vec3 a = vec3_make(test_rng_uniform(&rng, -2, 2), test_rng_uniform(&rng, -2, 2),
                         test_rng_uniform(&rng, -2, 2));
      vec3 b = vec3_add(
          a, vec3_make(test_rng_normal(&rng), test_rng_normal(&rng), test_rng_normal(&rng)));
      double da = piola_obstacle_signed_distance(o, 0, a, NULL, NULL);
      double db = piola_obstacle_signed_distance(o, 0, b, NULL, NULL);
      assert_true(fabs(da - db) <= vec3_norm(vec3_sub(a, b)) * (1 + 1e-12));
    }
    piola_obstacle_destroy(o);
  }
  free_mesh(&cube);
}

/* Every shape moves rigidly: a material point x0 at time 0 has the same distance at x(t),
 * its normal turns with the rotation, and the obstacle's velocity there is dx/dt. */
static void moving_obstacles_carry_their_distance(void **state) {
  (void)state;
  piola_tri_mesh cube;
  cube_mesh(&cube, vec3_make(-0.5, -0.7, -0.9), vec3_make(0.6, 0.8, 1.0), 0);
  const double times[] = {0.0, 0.5, 2.0};
  for (int type = 0; type < PIOLA_OBSTACLE_TYPE_COUNT; ++type) {
    piola_obstacle_def d = random_def((piola_obstacle_type)type, &cube);
    d.motion.axis = vec3_make(0, 0.6, -0.8);
    d.motion.pivot = vec3_make(0.3, 0.1, -0.4);
    const double vx[] = {1, -1, 0.5}, vz[] = {0, 2, 2}, w[] = {0.5, 3, -1};
    piola_track_from_keys(times, vx, 3, &d.motion.velocity[0]);
    piola_track_from_keys(times, vz, 3, &d.motion.velocity[2]);
    piola_track_from_keys(times, w, 3, &d.motion.angular_speed);
    piola_obstacle *o = make(&d);
    test_rng rng = test_rng_seeded(300 + (uint64_t)type);
    for (long s = 0; s < test_samples(200, 20); ++s) {
      double t = test_rng_uniform(&rng, 0.05, 3.0);
      vec3 x0 = vec3_make(test_rng_uniform(&rng, -2, 2), test_rng_uniform(&rng, -2, 2),
                          test_rng_uniform(&rng, -2, 2));
      mat3 r;
      vec3 c;
      piola_rigid_motion_pose(&d.motion, t, &r, &c);
      vec3 xt = vec3_add(mat3_mul_vec(r, x0), c);
      vec3 n0, nt, vel;
      double d0 = piola_obstacle_signed_distance(o, 0.0, x0, &n0, NULL);
      double dt = piola_obstacle_signed_distance(o, t, xt, &nt, &vel);
      assert_close(dt, d0, 1e-12);
      assert_close(vec3_norm(vec3_sub(nt, mat3_mul_vec(r, n0))), 0, 1e-12);
      if (fabs(t - 0.5) < 1e-3 || fabs(t - 2.0) < 1e-3) continue; /* velocity jumps at keys */
      double h = 1e-6;
      mat3 rp, rm;
      vec3 cp, cm;
      piola_rigid_motion_pose(&d.motion, t + h, &rp, &cp);
      piola_rigid_motion_pose(&d.motion, t - h, &rm, &cm);
      vec3 fd = vec3_scale(
          vec3_sub(vec3_add(mat3_mul_vec(rp, x0), cp), vec3_add(mat3_mul_vec(rm, x0), cm)),
          0.5 / h);
      assert_close(vec3_norm(vec3_sub(fd, vel)), 0, 1e-7 * (1 + vec3_norm(vel)));
    }
    piola_obstacle_destroy(o);
  }
  free_mesh(&cube);
}

/* Independent of the implementation's inverse pose: a translating sphere is |p - c(t)| - r,
 * and a box turned a quarter about z through its centre is the box with x and y swapped. */
static void moving_shapes_match_closed_forms(void **state) {
  (void)state;
  piola_obstacle_def d = piola_default_obstacle_def();
  d.type = PIOLA_OBSTACLE_SPHERE;
  d.radius = 0.5;
  d.center = vec3_make(1, 2, 3);
  d.motion.velocity[0] = piola_track_constant(2.0);
  d.motion.velocity[1] = piola_track_constant(-1.0);
  piola_obstacle *sphere = make(&d);
  vec3 vel;
  double t = 0.75;
  vec3 p = vec3_make(0.3, 0.2, 2.1);
  vec3 c = vec3_make(1 + 2 * t, 2 - t, 3);
  assert_close(piola_obstacle_signed_distance(sphere, t, p, NULL, &vel),
               vec3_norm(vec3_sub(p, c)) - 0.5, 1e-14);
  assert_close(vel.x, 2, 0);
  assert_close(vel.y, -1, 0);
  assert_close(vel.z, 0, 0);
  piola_obstacle_destroy(sphere);

  piola_obstacle_def b = piola_default_obstacle_def();
  b.type = PIOLA_OBSTACLE_BOX;
  b.center = vec3_make(1, 1, 0);
  b.half_extents = vec3_make(1, 2, 3);
  b.motion.pivot = b.center;
  b.motion.angular_speed = piola_track_constant(M_PI / 2); /* a quarter turn per second */
  piola_obstacle *turning = make(&b);
  b.half_extents = vec3_make(2, 1, 3);
  b.motion = piola_default_rigid_motion_def();
  piola_obstacle *swapped = make(&b);
  test_rng rng = test_rng_seeded(9);
  for (long s = 0; s < test_samples(500, 50); ++s) {
    vec3 q = vec3_make(test_rng_uniform(&rng, -3, 5), test_rng_uniform(&rng, -3, 5),
                       test_rng_uniform(&rng, -4, 4));
    assert_close(piola_obstacle_signed_distance(turning, 1.0, q, NULL, NULL),
                 piola_obstacle_signed_distance(swapped, 0.0, q, NULL, NULL), 1e-12);
  }
  /* The material point at the box's +x face centre (2, 1, 0) at t = 0 is at (1, 2, 0) at t = 1,
   * moving with (pi/2) z x (0, 1, 0) = (-pi/2, 0, 0). */
  piola_obstacle_signed_distance(turning, 1.0, vec3_make(1, 2, 0), NULL, &vel);
  assert_close(vel.x, -M_PI / 2, 1e-14);
  assert_close(vel.y, 0, 1e-14);
  piola_obstacle_destroy(turning);
  piola_obstacle_destroy(swapped);
}

static void expect_error(const piola_obstacle_def *d, piola_status expected, const char *needle) {
  piola_obstacle *o = (piola_obstacle *)&o; /* must be set to NULL on failure */
  piola_status s = piola_obstacle_create(d, &o);
  if (s != expected) fail_msg("expected status %d, got %d (%s)", expected, s, piola_last_error());
  assert_null(o);
  if (needle && !strstr(piola_last_error(), needle))
    fail_msg("message \"%s\" does not mention \"%s\"", piola_last_error(), needle);
}

static void invalid_definitions_are_rejected(void **state) {
  (void)state;
  piola_obstacle_def d = piola_default_obstacle_def();
  d.type = PIOLA_OBSTACLE_SPHERE;
  d.radius = -1;
  expect_error(&d, PIOLA_ERROR_INVALID_ARGUMENT, "radius");
  d.radius = NAN;
  expect_error(&d, PIOLA_ERROR_INVALID_ARGUMENT, "radius");
  d.radius = 1;
  d.friction = -0.1;
  expect_error(&d, PIOLA_ERROR_INVALID_ARGUMENT, "friction");
  d.friction = 0.3;
  d.center.x = INFINITY;
  expect_error(&d, PIOLA_ERROR_NOT_FINITE, "center");
  d.center.x = 0;
  d.motion.axis = vec3_make(0, 2, 0);
  expect_error(&d, PIOLA_ERROR_INVALID_ARGUMENT, "motion axis");
  d.motion.axis = vec3_make(0, 0, 1);
  d.motion.velocity[1].key_count = 2;
  d.motion.velocity[1].times[0] = 1;
  d.motion.velocity[1].times[1] = 1;
  expect_error(&d, PIOLA_ERROR_INVALID_ARGUMENT, "velocity.y");
  d.motion = piola_default_rigid_motion_def();

  d.type = PIOLA_OBSTACLE_BOX;
  d.half_extents = vec3_make(1, 0, 1);
  expect_error(&d, PIOLA_ERROR_INVALID_ARGUMENT, "half_extents.y");

  d.type = PIOLA_OBSTACLE_CYLINDER;
  d.half_length = 1;
  d.axis = vec3_make(0, 0, 0);
  expect_error(&d, PIOLA_ERROR_INVALID_ARGUMENT, "cylinder axis");
  d.axis = vec3_make(1, 1, 0);
  expect_error(&d, PIOLA_ERROR_INVALID_ARGUMENT, "cylinder axis");
  d.axis = vec3_make(0, 0, 1.0004); /* close enough: normalized */
  piola_obstacle *o = make(&d);
  assert_close(piola_obstacle_signed_distance(o, 0, vec3_make(0, 0, 3), NULL, NULL), 2, 1e-15);
  piola_obstacle_destroy(o);
  d.axis = vec3_make(0, 0, 1);
  d.half_length = 0;
  expect_error(&d, PIOLA_ERROR_INVALID_ARGUMENT, "half_length");

  d.type = PIOLA_OBSTACLE_TORUS;
  d.radius = 1;
  d.minor_radius = 1.5;
  expect_error(&d, PIOLA_ERROR_INVALID_ARGUMENT, "minor_radius");

  d.type = PIOLA_OBSTACLE_GEAR;
  d.half_length = 0.1;
  d.tooth_count = 2;
  d.tooth_depth = 0.1;
  expect_error(&d, PIOLA_ERROR_INVALID_ARGUMENT, "tooth_count");
  d.tooth_count = 12;
  d.tooth_depth = 1.0;
  expect_error(&d, PIOLA_ERROR_INVALID_ARGUMENT, "tooth_depth");
  d.tooth_depth = 0;
  expect_error(&d, PIOLA_ERROR_INVALID_ARGUMENT, "tooth_depth");

  d.type = PIOLA_OBSTACLE_MESH;
  d.mesh = NULL;
  expect_error(&d, PIOLA_ERROR_INVALID_ARGUMENT, "mesh");
  piola_tri_mesh cube;
  cube_mesh(&cube, vec3_make(0, 0, 0), vec3_make(1, 1, 1), 0);
  d.mesh = &cube;
  cube.triangle_count = 11; /* a hole */
  expect_error(&d, PIOLA_ERROR_INVALID_ARGUMENT, "open");
  cube.triangle_count = 12;
  int32_t keep = cube.triangles[1];
  cube.triangles[1] = cube.triangles[2]; /* one face wound against its neighbours */
  cube.triangles[2] = keep;
  expect_error(&d, PIOLA_ERROR_INVALID_ARGUMENT,
               "mesh obstacle: surface is not consistently oriented");
  cube.triangles[2] = cube.triangles[1];
  cube.triangles[1] = keep;
  cube.triangles[5] = 8;
  expect_error(&d, PIOLA_ERROR_INVALID_ARGUMENT, "out of");
  free_mesh(&cube);

  d.type = PIOLA_OBSTACLE_TYPE_COUNT;
  expect_error(&d, PIOLA_ERROR_INVALID_ARGUMENT, "type");
  assert_int_equal(piola_obstacle_create(NULL, &o), PIOLA_ERROR_INVALID_ARGUMENT);
  piola_obstacle_destroy(NULL);
}

static void friction_is_reported(void **state) {
  (void)state;
  piola_obstacle_def d = piola_default_obstacle_def();
  assert_close(d.friction, 0, 0);
  d.friction = 0.4;
  piola_obstacle *o = make(&d);
  assert_close(piola_obstacle_friction(o), 0.4, 0);
  piola_obstacle_destroy(o);
}

/* A query at a non-finite point or time has no distance: a box's clamps put a NaN point on
 * its surface (distance 0) before. */
static void non_finite_queries_give_nan(void **state) {
  (void)state;
  piola_obstacle_def d = piola_default_obstacle_def();
  d.type = PIOLA_OBSTACLE_BOX;
  d.half_extents = vec3_make(1, 2, 3);
  piola_obstacle *o = make(&d);
  vec3 n, v;
  assert_true(isnan(piola_obstacle_signed_distance(o, 0, vec3_make(NAN, 0, 0), &n, &v)));
  assert_true(isnan(n.x) && isnan(v.x));
  assert_true(isnan(piola_obstacle_signed_distance(o, INFINITY, vec3_make(0, 0, 5), NULL, NULL)));
  const piola_obstacle_pose pose = piola_obstacle_pose_at(o, 0);
  assert_true(isnan(piola_obstacle_posed_distance(o, &pose, vec3_make(0, INFINITY, 0), &n)));
  assert_true(isnan(n.z));
  assert_close(piola_obstacle_signed_distance(o, 0, vec3_make(0, 0, 5), &n, &v), 2, 1e-15);
  piola_obstacle_destroy(o);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(non_finite_queries_give_nan),
      cmocka_unit_test(plane_distances),
      cmocka_unit_test(sphere_distances),
      cmocka_unit_test(box_distances),
      cmocka_unit_test(cylinder_distances),
      cmocka_unit_test(capsule_distances),
      cmocka_unit_test(torus_distances),
      cmocka_unit_test(mesh_cube_equals_box),
      cmocka_unit_test(mesh_octahedron_matches_its_face_planes),
      cmocka_unit_test(normals_are_gradients_and_eikonal),
      cmocka_unit_test(distances_are_one_lipschitz),
      cmocka_unit_test(moving_obstacles_carry_their_distance),
      cmocka_unit_test(moving_shapes_match_closed_forms),
      cmocka_unit_test(invalid_definitions_are_rejected),
      cmocka_unit_test(friction_is_reported),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
