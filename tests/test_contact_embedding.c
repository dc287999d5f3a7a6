/* Embedded collision surfaces (src/contact/embedding.c, docs/contact.md "Embedded
 * vertices"): two boxes' boundaries thrown into each other fast enough that repulsion,
 * impacts and rigid zones act.
 *  - With every vertex embedded in its own node with weight 1, processing gives the same
 *    velocities, to the bit, as the plain surface.
 *  - With each vertex a point between two nodes of its own (weights 0.8 and 0.2, the nodes
 *    with different masses and velocities), processing keeps the nodes' linear momentum
 *    to rounding, and the vertices' paths from the new node velocities leave no
 *    intersecting triangle pair at five times of the step (the exact referee), where the
 *    unprocessed throw has some; again with rigid impact zones alone (zones of nodes).
 *  - A bad embedding is refused. */
#include "test_support.h"
#include "triangle_referee.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "piola/collision_surface.h"
#include "piola/mesh.h"

typedef struct two_boxes {
  int32_t n, nt;     /* vertices (both boxes), triangles */
  double *x, *v, *m; /* per vertex */
  int32_t *tris;
} two_boxes;

/* Box 1 a little to the right of box 0 and thrown into it (m/s). */
static two_boxes make_boxes(double speed) {
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(3, 3, 3, (piola_vec3){0.02, 0.02, 0.02}, &mesh), PIOLA_OK);
  piola_tri_mesh boundary;
  assert_int_equal(piola_tet_mesh_boundary(&mesh, &boundary), PIOLA_OK);
  two_boxes b;
  const int32_t n = mesh.vertex_count, nt = boundary.triangle_count;
  b.n = 2 * n, b.nt = 2 * nt;
  b.x = malloc(3 * sizeof(double) * (size_t)b.n), b.v = malloc(3 * sizeof(double) * (size_t)b.n);
  b.m = malloc(sizeof(double) * (size_t)b.n), b.tris = malloc(3 * sizeof(int32_t) * (size_t)b.nt);
  for (int box = 0; box < 2; ++box) {
    for (int32_t i = 0; i < n; ++i) {
      const int32_t g = box * n + i;
      for (int k = 0; k < 3; ++k) b.x[3 * g + k] = mesh.positions[3 * i + k] + (box && k == 0 ? 0.0605 : 0);
      b.x[3 * g + 1] += box ? 0.013 : 0; /* offset, so edges and corners meet faces */
      b.v[3 * g] = box ? -speed : 0.3 * speed, b.v[3 * g + 1] = box ? 0.1 * speed : 0;
      b.v[3 * g + 2] = 0.05 * speed * (double)(i % 3);
      b.m[g] = 0.001 * (1 + (i % 4));
    }
    for (int32_t t = 0; t < 3 * nt; ++t) b.tris[3 * box * nt + t] = box * n + boundary.triangles[t];
  }
  piola_tri_mesh_free(&boundary);
  piola_tet_mesh_free(&mesh);
  return b;
}

static void free_boxes(two_boxes *b) { free(b->x), free(b->v), free(b->m), free(b->tris); }

static piola_collision_surface *surface_of(const two_boxes *b, int32_t nodes, const int32_t *embed,
                                           const double *weights) {
  piola_collision_body_def body = piola_default_collision_body_def();
  body.thickness = 1e-3;
  piola_collision_surface_def def = piola_default_collision_surface_def();
  def.vertex_count = b->n, def.triangle_count = b->nt, def.triangles = b->tris;
  def.body_count = 1, def.bodies = &body;
  def.node_count = nodes, def.embed_nodes = embed, def.embed_weights = weights;
  piola_collision_surface *s = NULL;
  assert_int_equal(piola_collision_surface_create(&def, &s), PIOLA_OK);
  return s;
}

static void identity_embedding_changes_nothing(void **state) {
  (void)state;
  two_boxes b = make_boxes(3.0);
  const double dt = 0.01;
  piola_collision_surface *plain = surface_of(&b, 0, NULL, NULL);
  int32_t *embed = malloc(4 * sizeof(int32_t) * (size_t)b.n);
  double *weights = calloc(4 * (size_t)b.n, sizeof(double));
  for (int32_t i = 0; i < b.n; ++i) {
    embed[4 * i] = i, weights[4 * i] = 1;
    for (int j = 1; j < 4; ++j) embed[4 * i + j] = -1;
  }
  piola_collision_surface *same = surface_of(&b, b.n, embed, weights);
  double *v1 = malloc(3 * sizeof(double) * (size_t)b.n), *v2 = malloc(3 * sizeof(double) * (size_t)b.n);
  memcpy(v1, b.v, 3 * sizeof(double) * (size_t)b.n), memcpy(v2, b.v, 3 * sizeof(double) * (size_t)b.n);
  piola_collision_stats s1, s2;
  assert_int_equal(piola_collision_surface_process(plain, b.x, v1, b.m, dt, NULL, &s1), PIOLA_OK);
  assert_int_equal(piola_collision_surface_process(same, b.x, v2, b.m, dt, NULL, &s2), PIOLA_OK);
  assert_true(s1.impacts > 0 || s1.impact_zones > 0);
  assert_memory_equal(v1, v2, 3 * sizeof(double) * (size_t)b.n);
  assert_int_equal(s1.impacts, s2.impacts);
  assert_int_equal(s1.impact_zones, s2.impact_zones);
  /* a bad embedding: weights that do not sum to 1 */
  weights[0] = 0.5;
  piola_collision_body_def body = piola_default_collision_body_def();
  piola_collision_surface_def def = piola_default_collision_surface_def();
  def.vertex_count = b.n, def.triangle_count = b.nt, def.triangles = b.tris;
  def.body_count = 1, def.bodies = &body;
  def.node_count = b.n, def.embed_nodes = embed, def.embed_weights = weights;
  piola_collision_surface *bad = NULL;
  assert_int_equal(piola_collision_surface_create(&def, &bad), PIOLA_ERROR_INVALID_ARGUMENT);
  weights[0] = 1, embed[1] = b.n; /* a node out of range */
  weights[1] = 0.0;
  assert_int_equal(piola_collision_surface_create(&def, &bad), PIOLA_ERROR_INVALID_ARGUMENT);
  piola_collision_surface_destroy(plain);
  piola_collision_surface_destroy(same);
  free(v1), free(v2), free(embed), free(weights);
  free_boxes(&b);
}

