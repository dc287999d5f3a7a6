/* The accelerated detection of collision processing (candidates from one tree descent, scans
 * of them, tree queries for vertices whose velocity left its reach box, collecting again when
 * many did) finds exactly the contacts and collisions that testing every pair finds, on random
 * small configurations: two noisy sheets close together with random velocities, some vertices
 * pinned, velocities changed after the candidates were collected (a little for most vertices,
 * a lot for a few or for many), and passes restricted to pairs with a dirty vertex. */
#include "test_support.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "contact/contact_internal.h"
#include "piola/collision_surface.h"

/* A pair as a sortable key: kind, then the vertices; an edge-edge pair lists its lower edge
 * first, so both orders of the same two edges give one key. */
typedef struct pair_key {
  int32_t k[5];
} pair_key;

static int compare_keys(const void *a, const void *b) {
  const pair_key *x = a, *y = b;
  for (int i = 0; i < 5; ++i)
    if (x->k[i] != y->k[i]) return (x->k[i] > y->k[i]) - (x->k[i] < y->k[i]);
  return 0;
}

static pair_key key_of(const piola__contact *c) {
  pair_key key = {{c->edge_edge, c->v[0], c->v[1], c->v[2], c->v[3]}};
  if (c->edge_edge && (c->v[0] > c->v[2] || (c->v[0] == c->v[2] && c->v[1] > c->v[3]))) {
    key.k[1] = c->v[2], key.k[2] = c->v[3], key.k[3] = c->v[0], key.k[4] = c->v[1];
  }
  return key;
}

/* Sorted keys of a contact list, keeping only pairs with a vertex marked in filter (if given). */
static pair_key *keys_of(const piola__contact_list *list, const uint8_t *filter, int64_t *count) {
  pair_key *keys = malloc(sizeof(pair_key) * (size_t)(list->count + 1));
  assert_non_null(keys);
  int64_t n = 0;
  for (int64_t i = 0; i < list->count; ++i) {
    const int32_t *v = list->items[i].v;
    if (filter && !(filter[v[0]] || filter[v[1]] || filter[v[2]] || filter[v[3]])) continue;
    keys[n++] = key_of(&list->items[i]);
  }
  qsort(keys, (size_t)n, sizeof(pair_key), compare_keys);
  *count = n;
  return keys;
}

/* The accelerated result (s->found) holds each pair of the reference once and nothing else. */
static void assert_same_pairs(const piola_collision_surface *s, const piola__contact_list *ref,
                              const uint8_t *filter, const char *what) {
  int64_t n_fast, n_ref;
  pair_key *fast = keys_of(&s->found, NULL, &n_fast);
  pair_key *slow = keys_of(ref, filter, &n_ref);
  for (int64_t i = 1; i < n_fast; ++i)
    if (compare_keys(&fast[i - 1], &fast[i]) == 0)
      fail_msg("%s: pair (%d %d %d %d) found twice", what, fast[i].k[1], fast[i].k[2], fast[i].k[3],
               fast[i].k[4]);
  if (n_fast != n_ref)
    fail_msg("%s: %lld pairs, all-pairs reference %lld", what, (long long)n_fast, (long long)n_ref);
  for (int64_t i = 0; i < n_ref; ++i)
    if (compare_keys(&fast[i], &slow[i]) != 0)
      fail_msg("%s: pair %lld differs: (%d: %d %d %d %d) vs reference (%d: %d %d %d %d)", what,
               (long long)i, fast[i].k[0], fast[i].k[1], fast[i].k[2], fast[i].k[3], fast[i].k[4],
               slow[i].k[0], slow[i].k[1], slow[i].k[2], slow[i].k[3], slow[i].k[4]);
  free(fast), free(slow);
}

typedef struct config {
  int32_t nv, nt;
  double *x, *v;
  int32_t *tris;
  double h, dt;
} config;

/* Two n x n sheets of spacing 1/(n-1) m, the second one gap above the first and slightly
 * turned, both with noise of a thickness or so, and random velocities that move vertices by
 * up to `reach` thicknesses over the step. */
