/* Collision processing of whole surfaces (BFA02): after every step of randomized stress
 * scenes no two triangles without a shared vertex intersect (checked with the exact referee
 * over all pairs), momentum is conserved, friction behaves, pinned vertices stay put, and
 * results do not depend on the thread count. */
#include "test_support.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/union_find.h"
#include "contact/contact_internal.h"
#include "contact/triangle_intersection.h"
#include "piola/collision_surface.h"
#include "piola/threads.h"

typedef struct scene {
  int32_t nv, nt, vcap, tcap;
  double *x, *v, *m;
  int32_t *tris, *body;
} scene;

static void scene_free(scene *s) {
  free(s->x), free(s->v), free(s->m), free(s->tris), free(s->body);
  memset(s, 0, sizeof(*s));
}

static int32_t add_vertex(scene *s, double x, double y, double z, int32_t body) {
  if (s->nv == s->vcap) {
    s->vcap = s->vcap ? 2 * s->vcap : 256;
    s->x = realloc(s->x, sizeof(double) * 3 * (size_t)s->vcap);
    s->v = realloc(s->v, sizeof(double) * 3 * (size_t)s->vcap);
    s->m = realloc(s->m, sizeof(double) * (size_t)s->vcap);
    s->body = realloc(s->body, sizeof(int32_t) * (size_t)s->vcap);
    assert_non_null(s->x), assert_non_null(s->v), assert_non_null(s->m), assert_non_null(s->body);
  }
  int32_t i = s->nv++;
  s->x[3 * i] = x, s->x[3 * i + 1] = y, s->x[3 * i + 2] = z;
  s->v[3 * i] = s->v[3 * i + 1] = s->v[3 * i + 2] = 0.0;
  s->m[i] = 1e-3;
  s->body[i] = body;
  return i;
}

static void add_triangle(scene *s, int32_t a, int32_t b, int32_t c) {
  if (s->nt == s->tcap) {
    s->tcap = s->tcap ? 2 * s->tcap : 512;
    s->tris = realloc(s->tris, sizeof(int32_t) * 3 * (size_t)s->tcap);
    assert_non_null(s->tris);
  }
  s->tris[3 * s->nt] = a, s->tris[3 * s->nt + 1] = b, s->tris[3 * s->nt + 2] = c;
  ++s->nt;
}

/* An nx by ny vertex grid; position(i, j) decides where each vertex goes. Returns the first
 * vertex index. */
typedef void (*grid_position)(int i, int j, double out[3], const void *ctx);

static int32_t add_grid(scene *s, int nx, int ny, grid_position pos, const void *ctx,
                        int32_t body) {
  int32_t first = s->nv;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      double p[3];
      pos(i, j, p, ctx);
      add_vertex(s, p[0], p[1], p[2], body);
    }
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      int32_t a = first + j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      if ((i + j) % 2)
        add_triangle(s, a, b, d), add_triangle(s, a, d, c);
      else
        add_triangle(s, a, b, c), add_triangle(s, b, d, c);
    }
  return first;
}

typedef struct flat_sheet {
  double spacing, x0, y0, z;
} flat_sheet;

static void flat_position(int i, int j, double out[3], const void *ctx) {
  const flat_sheet *f = ctx;
  out[0] = f->x0 + i * f->spacing, out[1] = f->y0 + j * f->spacing, out[2] = f->z;
}

/* Triangle pairs without a shared vertex that intersect, by the exact referee; -1 pairs
 * (both degenerate) are counted in *undecided. */
static long count_intersections(const scene *s, const double *x, long *undecided) {
  const int32_t nt = s->nt;
  double *lo = malloc(sizeof(double) * 3 * (size_t)nt),
         *hi = malloc(sizeof(double) * 3 * (size_t)nt);
  assert_non_null(lo), assert_non_null(hi);
  for (int32_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      double a = x[3 * s->tris[3 * t] + k], b = x[3 * s->tris[3 * t + 1] + k],
             c = x[3 * s->tris[3 * t + 2] + k];
      lo[3 * t + k] = fmin(a, fmin(b, c)), hi[3 * t + k] = fmax(a, fmax(b, c));
    }
  long hits = 0, open = 0;
  for (int32_t a = 0; a < nt; ++a)
    for (int32_t b = a + 1; b < nt; ++b) {
      int apart = 0;
      for (int k = 0; k < 3; ++k)
        apart |= hi[3 * a + k] < lo[3 * b + k] || hi[3 * b + k] < lo[3 * a + k];
      if (apart) continue;
      const int32_t *ta = s->tris + 3 * a, *tb = s->tris + 3 * b;
      int shared = 0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) shared |= ta[i] == tb[j];
      if (shared) continue;
      const double *p[3] = {x + 3 * ta[0], x + 3 * ta[1], x + 3 * ta[2]};
      const double *q[3] = {x + 3 * tb[0], x + 3 * tb[1], x + 3 * tb[2]};
      int r = piola__triangles_intersect(p, q);
      if (r == 1) ++hits;
      if (r < 0) ++open;
    }
  free(lo), free(hi);
  if (undecided) *undecided = open;
  return hits;
}

