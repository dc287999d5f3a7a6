/* Collision processing on the boundary surfaces of volumetric solids (real meshes from
 * ../shared/data): two solids driven onto each other, and one solid squeezed flat so that its
 * surface folds onto itself. After every step the exact referee checks all boundary triangle
 * pairs without a shared vertex. Interior nodes are in the vertex arrays but take no part. */
#include "test_support.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "contact/triangle_intersection.h"
#include "piola/collision_surface.h"
#include "piola/mesh.h"
#include "piola/mesh_io.h"
#include "triangle_referee.h"

typedef struct solids {
  int32_t nv, nt;
  double *x, *v, *m;
  int32_t *tris, *body;
} solids;

static void solids_free(solids *s) {
  free(s->x), free(s->v), free(s->m), free(s->tris), free(s->body);
  memset(s, 0, sizeof(*s));
}

/* Appends the solid in `path`, scaled to unit size and moved by `offset`, as body `body`. */
static void add_solid(solids *s, const char *path, const double offset[3], int32_t body) {
  piola_tet_mesh mesh = {0};
  piola_tri_mesh boundary = {0};
  if (piola_tet_mesh_read(path, &mesh) != PIOLA_OK) fail_msg("%s: %s", path, piola_last_error());
  assert_int_equal(piola_tet_mesh_boundary(&mesh, &boundary), PIOLA_OK);
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (int32_t i = 0; i < mesh.vertex_count; ++i)
    for (int k = 0; k < 3; ++k) {
      lo[k] = fmin(lo[k], mesh.positions[3 * i + k]);
      hi[k] = fmax(hi[k], mesh.positions[3 * i + k]);
    }
  double size = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
  int32_t first = s->nv, nv = s->nv + mesh.vertex_count, nt = s->nt + boundary.triangle_count;
  s->x = realloc(s->x, sizeof(double) * 3 * (size_t)nv);
  s->v = realloc(s->v, sizeof(double) * 3 * (size_t)nv);
  s->m = realloc(s->m, sizeof(double) * (size_t)nv);
  s->body = realloc(s->body, sizeof(int32_t) * (size_t)nv);
  s->tris = realloc(s->tris, sizeof(int32_t) * 3 * (size_t)nt);
  assert_non_null(s->x), assert_non_null(s->v), assert_non_null(s->m), assert_non_null(s->body),
      assert_non_null(s->tris);
  for (int32_t i = 0; i < mesh.vertex_count; ++i) {
    for (int k = 0; k < 3; ++k) {
      double centre = 0.5 * (lo[k] + hi[k]);
      s->x[3 * (first + i) + k] = (mesh.positions[3 * i + k] - centre) / size + offset[k];
      s->v[3 * (first + i) + k] = 0.0;
    }
    s->m[first + i] = 1e-3;
    s->body[first + i] = body;
  }
  for (int32_t t = 0; t < 3 * boundary.triangle_count; ++t)
    s->tris[3 * s->nt + t] = first + boundary.triangles[t];
  s->nv = nv, s->nt = nt;
  piola_tet_mesh_free(&mesh);
  piola_tri_mesh_free(&boundary);
}

static long count_intersections(const solids *s) {
  return referee_count_intersections_every_pair((judged){s->x, s->tris, s->nt});
}

static piola_collision_surface *make_surface(const solids *s, int bodies) {
  piola_collision_body_def defs[2];
  for (int b = 0; b < bodies; ++b) {
    defs[b] = piola_default_collision_body_def();
    defs[b].thickness = 0.01, defs[b].friction = 0.4;
  }
  piola_collision_surface_def def = piola_default_collision_surface_def();
  def.vertex_count = s->nv, def.triangle_count = s->nt, def.triangles = s->tris;
  def.body_count = bodies, def.bodies = defs, def.vertex_body = s->body;
  piola_collision_surface *surface = NULL;
  assert_int_equal(piola_collision_surface_create(&def, &surface), PIOLA_OK);
  return surface;
}

