/* Mesh obstacles from the real surfaces in shared/data: the triangulated unit sphere is
 * within its Hausdorff distance of the analytic sphere everywhere, and random nodes pushed
 * out of the bunny and the armadillo end outside, with the exact distance's properties. */
#include <math.h>
#include <stdlib.h>

#include "test_support.h"

#include "math/mat3.h"
#include "piola/mesh_io.h"
#include "piola/obstacle.h"

static piola_obstacle *mesh_obstacle(const char *relative, piola_tri_mesh *mesh) {
  piola_status s = piola_tri_mesh_read(test_data_path(relative), mesh);
  if (s != PIOLA_OK) fail_msg("reading %s: %s", relative, piola_last_error());
  piola_obstacle_def d = piola_default_obstacle_def();
  d.type = PIOLA_OBSTACLE_MESH;
  d.mesh = mesh;
  piola_obstacle *o = NULL;
  if (piola_obstacle_create(&d, &o) != PIOLA_OK) fail_msg("%s: %s", relative, piola_last_error());
  return o;
}

/* |d_mesh - d_sphere| <= h, the Hausdorff distance between the two surfaces: the farthest a
 * vertex is from the unit sphere, or the deepest a triangle dips inside it (1 - the distance
 * from the centre to the mesh). */
static void triangulated_sphere_is_within_its_hausdorff_distance(void **state) {
  (void)state;
  piola_tri_mesh mesh;
  piola_obstacle *o = mesh_obstacle("surface/sphere.obj", &mesh);
  double h = 0;
  for (int32_t i = 0; i < mesh.vertex_count; ++i)
    h = fmax(h, fabs(vec3_norm(vec3_load(mesh.positions + 3 * i)) - 1));
  double centre = piola_obstacle_signed_distance(o, 0, vec3_make(0, 0, 0), NULL, NULL);
  assert_true(centre < -0.9);
  h = fmax(h, 1 + centre);
  assert_true(h < 0.05);
  piola_obstacle_def sd = piola_default_obstacle_def();
  sd.type = PIOLA_OBSTACLE_SPHERE;
  sd.radius = 1;
  piola_obstacle *sphere;
  assert_int_equal(piola_obstacle_create(&sd, &sphere), PIOLA_OK);
  test_rng rng = test_rng_seeded(8);
  for (long k = 0; k < test_samples(3000, 100); ++k) {
    vec3 p = vec3_make(test_rng_uniform(&rng, -2, 2), test_rng_uniform(&rng, -2, 2),
                       test_rng_uniform(&rng, -2, 2));
    double dm = piola_obstacle_signed_distance(o, 0, p, NULL, NULL);
    double ds = piola_obstacle_signed_distance(sphere, 0, p, NULL, NULL);
    assert_true(fabs(dm - ds) <= h + 1e-12);
  }
  piola_obstacle_destroy(sphere);
  piola_obstacle_destroy(o);
  free(mesh.positions);
  free(mesh.triangles);
}

static void nodes_are_pushed_out_of_real_surfaces(void **state) {
  (void)state;
  const char *files[] = {"surface/bunny_10k.obj", "surface/armadillo_low_res.obj"};
  for (int f = 0; f < 2; ++f) {
    piola_tri_mesh mesh;
    piola_obstacle *o = mesh_obstacle(files[f], &mesh);
    vec3 lo = vec3_load(mesh.positions), hi = lo;
    for (int32_t i = 1; i < mesh.vertex_count; ++i) {
      vec3 p = vec3_load(mesh.positions + 3 * i);
      lo = vec3_make(fmin(lo.x, p.x), fmin(lo.y, p.y), fmin(lo.z, p.z));
      hi = vec3_make(fmax(hi.x, p.x), fmax(hi.y, p.y), fmax(hi.z, p.z));
    }
    int32_t n = (int32_t)test_samples(3000, 200);
    double *x = malloc(sizeof(double) * 3 * (size_t)n), *v = calloc(3 * (size_t)n, sizeof(double));
    uint8_t *c = malloc((size_t)n);
    test_rng rng = test_rng_seeded(60 + (uint64_t)f);
    int32_t inside = 0;
    for (int32_t i = 0; i < n; ++i) {
      x[3 * i] = test_rng_uniform(&rng, lo.x, hi.x);
      x[3 * i + 1] = test_rng_uniform(&rng, lo.y, hi.y);
      x[3 * i + 2] = test_rng_uniform(&rng, lo.z, hi.z);
      inside += piola_obstacle_signed_distance(o, 0, vec3_load(x + 3 * i), NULL, NULL) < 0;
    }
    assert_true(inside > n / 20); /* the model fills a good part of its box */
    assert_int_equal(piola_obstacles_collide(&o, 1, 0, 0.01, n, x, v, c, NULL), inside);
    double scale = vec3_norm(vec3_sub(hi, lo));
    for (int32_t i = 0; i < n; ++i) {
      vec3 p = vec3_load(x + 3 * i);
      double phi = piola_obstacle_signed_distance(o, 0, p, NULL, NULL);
      if (!(phi >= -1e-12 * scale)) fail_msg("%s: node %d left %g inside", files[f], (int)i, phi);
      if (c[i]) assert_true(phi <= 1e-9 * scale); /* projected nodes lie on the surface */
    }
    piola_obstacle_destroy(o);
    free(mesh.positions);
    free(mesh.triangles);
    free(x);
    free(v);
    free(c);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(triangulated_sphere_is_within_its_hausdorff_distance),
      cmocka_unit_test(nodes_are_pushed_out_of_real_surfaces),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