static config make_config(test_rng *rng, int n) {
  config c = {0};
  c.nv = 2 * n * n, c.nt = 4 * (n - 1) * (n - 1);
  c.x = malloc(sizeof(double) * 3 * (size_t)c.nv);
  c.v = malloc(sizeof(double) * 3 * (size_t)c.nv);
  c.tris = malloc(sizeof(int32_t) * 3 * (size_t)c.nt);
  assert_non_null(c.x), assert_non_null(c.v), assert_non_null(c.tris);
  const double spacing = 1.0 / (n - 1);
  c.h = test_rng_uniform(rng, 0.15, 0.4) * spacing;
  c.dt = 1e-2;
  const double gap = test_rng_uniform(rng, 0.0, 2.0) * c.h, turn = test_rng_uniform(rng, -0.3, 0.3);
  const double reach = test_rng_uniform(rng, 0.1, 2.0);
  int32_t k = 0;
  for (int sheet = 0; sheet < 2; ++sheet)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        double u = i * spacing - 0.5, w = j * spacing - 0.5;
        double ct = sheet ? cos(turn) : 1.0, st = sheet ? sin(turn) : 0.0;
        double *p = c.x + 3 * k, *q = c.v + 3 * k;
        p[0] = ct * u - st * w + test_rng_uniform(rng, -0.5, 0.5) * c.h;
        p[1] = st * u + ct * w + test_rng_uniform(rng, -0.5, 0.5) * c.h;
        p[2] = sheet * gap + test_rng_uniform(rng, -1.0, 1.0) * c.h;
        for (int d = 0; d < 3; ++d) q[d] = test_rng_uniform(rng, -1.0, 1.0) * reach * c.h / c.dt;
        ++k;
      }
  k = 0;
  for (int sheet = 0; sheet < 2; ++sheet)
    for (int j = 0; j + 1 < n; ++j)
      for (int i = 0; i + 1 < n; ++i) {
        int32_t a = sheet * n * n + j * n + i, b = a + 1, cc = a + n, d = cc + 1;
        int32_t *t = c.tris + 3 * k;
        t[0] = a, t[1] = b, t[2] = d, t[3] = a, t[4] = d, t[5] = cc;
        k += 2;
      }
  return c;
}

static void config_free(config *c) { free(c->x), free(c->v), free(c->tris); }

static piola_collision_surface *make_surface(const config *c, test_rng *rng) {
  piola_collision_body_def body = piola_default_collision_body_def();
  body.thickness = c->h;
  piola_collision_surface_def def = piola_default_collision_surface_def();
  def.vertex_count = c->nv, def.triangle_count = c->nt, def.triangles = c->tris;
  def.body_count = 1, def.bodies = &body;
  piola_collision_surface *s = NULL;
  assert_int_equal(piola_collision_surface_create(&def, &s), PIOLA_OK);
  /* What processing sets up before detecting: inverse masses, some vertices pinned. */
  for (int32_t i = 0; i < c->nv; ++i)
    s->inverse_mass[i] = test_rng_uniform(rng, 0.0, 1.0) < 0.05 ? 0.0 : 1e3;
  return s;
}

/* Counts over all configurations, so that the comparisons cannot pass by finding nothing. */
typedef struct totals {
  int64_t contacts, collisions, escaped_runs, recollect_runs, dirty_collisions;
} totals;

static int64_t count_escaped(const piola_collision_surface *s) {
  int64_t n = 0;
  for (int32_t i = 0; i < s->vertex_count; ++i) n += s->escaped[i];
  return n;
}