static piola_collision_surface *make_surface(const scene *s, int bodies, double thickness,
                                             double friction) {
  piola_collision_body_def defs[4];
  for (int b = 0; b < bodies; ++b) {
    defs[b] = piola_default_collision_body_def();
    defs[b].thickness = thickness, defs[b].friction = friction;
  }
  piola_collision_surface_def def = piola_default_collision_surface_def();
  def.vertex_count = s->nv, def.triangle_count = s->nt, def.triangles = s->tris;
  def.body_count = bodies, def.bodies = defs, def.vertex_body = s->body;
  piola_collision_surface *surface = NULL;
  assert_int_equal(piola_collision_surface_create(&def, &surface), PIOLA_OK);
  return surface;
}

typedef void (*velocity_rule)(scene *s, int step, test_rng *rng, const void *ctx);

typedef struct run_totals {
  int64_t contacts, impacts, zones;
  int steps_with_zones;
} run_totals;

/* Runs `steps` steps: velocities from the rule, collision processing, x += dt v; after each
 * step the exact referee must find no intersecting pair. */
static run_totals run_scene(scene *s, piola_collision_surface *surface, int steps, double dt,
                            velocity_rule rule, const void *ctx, uint64_t seed,
                            const piola_collision_settings *settings) {
  test_rng rng = test_rng_seeded(seed);
  run_totals totals = {0};
  long undecided = 0;
  assert_int_equal(count_intersections(s, s->x, &undecided), 0);
  for (int step = 0; step < steps; ++step) {
    rule(s, step, &rng, ctx);
    piola_collision_stats st;
    assert_int_equal(piola_collision_surface_process(surface, s->x, s->v, s->m, dt, settings, &st),
                     PIOLA_OK);
    assert_int_equal(st.resolved, 1);
    for (int32_t i = 0; i < 3 * s->nv; ++i) s->x[i] += dt * s->v[i];
    long bad = count_intersections(s, s->x, &undecided);
    if (bad) fail_msg("step %d: %ld intersecting triangle pairs", step, bad);
    assert_int_equal(undecided, 0);
    if (getenv("PIOLA_CONTACT_TRACE"))
      print_message(
          "step %d: contacts %lld impacts %lld passes %d zones %d (%d vertices) zone passes %d\n",
          step, (long long)st.contacts, (long long)st.impacts, st.collision_passes, st.impact_zones,
          st.zone_vertices, st.zone_passes);
    totals.contacts += st.contacts, totals.impacts += st.impacts, totals.zones += st.impact_zones;
    totals.steps_with_zones += st.impact_zones > 0;
  }
  return totals;
}

/* ---------------------------------------------------------------- two sheets */

typedef struct sheets_ctx {
  int32_t split; /* vertices below this are the lower sheet */
  double speed, jitter;
} sheets_ctx;

static void sheets_velocity(scene *s, int step, test_rng *rng, const void *ctx) {
  (void)step;
  const sheets_ctx *c = ctx;
  for (int32_t i = 0; i < s->nv; ++i) {
    double dir = i < c->split ? 1.0 : -1.0;
    for (int k = 0; k < 3; ++k) s->v[3 * i + k] = c->jitter * test_rng_uniform(rng, -1, 1);
    s->v[3 * i + 2] += dir * c->speed;
  }
}