static void embedded_points_keep_momentum_and_do_not_cross(void **state) {
  (void)state;
  two_boxes b = make_boxes(3.0);
  const double dt = 0.01;
  /* nodes: two per vertex, its own (i) and a second one (n + i) a little off it, moving
   * differently: vertex i = 0.8 y_i + 0.2 y_{n+i}, placed where the box's vertex was */
  const int32_t nodes = 2 * b.n;
  double *y = malloc(3 * sizeof(double) * (size_t)nodes), *u = malloc(3 * sizeof(double) * (size_t)nodes);
  double *m = malloc(sizeof(double) * (size_t)nodes);
  int32_t *embed = malloc(4 * sizeof(int32_t) * (size_t)b.n);
  double *weights = calloc(4 * (size_t)b.n, sizeof(double));
  for (int32_t i = 0; i < b.n; ++i) {
    const int32_t second = b.n + i;
    embed[4 * i] = i, embed[4 * i + 1] = second, embed[4 * i + 2] = embed[4 * i + 3] = -1;
    weights[4 * i] = 0.8, weights[4 * i + 1] = 0.2;
    for (int k = 0; k < 3; ++k) {
      y[3 * second + k] = b.x[3 * i + k] + 0.004 * (k == (int)(i % 3) ? 1 : -0.5);
      y[3 * i + k] = (b.x[3 * i + k] - 0.2 * y[3 * second + k]) / 0.8;
      u[3 * second + k] = b.v[3 * i + k] + (k == 2 ? 0.2 : 0);
      u[3 * i + k] = (b.v[3 * i + k] - 0.2 * u[3 * second + k]) / 0.8;
    }
    m[i] = b.m[i], m[second] = 0.5 * b.m[i];
  }
  piola_collision_surface *s = surface_of(&b, nodes, embed, weights);
  double *u0 = malloc(3 * sizeof(double) * (size_t)nodes), *x = malloc(3 * sizeof(double) * (size_t)b.n);
  memcpy(u0, u, 3 * sizeof(double) * (size_t)nodes);
  judged set = {.x = x, .tris = b.tris, .count = b.nt};
  /* with the default stages, and with rigid impact zones alone (no impact passes) */
  for (int zones_only = 0; zones_only < 2; ++zones_only) {
    memcpy(u, u0, 3 * sizeof(double) * (size_t)nodes);
    piola_collision_settings settings = piola_default_collision_settings();
    if (zones_only) settings.collision_iterations = 0;
    double p0[3] = {0, 0, 0}, p1[3] = {0, 0, 0}, scale = 0;
    for (int32_t j = 0; j < nodes; ++j)
      for (int k = 0; k < 3; ++k) p0[k] += m[j] * u[3 * j + k], scale += m[j] * fabs(u[3 * j + k]);
    piola_collision_stats st;
    assert_int_equal(piola_collision_surface_process(s, y, u, m, dt, &settings, &st), PIOLA_OK);
    assert_true(zones_only ? st.impact_zones > 0 : st.contacts + st.impacts > 0);
    assert_int_equal(st.resolved, 1);
    for (int32_t j = 0; j < nodes; ++j)
      for (int k = 0; k < 3; ++k) p1[k] += m[j] * u[3 * j + k];
    for (int k = 0; k < 3; ++k) assert_true(fabs(p1[k] - p0[k]) < 1e-12 * scale);
    /* the vertices from the nodes at five times of the step */
    for (int step = 1; step <= 5; ++step) {
      const double tau = dt * step / 5.0;
      for (int32_t i = 0; i < b.n; ++i)
        for (int k = 0; k < 3; ++k) {
          x[3 * i + k] = 0;
          for (int j = 0; j < 2; ++j) {
            const int32_t node = embed[4 * i + j];
            x[3 * i + k] += weights[4 * i + j] * (y[3 * node + k] + tau * u[3 * node + k]);
          }
        }
      assert_int_equal(referee_count_intersections(&set, 1), 0);
    }
  }
  /* without processing, the same throw crosses */
  for (int32_t i = 0; i < b.n; ++i)
    for (int k = 0; k < 3; ++k) x[3 * i + k] = b.x[3 * i + k] + dt * b.v[3 * i + k];
  assert_true(referee_count_intersections(&set, 1) > 0);
  piola_collision_surface_destroy(s);
  free(x), free(y), free(u), free(u0), free(m), free(embed), free(weights);
  free_boxes(&b);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(identity_embedding_changes_nothing),
      cmocka_unit_test(embedded_points_keep_momentum_and_do_not_cross),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
