/* A cloth falling onto itself in folds, with the collision module in the loop of a small
 * mass-spring integrator (symplectic Euler, gravity, stretch and shear springs): the cloth
 * starts upright above a pinned ground sheet, hits it, and piles up in folds. Collision
 * processing runs after every step on the proposed velocities; the exact referee checks all
 * triangle pairs every few steps and at the end. */
#include "test_support.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "contact/triangle_intersection.h"
#include "piola/collision_surface.h"
#include "triangle_referee.h"

typedef struct cloth_scene {
  int32_t nv, nt, ns;
  double *x, *v, *m;
  int32_t *tris, *body, *springs;
  double *rest;
} cloth_scene;

static int32_t grid_vertex(int n, int i, int j) { return j * n + i; }

static void build(cloth_scene *s, int n, double spacing, int ground_n, double ground_spacing) {
  s->nv = n * n + ground_n * ground_n;
  s->nt = 2 * (n - 1) * (n - 1) + 2 * (ground_n - 1) * (ground_n - 1);
  s->x = calloc(3 * (size_t)s->nv, sizeof(double));
  s->v = calloc(3 * (size_t)s->nv, sizeof(double));
  s->m = calloc((size_t)s->nv, sizeof(double));
  s->body = calloc((size_t)s->nv, sizeof(int32_t));
  s->tris = calloc(3 * (size_t)s->nt, sizeof(int32_t));
  s->springs = calloc(2 * 4 * (size_t)n * (size_t)n, sizeof(int32_t));
  s->rest = calloc(4 * (size_t)n * (size_t)n, sizeof(double));
  assert_non_null(s->x), assert_non_null(s->v), assert_non_null(s->m), assert_non_null(s->body);
  assert_non_null(s->tris), assert_non_null(s->springs), assert_non_null(s->rest);
  /* The cloth: upright in the plane y = 0, slightly tilted so it folds to one side. */
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      int32_t a = grid_vertex(n, i, j);
      s->x[3 * a] = (i - 0.5 * (n - 1)) * spacing;
      s->x[3 * a + 1] = 0.15 * j * spacing;
      s->x[3 * a + 2] = 0.01 + j * spacing;
      s->m[a] = 1e-3;
    }
  int32_t t = 0;
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      int32_t a = grid_vertex(n, i, j), b = a + 1, c = a + n, d = c + 1;
      int32_t *T = s->tris + 3 * t;
      T[0] = a, T[1] = b, T[2] = d, T[3] = a, T[4] = d, T[5] = c;
      t += 2;
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      int32_t a = grid_vertex(n, i, j);
      int32_t others[4] = {i + 1 < n ? a + 1 : -1, j + 1 < n ? a + n : -1,
                           i + 1 < n && j + 1 < n ? a + n + 1 : -1,
                           i > 0 && j + 1 < n ? a + n - 1 : -1};
      for (int k = 0; k < 4; ++k) {
        if (others[k] < 0) continue;
        s->springs[2 * s->ns] = a, s->springs[2 * s->ns + 1] = others[k];
        double len = 0.0;
        for (int c = 0; c < 3; ++c) len += pow(s->x[3 * others[k] + c] - s->x[3 * a + c], 2);
        s->rest[s->ns++] = sqrt(len);
      }
    }
  /* The ground: a pinned sheet at z = 0 (body 1). */
  int32_t first = n * n;
  for (int j = 0; j < ground_n; ++j)
    for (int i = 0; i < ground_n; ++i) {
      int32_t a = first + j * ground_n + i;
      s->x[3 * a] = (i - 0.5 * (ground_n - 1)) * ground_spacing;
      s->x[3 * a + 1] = (j - 0.5 * (ground_n - 1)) * ground_spacing;
      s->x[3 * a + 2] = 0.0;
      s->m[a] = INFINITY;
      s->body[a] = 1;
    }
  for (int j = 0; j + 1 < ground_n; ++j)
    for (int i = 0; i + 1 < ground_n; ++i) {
      int32_t a = first + j * ground_n + i, b = a + 1, c = a + ground_n, d = c + 1;
      int32_t *T = s->tris + 3 * t;
      T[0] = a, T[1] = b, T[2] = d, T[3] = a, T[4] = d, T[5] = c;
      t += 2;
    }
  assert_int_equal(t, s->nt);
}

static void cloth_free(cloth_scene *s) {
  free(s->x), free(s->v), free(s->m), free(s->tris), free(s->body), free(s->springs), free(s->rest);
}

static long count_intersections(const cloth_scene *s) {
  return referee_count_intersections_every_pair((judged){s->x, s->tris, s->nt});
}