static void two_sheets_driven_into_each_other(void **state) {
  (void)state;
  const long runs = test_samples(3, 1);
  for (long r = 0; r < runs; ++r) {
    scene s = {0};
    const int n = 14;
    flat_sheet lower = {0.01, 0, 0, 0}, upper = {0.01, 0.003, 0.004, 0.012};
    add_grid(&s, n, n, flat_position, &lower, 0);
    sheets_ctx ctx = {s.nv, 0.5, 0.1};
    add_grid(&s, n, n, flat_position, &upper, 1);
    piola_collision_surface *surface = make_surface(&s, 2, 0.002, 0.2);
    run_totals t = run_scene(&s, surface, 8, 0.02, sheets_velocity, &ctx, 100 + (uint64_t)r, NULL);
    /* The scene is violent enough to need every stage. */
    assert_true(t.contacts > 0);
    assert_true(t.impacts > 0);
    assert_true(t.zones > 0);
    piola_collision_surface_destroy(surface);
    scene_free(&s);
  }
}

/* ---------------------------------------------------------------- folded cloth */

typedef struct fold_ctx {
  int nx;
  double spacing, gap;
} fold_ctx;

static void fold_position(int i, int j, double out[3], const void *ctx) {
  const fold_ctx *f = ctx;
  int half = f->nx / 2;
  if (i < half) {
    out[0] = i * f->spacing, out[2] = 0.0;
  } else {
    out[0] = (f->nx - 1 - i) * f->spacing + 0.5 * f->spacing, out[2] = f->gap;
  }
  out[1] = j * f->spacing;
}

static void fold_velocity(scene *s, int step, test_rng *rng, const void *ctx) {
  (void)step;
  const fold_ctx *f = ctx;
  for (int32_t i = 0; i < s->nv; ++i) {
    int col = i % f->nx;
    for (int k = 0; k < 3; ++k) s->v[3 * i + k] = 0.2 * test_rng_uniform(rng, -1, 1);
    s->v[3 * i + 2] += col < f->nx / 2 ? 0.4 : -0.8;
  }
}

static void cloth_pushed_through_itself(void **state) {
  (void)state;
  scene s = {0};
  fold_ctx ctx = {24, 0.01, 0.01};
  add_grid(&s, ctx.nx, 12, fold_position, &ctx, 0);
  piola_collision_surface *surface = make_surface(&s, 1, 0.001, 0.0);
  run_totals t =
      run_scene(&s, surface, (int)test_samples(8, 3), 0.02, fold_velocity, &ctx, 5, NULL);
  assert_true(t.impacts > 0);
  piola_collision_surface_destroy(surface);
  scene_free(&s);
}

/* ---------------------------------------------------------------- crumpled sheet */

static void crumple_velocity(scene *s, int step, test_rng *rng, const void *ctx) {
  (void)step, (void)ctx;
  /* A few random plane waves with wavelengths of a few cells. */
  double k[4][3], amp[4][3], phase[4];
  for (int w = 0; w < 4; ++w) {
    for (int c = 0; c < 3; ++c)
      k[w][c] = test_rng_uniform(rng, -150, 150), amp[w][c] = test_rng_uniform(rng, -0.4, 0.4);
    phase[w] = test_rng_uniform(rng, 0, 6.283185307179586);
  }
  for (int32_t i = 0; i < s->nv; ++i) {
    const double *x = s->x + 3 * i;
    for (int c = 0; c < 3; ++c) s->v[3 * i + c] = 0.0;
    for (int w = 0; w < 4; ++w) {
      double a = sin(k[w][0] * x[0] + k[w][1] * x[1] + k[w][2] * x[2] + phase[w]);
      for (int c = 0; c < 3; ++c) s->v[3 * i + c] += amp[w][c] * a;
    }
    /* Pull everything towards the centre so the sheet keeps folding onto itself. */
    s->v[3 * i] += 2.0 * (0.1 - x[0]);
    s->v[3 * i + 1] += 2.0 * (0.1 - x[1]);
  }
}

static void crumpled_sheet(void **state) {
  (void)state;
  scene s = {0};
  flat_sheet sheet = {0.01, 0, 0, 0};
  add_grid(&s, 21, 21, flat_position, &sheet, 0);
  piola_collision_surface *surface = make_surface(&s, 1, 0.001, 0.3);
  run_totals t =
      run_scene(&s, surface, (int)test_samples(20, 4), 0.02, crumple_velocity, NULL, 9, NULL);
  assert_true(t.impacts + t.contacts > 0);
  piola_collision_surface_destroy(surface);
  scene_free(&s);
}