static void step_and_check(solids *s, piola_collision_surface *surface, double dt, int step,
                           int64_t *events) {
  piola_collision_stats st;
  assert_int_equal(piola_collision_surface_process(surface, s->x, s->v, s->m, dt, NULL, &st),
                   PIOLA_OK);
  assert_int_equal(st.resolved, 1);
  *events += st.impacts + st.zone_vertices;
  if (getenv("PIOLA_CONTACT_TRACE"))
    print_message("step %d: contacts %lld impacts %lld zones %d (%d vertices)\n", step,
                  (long long)st.contacts, (long long)st.impacts, st.impact_zones, st.zone_vertices);
  for (int32_t i = 0; i < 3 * s->nv; ++i) s->x[i] += dt * s->v[i];
  long bad = count_intersections(s);
  if (bad) fail_msg("step %d: %ld intersecting boundary triangle pairs", step, bad);
}

static void two_solids_driven_onto_each_other(void **state) {
  (void)state;
  solids s = {0};
  const double below[3] = {0, 0, 0}, above[3] = {0.1, 0.05, 0.75};
  add_solid(&s, test_data_path("medit/unit_ball.mesh"), below, 0);
  const int32_t split = s.nv;
  add_solid(&s, test_data_path("gmsh/torus.msh"), above, 1);
  piola_collision_surface *surface = make_surface(&s, 2);
  assert_int_equal(count_intersections(&s), 0);
  test_rng rng = test_rng_seeded(12);
  const double dt = 0.01;
  int64_t events = 0;
  const int steps = (int)test_samples(16, 8);
  for (int step = 0; step < steps; ++step) {
    for (int32_t i = 0; i < s.nv; ++i) {
      const double *x = s.x + 3 * i;
      double *v = s.v + 3 * i;
      for (int k = 0; k < 3; ++k) v[k] = 0.3 * test_rng_uniform(&rng, -1, 1);
      if (i >= split) {
        /* Falling and spinning about a tilted axis through (0.1, 0.05, z). */
        v[2] -= 6.0;
        v[0] += 2.0 * (x[2] - 0.75), v[2] -= 2.0 * (x[0] - 0.1);
      } else {
        v[2] += 2.0;
      }
    }
    step_and_check(&s, surface, dt, step, &events);
  }
  assert_true(events > 0);
  piola_collision_surface_destroy(surface);
  solids_free(&s);
}

static void squeezed_solid_folds_onto_itself(void **state) {
  (void)state;
  solids s = {0};
  const double centre[3] = {0, 0, 0};
  add_solid(&s, test_data_path("medit/octopus-low.mesh"), centre, 0);
  piola_collision_surface *surface = make_surface(&s, 1);
  assert_int_equal(count_intersections(&s), 0);
  test_rng rng = test_rng_seeded(13);
  const double dt = 0.01;
  int64_t events = 0;
  const int steps = (int)test_samples(20, 9); /* the first impacts come in the 7th step */
  for (int step = 0; step < steps; ++step) {
    for (int32_t i = 0; i < s.nv; ++i) {
      const double *x = s.x + 3 * i;
      double *v = s.v + 3 * i;
      /* Flatten along z (the height shrinks by 30% a step, far below the thickness by the
       * end); bulge sideways. */
      v[0] = 3.0 * x[0] + 0.5 * test_rng_uniform(&rng, -1, 1);
      v[1] = 3.0 * x[1] + 0.5 * test_rng_uniform(&rng, -1, 1);
      v[2] = -30.0 * x[2] + 0.5 * test_rng_uniform(&rng, -1, 1);
    }
    step_and_check(&s, surface, dt, step, &events);
  }
  assert_true(events > 0);
  piola_collision_surface_destroy(surface);
  solids_free(&s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(two_solids_driven_onto_each_other),
      cmocka_unit_test(squeezed_solid_folds_onto_itself),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
