/* The history a collision surface carries from call to call (the trees' shapes and age,
 * contact/surface_history.h) travels through its bytes: a surface created anew that takes
 * the history of one that has run gives bit-identical velocities over the calls after, a
 * tree rebuild included, and hands back the same bytes; histories that do not fit (wrong
 * length, counts, indices, a node reached twice) are refused without touching the surface. */
#include "test_support.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "contact/contact_internal.h"
#include "contact/surface_history.h"
#include "piola/collision_surface.h"

enum { GRID = 8, VERTICES = 2 * GRID * GRID, TRIANGLES = 4 * (GRID - 1) * (GRID - 1) };
static const double spacing = 0.01, thickness = 4e-3, dt = 1e-3;

typedef struct sheets {
  int32_t tris[3 * TRIANGLES];
  double x[3 * VERTICES], v[3 * VERTICES], mass[VERTICES];
} sheets;

/* Two GRID x GRID sheets, the upper one a thickness above the lower, shifted and noisy,
 * falling onto it; a corner of each pinned (malloc'ed). */
static sheets *new_sheets(uint64_t seed) {
  test_rng r = test_rng_seeded(seed), *rng = &r;
  sheets *s = malloc(sizeof *s);
  assert_non_null(s);
  int32_t t = 0;
  for (int32_t i = 0; i < VERTICES; ++i) {
    const int32_t layer = i / (GRID * GRID), col = i % GRID, row = (i / GRID) % GRID;
    double *p = s->x + 3 * i, *q = s->v + 3 * i;
    p[0] = (col + 0.3 * layer) * spacing + test_rng_uniform(rng, -0.1, 0.1) * thickness;
    p[1] = (row + 0.2 * layer) * spacing + test_rng_uniform(rng, -0.1, 0.1) * thickness;
    p[2] = layer * thickness * 1.5 + test_rng_uniform(rng, -0.2, 0.2) * thickness;
    q[0] = test_rng_uniform(rng, -0.5, 0.5), q[1] = test_rng_uniform(rng, -0.5, 0.5);
    q[2] = layer ? -3.0 : test_rng_uniform(rng, -0.5, 0.5);
    s->mass[i] = (col == 0 && row == 0) ? INFINITY : 1e-3;
    if (col + 1 < GRID && row + 1 < GRID) {
      const int32_t a = i, b = i + 1, c = i + GRID, d = i + GRID + 1;
      const int32_t quad[6] = {a, b, d, a, d, c};
      memcpy(s->tris + 3 * t, quad, sizeof quad);
      t += 2;
    }
  }
  return s;
}

static piola_collision_surface *surface_of(const sheets *s) {
  piola_collision_body_def body = piola_default_collision_body_def();
  body.thickness = thickness;
  piola_collision_surface_def def = piola_default_collision_surface_def();
  def.vertex_count = VERTICES, def.triangle_count = TRIANGLES, def.triangles = s->tris;
  def.body_count = 1, def.bodies = &body;
  piola_collision_surface *surface = NULL;
  assert_int_equal(piola_collision_surface_create(&def, &surface), PIOLA_OK);
  return surface;
}

/* One call from x with the velocities v (changed), then the positions move on. */
static piola_collision_stats step(piola_collision_surface *surface, double *x, double *v,
                                  const double *mass) {
  piola_collision_stats stats;
  assert_int_equal(piola_collision_surface_process(surface, x, v, mass, dt, NULL, &stats), PIOLA_OK);
  for (int32_t i = 0; i < 3 * VERTICES; ++i) x[i] += dt * v[i];
  return stats;
}

static unsigned char *history_of(const piola_collision_surface *surface, size_t *n) {
  *n = piola__collision_surface_history_size(surface);
  unsigned char *bytes = malloc(*n);
  assert_non_null(bytes);
  piola__collision_surface_history_save(surface, bytes);
  return bytes;
}