/* Without stage 2 the fail-safe alone must still leave no intersection. */
static void impact_zones_alone_resolve_everything(void **state) {
  (void)state;
  scene s = {0};
  flat_sheet lower = {0.01, 0, 0, 0}, upper = {0.01, 0.004, 0.002, 0.01};
  add_grid(&s, 10, 10, flat_position, &lower, 0);
  sheets_ctx ctx = {s.nv, 0.6, 0.05};
  add_grid(&s, 10, 10, flat_position, &upper, 0);
  piola_collision_surface *surface = make_surface(&s, 1, 0.001, 0.0);
  piola_collision_settings set = piola_default_collision_settings();
  set.repulsion = 0, set.collision_iterations = 0;
  run_totals t = run_scene(&s, surface, 4, 0.02, sheets_velocity, &ctx, 21, &set);
  assert_true(t.zones > 0);
  piola_collision_surface_destroy(surface);
  scene_free(&s);
}

/* ---------------------------------------------------------------- conservation */

static void momenta(const scene *s, const double *v, double lin[3], double ang[3]) {
  for (int k = 0; k < 3; ++k) lin[k] = ang[k] = 0.0;
  for (int32_t i = 0; i < s->nv; ++i) {
    const double *x = s->x + 3 * i, *u = v + 3 * i, m = s->m[i];
    for (int k = 0; k < 3; ++k) lin[k] += m * u[k];
    ang[0] += m * (x[1] * u[2] - x[2] * u[1]);
    ang[1] += m * (x[2] * u[0] - x[0] * u[2]);
    ang[2] += m * (x[0] * u[1] - x[1] * u[0]);
  }
}

static void impact_zones_conserve_momentum(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(77);
  scene s = {0};
  flat_sheet sheet = {0.01, 0.3, -0.2, 0.5};
  add_grid(&s, 12, 12, flat_position, &sheet, 0);
  piola_collision_surface *surface = make_surface(&s, 1, 0.001, 0.0);
  const long trials = test_samples(50, 5);
  for (long trial = 0; trial < trials; ++trial) {
    for (int32_t i = 0; i < s.nv; ++i) {
      s.m[i] = test_rng_uniform(&rng, 0.5e-3, 2e-3);
      surface->inverse_mass[i] = 1.0 / s.m[i];
      surface->zone_parent[i] = i, surface->in_zone[i] = 0;
      for (int k = 0; k < 3; ++k) {
        s.x[3 * i + k] += 1e-3 * test_rng_uniform(&rng, -1, 1);
        s.v[3 * i + k] = test_rng_uniform(&rng, -2, 2);
      }
    }
    /* A handful of random "collisions" chaining random vertices into zones. */
    piola__contact_list hits = {0};
    int count = 1 + (int)(test_rng_next(&rng) % 20);
    for (int c = 0; c < count; ++c) {
      piola__contact h = {0};
      for (int k = 0; k < 4; ++k) h.v[k] = (int32_t)(test_rng_next(&rng) % (uint64_t)s.nv);
      assert_int_equal(piola__contact_list_push(&hits, &h), 0);
    }
    double lin0[3], ang0[3], lin1[3], ang1[3];
    momenta(&s, s.v, lin0, ang0);
    int32_t members = 0;
    int32_t zones = piola__impact_zones_apply(surface, &hits, s.x, s.v, &members);
    assert_true(zones >= 1);
    assert_true(members >= 2);
    momenta(&s, s.v, lin1, ang1);
    for (int k = 0; k < 3; ++k) {
      assert_close(lin1[k], lin0[k], 1e-14);
      assert_close(ang1[k], ang0[k], 1e-14);
    }
    /* And each zone now moves rigidly: pairwise distances inside it do not change to first
     * order, (x_i - x_j) . (v_i - v_j) = 0. */
    for (int32_t i = 0; i < s.nv; ++i)
      for (int32_t j = i + 1; j < s.nv; ++j) {
        if (!surface->in_zone[i] || !surface->in_zone[j]) continue;
        if (piola__union_find_root(surface->zone_parent, i) != piola__union_find_root(surface->zone_parent, j))
          continue;
        double dot = 0.0;
        for (int k = 0; k < 3; ++k)
          dot += (s.x[3 * i + k] - s.x[3 * j + k]) * (s.v[3 * i + k] - s.v[3 * j + k]);
        assert_close(dot, 0.0, 1e-13);
      }
    free(hits.items);
  }
  piola_collision_surface_destroy(surface);
  scene_free(&s);
}