static void check_config(test_rng *rng, totals *tot) {
  config c = make_config(rng, 6 + (int)(test_rng_next(rng) % 4));
  piola_collision_surface *s = make_surface(&c, rng);
  piola__contact_list ref = {0};
  int tree_built = 0;
  assert_int_equal(piola__collect_candidates(s, c.x, c.v, c.dt, &tree_built), 0);

  assert_int_equal(piola__detect(s, c.x, c.v, c.dt, PIOLA__DETECT_PROXIMITY, NULL, &tree_built), 0);
  assert_int_equal(piola__detect_all_pairs(s, c.x, c.v, c.dt, PIOLA__DETECT_PROXIMITY, &ref), 0);
  assert_same_pairs(s, &ref, NULL, "proximity");
  tot->contacts += ref.count;

  assert_int_equal(piola__detect(s, c.x, c.v, c.dt, PIOLA__DETECT_CCD, NULL, &tree_built), 0);
  assert_int_equal(piola__detect_all_pairs(s, c.x, c.v, c.dt, PIOLA__DETECT_CCD, &ref), 0);
  assert_same_pairs(s, &ref, NULL, "collisions with the velocities the candidates came from");
  tot->collisions += ref.count;

  /* Velocities change after the candidates were collected: a little for most vertices (as
   * repulsion does), a lot for a few (their swept boxes leave their reach boxes). */
  const int32_t nv = c.nv;
  double *v2 = malloc(sizeof(double) * 3 * (size_t)nv);
  uint8_t *dirty = calloc((size_t)nv, 1);
  assert_non_null(v2), assert_non_null(dirty);
  for (int32_t i = 0; i < nv; ++i) {
    double big = test_rng_uniform(rng, 0.0, 1.0) < 0.03 ? 4.0 : 0.2;
    for (int d = 0; d < 3; ++d)
      v2[3 * i + d] = c.v[3 * i + d] + test_rng_uniform(rng, -1.0, 1.0) * big * c.h / c.dt;
    dirty[i] = test_rng_uniform(rng, 0.0, 1.0) < 0.2;
  }
  assert_int_equal(piola__detect(s, c.x, v2, c.dt, PIOLA__DETECT_CCD, NULL, &tree_built), 0);
  tot->escaped_runs += count_escaped(s) > 0;
  assert_int_equal(piola__detect_all_pairs(s, c.x, v2, c.dt, PIOLA__DETECT_CCD, &ref), 0);
  assert_same_pairs(s, &ref, NULL, "collisions after a few velocities changed much");

  /* A later pass: only pairs with a dirty vertex. */
  assert_int_equal(piola__detect(s, c.x, v2, c.dt, PIOLA__DETECT_CCD, dirty, &tree_built), 0);
  assert_same_pairs(s, &ref, dirty, "collisions of pairs with a dirty vertex");
  for (int64_t i = 0; i < s->found.count; ++i) tot->dirty_collisions += 1;

  /* Most velocities change much: the candidates are collected again. */
  for (int32_t i = 0; i < 3 * nv; ++i)
    v2[i] = -0.5 * v2[i] + test_rng_uniform(rng, -3.0, 3.0) * c.h / c.dt;
  assert_int_equal(piola__detect(s, c.x, v2, c.dt, PIOLA__DETECT_CCD, NULL, &tree_built), 0);
  /* Escaped vertices are counted against the reach boxes of the last collection: none left
   * means the candidates were collected again from these velocities. */
  tot->recollect_runs += count_escaped(s) == 0;
  assert_int_equal(piola__detect_all_pairs(s, c.x, v2, c.dt, PIOLA__DETECT_CCD, &ref), 0);
  assert_same_pairs(s, &ref, NULL, "collisions after most velocities changed much");

  free(ref.items), free(v2), free(dirty);
  piola_collision_surface_destroy(s);
  config_free(&c);
}

static void detection_matches_all_pairs(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(20261122);
  totals tot = {0};
  const long samples = test_samples(60, 6);
  for (long i = 0; i < samples; ++i) check_config(&rng, &tot);
  /* The configurations exercise every path. */
  assert_true(tot.contacts > 0);
  assert_true(tot.collisions > 0);
  assert_true(tot.dirty_collisions > 0);
  assert_true(tot.escaped_runs > 0);
  assert_true(tot.recollect_runs > 0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(detection_matches_all_pairs),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