static void history_carries_the_impulse_order(void **state) {
  (void)state;
  sheets *s = new_sheets(18);
  piola_collision_surface *ran = surface_of(s);
  for (int call = 0; call < 3; ++call) step(ran, s->x, s->v, s->mass);
  assert_int_equal(ran->tree_age, 3);

  size_t n;
  unsigned char *bytes = history_of(ran, &n);
  piola_collision_surface *resumed = surface_of(s);
  assert_int_equal(piola__collision_surface_history_load(resumed, bytes, n, 0), 0);
  assert_int_equal(resumed->tree_age, 0); /* a check only */
  assert_int_equal(piola__collision_surface_history_load(resumed, bytes, n, 1), 0);
  size_t n2;
  unsigned char *again = history_of(resumed, &n2);
  assert_true(n2 == n && memcmp(bytes, again, n) == 0);

  /* Ten more calls each: the trees are refit five times, rebuilt, refit again. */
  double x2[3 * VERTICES], v2[3 * VERTICES];
  memcpy(x2, s->x, sizeof x2), memcpy(v2, s->v, sizeof v2);
  int64_t acted = 0;
  for (int call = 0; call < 10; ++call) {
    piola_collision_stats a = step(ran, s->x, s->v, s->mass);
    piola_collision_stats b = step(resumed, x2, v2, s->mass);
    assert_true(memcmp(s->v, v2, sizeof v2) == 0);
    assert_true(memcmp(s->x, x2, sizeof x2) == 0);
    assert_true(a.contacts == b.contacts && a.impacts == b.impacts);
    acted += a.contacts + a.impacts;
  }
  assert_true(acted > 20); /* the sheets were in contact: the order of impulses mattered */
  free(bytes), free(again), free(s);
  piola_collision_surface_destroy(ran);
  piola_collision_surface_destroy(resumed);
}

static int32_t get_i32(const unsigned char *p) {
  int32_t v;
  memcpy(&v, p, 4);
  return v;
}

static void put_i32(unsigned char *p, int32_t v) { memcpy(p, &v, 4); }

/* Refused by the check and by the store, and the surface keeps its own history. */
static void assert_refused(piola_collision_surface *surface, const unsigned char *bytes, size_t n,
                           const char *what) {
  size_t before_n;
  unsigned char *before = history_of(surface, &before_n);
  if (piola__collision_surface_history_load(surface, bytes, n, 0) != -1 ||
      piola__collision_surface_history_load(surface, bytes, n, 1) != -1)
    fail_msg("a history with %s was taken", what);
  size_t after_n;
  unsigned char *after = history_of(surface, &after_n);
  assert_true(before_n == after_n && memcmp(before, after, before_n) == 0);
  free(before), free(after);
}

static void histories_that_do_not_fit_are_refused(void **state) {
  (void)state;
  sheets *s = new_sheets(7);
  piola_collision_surface *surface = surface_of(s);
  step(surface, s->x, s->v, s->mass);
  size_t n;
  unsigned char *good = history_of(surface, &n), *bad = malloc(n + 8);
  assert_non_null(bad);
  /* the triangle tree: its node count at 4, nodes from 8, the root inner (first = right child) */
  const int32_t nodes = get_i32(good + 4);
  const size_t order = 8 + 8 * (size_t)nodes;
  assert_true(nodes > 1 && get_i32(good + 12) == 0);
  int32_t leaf = 0;
  while (get_i32(good + 8 + 8 * (size_t)leaf + 4) == 0) ++leaf;

  assert_refused(surface, good, n - 1, "a byte missing");
  memcpy(bad, good, n), bad[n] = 0;
  assert_refused(surface, bad, n + 1, "a byte too many");
  memcpy(bad, good, n), put_i32(bad, -1);
  assert_refused(surface, bad, n, "a negative age");
  memcpy(bad, good, n), put_i32(bad + 4, 2 * TRIANGLES);
  assert_refused(surface, bad, n, "more nodes than a tree over these triangles has");
  memcpy(bad, good, n), put_i32(bad + 8, 1);
  assert_refused(surface, bad, n, "both children of the root the same node");
  memcpy(bad, good, n), put_i32(bad + 8, nodes);
  assert_refused(surface, bad, n, "a child beyond the last node");
  memcpy(bad, good, n), put_i32(bad + 8 + 8 * (size_t)leaf, TRIANGLES - 1);
  assert_refused(surface, bad, n, "a leaf running past the last triangle");
  memcpy(bad, good, n), put_i32(bad + order, TRIANGLES);
  assert_refused(surface, bad, n, "a triangle index out of range");
  memcpy(bad, good, n), put_i32(bad + order + 4, -1);
  assert_refused(surface, bad, n, "a negative triangle index");
  /* and the unchanged bytes are taken */
  assert_int_equal(piola__collision_surface_history_load(surface, good, n, 1), 0);
  free(good), free(bad), free(s);
  piola_collision_surface_destroy(surface);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(history_carries_the_impulse_order),
      cmocka_unit_test(histories_that_do_not_fit_are_refused),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