static void processing_conserves_linear_momentum(void **state) {
  (void)state;
  scene s = {0};
  flat_sheet lower = {0.01, 0, 0, 0}, upper = {0.01, 0.003, 0.004, 0.008};
  add_grid(&s, 10, 10, flat_position, &lower, 0);
  sheets_ctx ctx = {s.nv, 0.5, 0.1};
  add_grid(&s, 10, 10, flat_position, &upper, 1);
  test_rng rng = test_rng_seeded(4);
  for (int32_t i = 0; i < s.nv; ++i) s.m[i] = test_rng_uniform(&rng, 0.5e-3, 2e-3);
  piola_collision_surface *surface = make_surface(&s, 2, 0.002, 0.5);
  sheets_velocity(&s, 0, &rng, &ctx);
  double lin0[3], ang0[3], lin1[3], ang1[3];
  momenta(&s, s.v, lin0, ang0);
  piola_collision_stats st;
  assert_int_equal(piola_collision_surface_process(surface, s.x, s.v, s.m, 0.02, NULL, &st),
                   PIOLA_OK);
  assert_true(st.contacts + st.impacts > 0);
  momenta(&s, s.v, lin1, ang1);
  for (int k = 0; k < 3; ++k) assert_close(lin1[k], lin0[k], 1e-14);
  piola_collision_surface_destroy(surface);
  scene_free(&s);
}

/* ---------------------------------------------------------------- friction and pinning */

static void repulsion_friction_reduces_tangential_velocity(void **state) {
  (void)state;
  scene s = {0};
  int32_t a = add_vertex(&s, -1, -1, 0, 0), b = add_vertex(&s, 2, -1, 0, 0),
          c = add_vertex(&s, -1, 2, 0, 0);
  add_triangle(&s, a, b, c);
  int32_t p = add_vertex(&s, 0.2, 0.3, 0.0004, 0);
  add_triangle(&s, p, add_vertex(&s, 0.2, 0.3, 0.5, 0), add_vertex(&s, 0.3, 0.3, 0.5, 0));
  s.m[a] = s.m[b] = s.m[c] = INFINITY;
  const double h = 0.001, dt = 0.01, mu = 0.4;
  const double vn = -0.05;
  for (int i = 3; i < 6; ++i) s.v[3 * i + 2] = vn, s.v[3 * i] = 0.3;
  s.v[3 * 3] = 0.3;
  piola_collision_surface *surface = make_surface(&s, 1, h, mu);
  piola_collision_stats st;
  assert_int_equal(piola_collision_surface_process(surface, s.x, s.v, s.m, dt, NULL, &st),
                   PIOLA_OK);
  assert_true(st.contacts >= 1);
  /* Normal: the approach is stopped and replaced by 0.1 d / dt with d = h - 0.0004. */
  double dn = 0.1 * (h - 0.0004) / dt - vn;
  assert_close(s.v[3 * p + 2], 0.1 * (h - 0.0004) / dt, 1e-12);
  /* Tangential: reduced by mu dn (the impulse over the mass), not reversed. */
  assert_close(s.v[3 * p], 0.3 - mu * dn, 1e-12);
  assert_close(s.v[3 * p + 1], 0.0, 1e-12);
  /* The pinned triangle did not move. */
  for (int i = 0; i < 9; ++i) assert_true(s.v[i] == 0.0);
  /* With large friction the tangential motion stops and does not reverse. */
  piola_collision_surface_destroy(surface);
  for (int i = 3; i < 6; ++i) s.v[3 * i + 2] = vn, s.v[3 * i] = 0.3, s.v[3 * i + 1] = 0.0;
  surface = make_surface(&s, 1, h, 100.0);
  assert_int_equal(piola_collision_surface_process(surface, s.x, s.v, s.m, dt, NULL, &st),
                   PIOLA_OK);
  assert_close(s.v[3 * p], 0.0, 1e-12);
  piola_collision_surface_destroy(surface);
  scene_free(&s);
}