static void cloth_falls_onto_itself_in_folds(void **state) {
  (void)state;
  cloth_scene s = {0};
  const int n = 16;
  const double spacing = 0.01, dt = 5e-4, k = 40.0, damping = 0.02;
  build(&s, n, spacing, 8, 0.06);
  piola_collision_body_def bodies[2] = {piola_default_collision_body_def(),
                                        piola_default_collision_body_def()};
  bodies[0].thickness = 0.002, bodies[0].friction = 0.3;
  bodies[1].thickness = 0.002, bodies[1].friction = 0.5;
  piola_collision_surface_def def = piola_default_collision_surface_def();
  def.vertex_count = s.nv, def.triangle_count = s.nt, def.triangles = s.tris;
  def.body_count = 2, def.bodies = bodies, def.vertex_body = s.body;
  piola_collision_surface *surface = NULL;
  assert_int_equal(piola_collision_surface_create(&def, &surface), PIOLA_OK);
  assert_int_equal(count_intersections(&s), 0);
  const int cloth_vertices = n * n;
  double *force = calloc(3 * (size_t)cloth_vertices, sizeof(double));
  assert_non_null(force);
  const int steps = (int)test_samples(700, 300);
  int64_t contacts = 0, impacts = 0;
  for (int step = 0; step < steps; ++step) {
    memset(force, 0, sizeof(double) * 3 * (size_t)cloth_vertices);
    for (int32_t i = 0; i < cloth_vertices; ++i) force[3 * i + 2] -= 9.81 * s.m[i];
    for (int32_t e = 0; e < s.ns; ++e) {
      int32_t a = s.springs[2 * e], b = s.springs[2 * e + 1];
      double d[3], len = 0.0;
      for (int c = 0; c < 3; ++c) d[c] = s.x[3 * b + c] - s.x[3 * a + c], len += d[c] * d[c];
      len = sqrt(len);
      double rel = 0.0;
      for (int c = 0; c < 3; ++c) rel += (s.v[3 * b + c] - s.v[3 * a + c]) * d[c] / len;
      double f = k * (len - s.rest[e]) + damping * rel;
      for (int c = 0; c < 3; ++c)
        force[3 * a + c] += f * d[c] / len, force[3 * b + c] -= f * d[c] / len;
    }
    for (int32_t i = 0; i < cloth_vertices; ++i)
      for (int c = 0; c < 3; ++c) s.v[3 * i + c] += dt * force[3 * i + c] / s.m[i];
    piola_collision_stats st;
    assert_int_equal(piola_collision_surface_process(surface, s.x, s.v, s.m, dt, NULL, &st),
                     PIOLA_OK);
    assert_int_equal(st.resolved, 1);
    contacts += st.contacts, impacts += st.impacts;
    for (int32_t i = 0; i < 3 * s.nv; ++i) s.x[i] += dt * s.v[i];
    if (getenv("PIOLA_CONTACT_TRACE") && step % 50 == 0) {
      double lo = 1e300, hi = -1e300, vmax = 0.0;
      for (int32_t i = 0; i < cloth_vertices; ++i) {
        lo = fmin(lo, s.x[3 * i + 2]), hi = fmax(hi, s.x[3 * i + 2]);
        vmax = fmax(vmax, fabs(s.v[3 * i + 2]));
      }
      print_message("step %d: z in [%g, %g], |vz| <= %g, contacts %lld impacts %lld zones %d\n",
                    step, lo, hi, vmax, (long long)st.contacts, (long long)st.impacts,
                    st.impact_zones);
    }
    if (step % 25 == 24 || step == steps - 1) {
      long bad = count_intersections(&s);
      if (bad) fail_msg("step %d: %ld intersecting triangle pairs", step, bad);
    }
  }
  /* The cloth has come down and lies in folds on the ground: its top fell below half the
   * cloth's height, yet stays several thicknesses up, resting on layers of itself. */
  double top = -1e300;
  for (int32_t i = 0; i < cloth_vertices; ++i) top = fmax(top, s.x[3 * i + 2]);
  if (steps >= 700) {
    assert_true(top < 0.5 * n * spacing);
    assert_true(top > 3.0 * bodies[0].thickness);
  }
  assert_true(contacts > 0);
  /* Nothing went through the ground. */
  for (int32_t i = 0; i < cloth_vertices; ++i) assert_true(s.x[3 * i + 2] > 0.0);
  free(force);
  piola_collision_surface_destroy(surface);
  cloth_free(&s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(cloth_falls_onto_itself_in_folds),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