static void pinned_sheet_is_not_moved(void **state) {
  (void)state;
  scene s = {0};
  flat_sheet lower = {0.01, 0, 0, 0}, upper = {0.01, 0.003, 0.004, 0.012};
  add_grid(&s, 10, 10, flat_position, &lower, 0);
  int32_t split = s.nv;
  add_grid(&s, 10, 10, flat_position, &upper, 1);
  for (int32_t i = 0; i < split; ++i) s.m[i] = INFINITY;
  sheets_ctx ctx = {split, 0.8, 0.1};
  piola_collision_surface *surface = make_surface(&s, 2, 0.001, 0.3);
  /* The lower sheet is pinned at rest: zero its velocities each step through the rule. */
  test_rng rng = test_rng_seeded(8);
  for (int step = 0; step < 5; ++step) {
    sheets_velocity(&s, step, &rng, &ctx);
    for (int32_t i = 0; i < 3 * split; ++i) s.v[i] = 0.0;
    piola_collision_stats st;
    assert_int_equal(piola_collision_surface_process(surface, s.x, s.v, s.m, 0.02, NULL, &st),
                     PIOLA_OK);
    assert_int_equal(st.resolved, 1);
    for (int32_t i = 0; i < 3 * split; ++i) assert_true(s.v[i] == 0.0);
    for (int32_t i = 0; i < 3 * s.nv; ++i) s.x[i] += 0.02 * s.v[i];
    assert_int_equal(count_intersections(&s, s.x, NULL), 0);
  }
  piola_collision_surface_destroy(surface);
  scene_free(&s);
}

/* ---------------------------------------------------------------- determinism, errors */

static void result_does_not_depend_on_thread_count(void **state) {
  (void)state;
  double *results[2] = {NULL, NULL};
  int32_t nv = 0;
  for (int run = 0; run < 2; ++run) {
    piola_set_thread_count(run == 0 ? 1 : 3);
    scene s = {0};
    flat_sheet lower = {0.01, 0, 0, 0}, upper = {0.01, 0.003, 0.004, 0.012};
    add_grid(&s, 14, 14, flat_position, &lower, 0);
    sheets_ctx ctx = {s.nv, 0.5, 0.1};
    add_grid(&s, 14, 14, flat_position, &upper, 1);
    piola_collision_surface *surface = make_surface(&s, 2, 0.002, 0.2);
    run_scene(&s, surface, 4, 0.02, sheets_velocity, &ctx, 31, NULL);
    results[run] = malloc(sizeof(double) * 3 * (size_t)s.nv);
    memcpy(results[run], s.x, sizeof(double) * 3 * (size_t)s.nv);
    nv = s.nv;
    piola_collision_surface_destroy(surface);
    scene_free(&s);
  }
  piola_set_thread_count(0);
  assert_memory_equal(results[0], results[1], sizeof(double) * 3 * (size_t)nv);
  free(results[0]), free(results[1]);
}

static void bad_input_is_reported(void **state) {
  (void)state;
  int32_t tri[3] = {0, 1, 5};
  piola_collision_body_def body = piola_default_collision_body_def();
  piola_collision_surface_def def = piola_default_collision_surface_def();
  def.vertex_count = 3, def.triangle_count = 1, def.triangles = tri, def.body_count = 1,
  def.bodies = &body;
  piola_collision_surface *s = NULL;
  assert_int_equal(piola_collision_surface_create(&def, &s), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_null(s);
  tri[2] = 2;
  body.thickness = 0.0;
  assert_int_equal(piola_collision_surface_create(&def, &s), PIOLA_ERROR_INVALID_ARGUMENT);
  body.thickness = 1e-3, body.friction = NAN;
  assert_int_equal(piola_collision_surface_create(&def, &s), PIOLA_ERROR_INVALID_ARGUMENT);
  body.friction = 0.1;
  assert_int_equal(piola_collision_surface_create(&def, &s), PIOLA_OK);
  assert_int_equal(piola_collision_surface_edge_count(s), 3);
  double x[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0}, v[9] = {0}, m[3] = {1, 1, 1};
  assert_int_equal(piola_collision_surface_process(s, x, v, m, 0.0, NULL, NULL),
                   PIOLA_ERROR_INVALID_ARGUMENT);
  v[4] = NAN;
  assert_int_equal(piola_collision_surface_process(s, x, v, m, 0.01, NULL, NULL),
                   PIOLA_ERROR_NOT_FINITE);
  v[4] = 0.0, m[1] = -1.0;
  assert_int_equal(piola_collision_surface_process(s, x, v, m, 0.01, NULL, NULL),
                   PIOLA_ERROR_INVALID_ARGUMENT);
  m[1] = 1.0;
  piola_collision_stats st;
  assert_int_equal(piola_collision_surface_process(s, x, v, m, 0.01, NULL, &st), PIOLA_OK);
  assert_int_equal(st.resolved, 1);
  assert_int_equal(st.contacts + st.impacts + st.impact_zones, 0);
  piola_collision_surface_destroy(s);
}

/* A zone with pinned vertices moves with them when they move rigidly, and reports that it
 * could not when they do not. */
static void zones_with_pinned_vertices(void **state) {
  (void)state;
  piola_collision_settings set = piola_default_collision_settings();
  set.repulsion = 0, set.collision_iterations = 0;
  for (int stretch = 0; stretch < 2; ++stretch) {
    scene s = {0};
    int32_t a = add_vertex(&s, -1, -1, 0, 0), b = add_vertex(&s, 2, -1, 0, 0),
            c = add_vertex(&s, -1, 2, 0, 0);
    add_triangle(&s, a, b, c);
    int32_t p = add_vertex(&s, 0.2, 0.3, -0.05, 0);
    add_triangle(&s, p, add_vertex(&s, 0.2, 0.3, -1.0, 0), add_vertex(&s, 0.3, 0.3, -1.0, 0));
    s.m[a] = s.m[b] = s.m[c] = INFINITY;
    /* The pinned triangle sweeps down through the point; with stretch, it also grows. */
    for (int k = 0; k < 3; ++k) {
      int32_t i = k == 0 ? a : (k == 1 ? b : c);
      s.v[3 * i + 2] = -10.0;
      if (stretch) s.v[3 * i] = 20.0 * s.x[3 * i], s.v[3 * i + 1] = 20.0 * s.x[3 * i + 1];
    }
    piola_collision_surface *surface = make_surface(&s, 1, 1e-3, 0.0);
    piola_collision_stats st;
    assert_int_equal(piola_collision_surface_process(surface, s.x, s.v, s.m, 0.01, &set, &st),
                     PIOLA_OK);
    assert_true(st.impact_zones >= 1);
    assert_int_equal(st.resolved, stretch ? 0 : 1);
    /* Pinned vertices keep their velocities either way. */
    assert_true(s.v[3 * a + 2] == -10.0 && s.v[3 * b + 2] == -10.0 && s.v[3 * c + 2] == -10.0);
    if (!stretch) {
      /* The point is carried along with the triangle. */
      assert_close(s.v[3 * p + 2], -10.0, 1e-12);
      for (int32_t i = 0; i < 3 * s.nv; ++i) s.x[i] += 0.01 * s.v[i];
      assert_int_equal(count_intersections(&s, s.x, NULL), 0);
    }
    piola_collision_surface_destroy(surface);
    scene_free(&s);
  }
}

/* Interior nodes of a solid are in the vertex arrays but in no boundary triangle. */
static void vertices_in_no_triangle_take_no_part(void **state) {
  (void)state;
  scene s = {0};
  int32_t a = add_vertex(&s, 0, 0, 0, 0), b = add_vertex(&s, 1, 0, 0, 0),
          c = add_vertex(&s, 0, 1, 0, 0);
  add_triangle(&s, a, b, c);
  int32_t inner = add_vertex(&s, 0.2, 0.2, 1e-4, 0);
  s.v[3 * inner + 2] = -1.0;
  piola_collision_surface *surface = make_surface(&s, 1, 1e-3, 0.3);
  piola_collision_stats st;
  assert_int_equal(piola_collision_surface_process(surface, s.x, s.v, s.m, 0.01, NULL, &st),
                   PIOLA_OK);
  assert_int_equal(st.contacts + st.impacts + st.impact_zones, 0);
  assert_true(s.v[3 * inner + 2] == -1.0);
  piola_collision_surface_destroy(surface);
  scene_free(&s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(two_sheets_driven_into_each_other),
      cmocka_unit_test(cloth_pushed_through_itself),
      cmocka_unit_test(crumpled_sheet),
      cmocka_unit_test(impact_zones_alone_resolve_everything),
      cmocka_unit_test(impact_zones_conserve_momentum),
      cmocka_unit_test(processing_conserves_linear_momentum),
      cmocka_unit_test(repulsion_friction_reduces_tangential_velocity),
      cmocka_unit_test(pinned_sheet_is_not_moved),
      cmocka_unit_test(result_does_not_depend_on_thread_count),
      cmocka_unit_test(bad_input_is_reported),
      cmocka_unit_test(vertices_in_no_triangle_take_no_part),
      cmocka_unit_test(zones_with_pinned_vertices),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
