/* Fracture by the virtual node algorithm (src/sim/fracture*.c, docs/fracture.md): the
 * polygons of one cut tet against the analytic corner volume; a box cut by a slanted plane
 * through its tets splits into two fragments whose closed surfaces enclose the analytic
 * volumes, with the body's mass; momentum across a cut in free flight; random planes through
 * generated and real meshes (no NaN, fractions in (0, 1] summing to 1 per tet, closed
 * consistently oriented fragment surfaces enclosing exactly their material); a cut body
 * collapsed to a point recovers. */
#include "test_support.h"
#include "block_scenes.h"
#include "fracture_checks.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "piola/elastic_body.h"
#include "piola/mesh.h"
#include "piola/mesh_io.h"
#include "piola/plasticity.h"
#include "piola/work_split.h"
#include "piola/world.h"
#include "piola/world_fracture.h"
#include "sim/fracture_internal.h"

/* Every invariant of a cut solid at rest: fractions, their sum per original tet, masses,
 * finite state, and each fragment's surface closed and enclosing exactly its material.
 * strict: also every edge paired (no T-junctions: a single cut plane). */
static void check_cut_solid(const piola_world *w, int strict) {
  const piola_elastic_body *b = piola_world_solid_body(w, 0);
  const int32_t nt = piola_elastic_body_tet_count(b);
  const double *f = piola_world_solid_material_fractions(w, 0);
  const int32_t *parent = piola_world_solid_parent_tets(w, 0);
  assert_non_null(f);
  int32_t original = 0;
  for (int32_t t = 0; t < nt; ++t) original = parent[t] + 1 > original ? parent[t] + 1 : original;
  double *sum = calloc((size_t)original, sizeof(double));
  for (int32_t t = 0; t < nt; ++t) {
    if (!(f[t] > 0 && f[t] <= 1)) fail_msg("tet %d has material fraction %g", (int)t, f[t]);
    sum[parent[t]] += f[t];
  }
  for (int32_t t = 0; t < original; ++t) assert_close(sum[t], 1.0, 1e-12);
  free(sum);
  const double *x = piola_world_solid_positions(w, 0);
  for (int32_t i = 0; i < 3 * piola_elastic_body_vertex_count(b); ++i) assert_true(isfinite(x[i]));
  piola_fracture_surface s;
  assert_int_equal(piola_world_solid_fracture_surface(w, 0, &s), PIOLA_OK);
  double *material = fracture_material_volumes(w);
  for (int32_t g = 0; g < s.fragment_count; ++g) {
    double enclosed = fracture_enclosed_volume(&s, s.fragment_start[g], s.fragment_start[g + 1]);
    if (!(fabs(enclosed - material[g]) <= 1e-9 * (fabs(material[g]) + 1e-12)))
      fail_msg("fragment %d encloses %.12g m^3, holds %.12g m^3", (int)g, enclosed, material[g]);
    if (strict) {
      int32_t open = fracture_unpaired_edges(&s, s.fragment_start[g], s.fragment_start[g + 1]);
      if (open) fail_msg("fragment %d: %d edges without their opposite", (int)g, (int)open);
    }
  }
  free(material);
  piola_fracture_surface_free(&s);
}

static void check_cut_solid_positions_finite(const piola_world *w) {
  const piola_elastic_body *b = piola_world_solid_body(w, 0);
  const double *x = piola_world_solid_positions(w, 0), *f = piola_world_solid_material_fractions(w, 0);
  for (int32_t i = 0; i < 3 * piola_elastic_body_vertex_count(b); ++i) assert_true(isfinite(x[i]));
  for (int32_t t = 0; t < piola_elastic_body_tet_count(b); ++t) assert_true(f[t] > 0 && f[t] <= 1);
}

/* One tet cut with one corner alone: its side is the corner tet of edge ratios t_k, the
 * analytic volume prod t_k; both sides' fractions sum to 1 and their surfaces close. */
static void one_tet_matches_the_corner_volume(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(7);
  const int32_t ids[4] = {10, 3, 7, 5};
  for (int trial = 0; trial < 200; ++trial) {
    double d[4];
    int alone = (int)(test_rng_next(&rng) % 4);
    for (int k = 0; k < 4; ++k) d[k] = k == alone ? test_rng_uniform(&rng, 0.01, 1) : -test_rng_uniform(&rng, 0.01, 1);
    copy_polygons plus, minus;
    piola__fracture_copy_polygons(d, 1, ids, &plus);
    piola__fracture_copy_polygons(d, -1, ids, &minus);
    double expected = 1;
    for (int k = 0; k < 4; ++k)
      if (k != alone) expected *= d[alone] / (d[alone] - d[k]);
    assert_close(plus.fraction, expected, 1e-14);
    assert_close(plus.fraction + minus.fraction, 1.0, 1e-14);
    assert_int_equal(plus.crack_size, 3);
    /* a 2-2 split: a quadrilateral crack */
    for (int k = 0; k < 4; ++k) d[k] = (k < 2 ? 1 : -1) * test_rng_uniform(&rng, 0.01, 1);
    piola__fracture_copy_polygons(d, 1, ids, &plus);
    piola__fracture_copy_polygons(d, -1, ids, &minus);
    assert_int_equal(plus.crack_size, 4);
    assert_int_equal(minus.crack_size, 4);
    assert_true(plus.fraction > 0 && minus.fraction > 0);
    assert_close(plus.fraction + minus.fraction, 1.0, 1e-14);
  }
}

/* The unit box of 5 x 5 x 5 cubes cut by the plane through (0.4, 0.5, 0.5) with normal
 * (1, 0.2, 0.1): it crosses tets, not faces, stays within x in [0.25, 0.55] on the box, so
 * the side x < plane holds exactly 0.4 m^3. */
static void box_splits_into_the_analytic_volumes(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(5, 5, 5, (piola_vec3){0.2, 0.2, 0.2}, &mesh), PIOLA_OK);
  piola_world *w = weightless_world(1e-3);
  fracture_add_solid(w, &mesh, 0);
  const double mass = fracture_total_mass(w);
  assert_int_equal(piola_world_solid_fragment_count(w, 0), 1);
  piola_fracture_cut cut = {.time = 0, .point = {0.4, 0.5, 0.5}, .normal = {1, 0.2, 0.1}};
  fracture_set_cuts(w, &cut, 1); /* due at t = 0 */
  assert_int_equal(piola_world_solid_fragment_count(w, 0), 2);
  assert_true(piola_world_solid_cut_tet_count(w, 0) > 0);
  assert_close(fracture_total_mass(w), mass, 1e-13 * mass);
  check_cut_solid(w, 1);
  piola_fracture_surface s;
  assert_int_equal(piola_world_solid_fracture_surface(w, 0, &s), PIOLA_OK);
  assert_int_equal(s.fragment_count, 2);
  double volume[2] = {fracture_enclosed_volume(&s, s.fragment_start[0], s.fragment_start[1]),
                      fracture_enclosed_volume(&s, s.fragment_start[1], s.fragment_start[2])};
  double low = fmin(volume[0], volume[1]), high = fmax(volume[0], volume[1]);
  assert_close(low, 0.4, 0.005 * 0.4);
  assert_close(high, 0.6, 0.005 * 0.6);
  piola_fracture_surface_free(&s);
  /* the pieces move apart: each fragment moves rigidly away from the plane at 0.5 m/s */
  const piola_elastic_body *body = piola_world_solid_body(w, 0);
  const int32_t n = piola_elastic_body_vertex_count(body), nt = piola_elastic_body_tet_count(body);
  const int32_t *frag = piola_world_solid_fragments(w, 0), *tets = piola_elastic_body_tets(body);
  const double nn = sqrt(1 + 0.04 + 0.01);
  double mean[2] = {0, 0};
  const double *x = piola_world_solid_positions(w, 0);
#define PLANE(p) (((p)[0] - 0.4 + 0.2 * ((p)[1] - 0.5) + 0.1 * ((p)[2] - 0.5)) / nn)
  for (int32_t t = 0; t < nt; ++t)
    for (int k = 0; k < 4; ++k) mean[frag[t]] += PLANE(x + 3 * tets[4 * t + k]);
  assert_true(mean[0] * mean[1] < 0); /* one fragment on each side */
  double *v = calloc(3 * (size_t)n, sizeof(double));
  for (int32_t t = 0; t < nt; ++t)
    for (int k = 0; k < 4; ++k)
      for (int c = 0; c < 3; ++c)
        v[3 * tets[4 * t + k] + c] = (mean[frag[t]] > 0 ? 0.5 : -0.5) * (c == 0 ? 1 : c == 1 ? 0.2 : 0.1) / nn;
  assert_int_equal(piola_world_solid_set_state(w, 0, NULL, v), PIOLA_OK);
  assert_int_equal(piola_world_advance_to(w, 0.2, NULL), PIOLA_OK);
  /* the crack opened by 0.2 m: the fragments' surfaces are that far apart across the plane */
  assert_int_equal(piola_world_solid_fracture_surface(w, 0, &s), PIOLA_OK);
  double inner[2] = {INFINITY, INFINITY};
  for (int g = 0; g < 2; ++g)
    for (int32_t i = s.fragment_start[g]; i < s.fragment_start[g + 1]; ++i)
      for (int k = 0; k < 3; ++k)
        inner[g] = fmin(inner[g], fabs(PLANE(s.positions + 3 * s.triangles[3 * i + k])));
#undef PLANE
  assert_close(inner[0], 0.1, 1e-3);
  assert_close(inner[1], 0.1, 1e-3);
  piola_fracture_surface_free(&s);
  free(v);
  free(mesh.positions), free(mesh.tets);
  piola_world_destroy(w);
}

/* A spinning, stretched bar in free flight is cut at t = 0.05 s by two planes: momentum is
 * the same to rounding right after the cut and (undamped, so angular too) after it flies on. */
static void cut_in_free_flight_keeps_momentum(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(6, 2, 2, (piola_vec3){0.05, 0.05, 0.05}, &mesh), PIOLA_OK);
  piola_world *w = fracture_spinning_bar(&mesh, 1.2, 0.05);
  piola_fracture_cut cuts[2] = {{.time = 0.05, .point = {0.17, 0.05, 0.05}, .normal = {1, 0.3, -0.2}},
                                {.time = 0.05, .point = {0.0, 0.05, 0.05}, .normal = {0.1, 1, 0.3}}};
  fracture_set_cuts(w, cuts, 2);
  assert_int_equal(piola_world_advance_to(w, 0.05, NULL), PIOLA_OK);
  assert_int_equal(piola_world_solid_cut_tet_count(w, 0), 0); /* not yet: due at the next step */
  double p0[3], l0[3], p1[3], l1[3];
  solid_momenta(w, p0, l0, NULL);
  const double mass = fracture_total_mass(w);
  assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
  assert_true(piola_world_solid_cut_tet_count(w, 0) > 0);
  assert_true(piola_world_solid_fragment_count(w, 0) >= 2);
  assert_close(fracture_total_mass(w), mass, 1e-13 * mass);
  /* one step on: the cut moved no node, so the step's change is the usual rounding */
  solid_momenta(w, p1, l1, NULL);
  double ls = sqrt(l0[0] * l0[0] + l0[1] * l0[1] + l0[2] * l0[2]);
  double ps = sqrt(p0[0] * p0[0] + p0[1] * p0[1] + p0[2] * p0[2]);
  for (int k = 0; k < 3; ++k) {
    assert_close(p1[k], p0[k], 1e-12 * ps);
    assert_close(l1[k], l0[k], 1e-9 * ls);
  }
  assert_int_equal(piola_world_advance_to(w, 0.2, NULL), PIOLA_OK);
  solid_momenta(w, p1, l1, NULL);
  for (int k = 0; k < 3; ++k) {
    assert_close(p1[k], p0[k], 1e-12 * ps);
    assert_close(l1[k], l0[k], 1e-6 * ls);
  }
  free(mesh.positions), free(mesh.tets);
  piola_world_destroy(w);
}

/* The same spinning, stretched bar with the stress criterion: cracks start and grow while it
 * flies, and every step that cuts keeps the momentum (linear to rounding, angular to the
 * step's usual rounding) and the mass. */
static void grown_cracks_in_free_flight_keep_momentum(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(6, 2, 2, (piola_vec3){0.05, 0.05, 0.05}, &mesh), PIOLA_OK);
  piola_world *w = fracture_spinning_bar(&mesh, 1.3, 0.05);
  piola_fracture_def def = piola_default_fracture_def();
  def.criterion = PIOLA_FRACTURE_STRESS, def.threshold = 3e3;
  assert_int_equal(piola_world_solid_set_fracture(w, 0, &def), PIOLA_OK);
  const double mass = fracture_total_mass(w);
  double p0[3], l0[3];
  solid_momenta(w, p0, l0, NULL);
  const double ls = sqrt(l0[0] * l0[0] + l0[1] * l0[1] + l0[2] * l0[2]);
  const double ps = sqrt(p0[0] * p0[0] + p0[1] * p0[1] + p0[2] * p0[2]);
  int cutting_steps = 0;
  for (int step = 0; step < 100; ++step) {
    const int32_t before = piola_world_solid_cut_tet_count(w, 0);
    double pa[3], la[3], pb[3], lb[3];
    solid_momenta(w, pa, la, NULL);
    assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
    solid_momenta(w, pb, lb, NULL);
    cutting_steps += piola_world_solid_cut_tet_count(w, 0) > before;
    for (int k = 0; k < 3; ++k) {
      assert_close(pb[k], pa[k], 1e-12 * ps);
      assert_close(lb[k], la[k], 1e-9 * ls);
    }
    assert_close(fracture_total_mass(w), mass, 1e-13 * mass);
  }
  assert_true(cutting_steps >= 2); /* a crack started and grew */
  check_cut_solid_positions_finite(w);
  free(mesh.positions), free(mesh.tets);
  piola_world_destroy(w);
}

/* Random planes through a jittered box and real meshes: every invariant holds after one
 * plane and after a second, which cuts again the tets the first one cut that it crosses
 * (strictly closed surfaces both times), and the cut body steps without NaN. */
static void random_cuts_keep_every_invariant_mesh(const piola_tet_mesh *mesh, test_rng *rng, int trials) {
  double lo[3], hi[3];
  fracture_mesh_bounds(mesh, lo, hi);
  for (int trial = 0; trial < trials; ++trial) {
    piola_world *w = weightless_world(1e-3);
    fracture_add_solid(w, mesh, 1);
    const double mass = fracture_total_mass(w);
    for (int plane = 0; plane < 2; ++plane) {
      double point[3], normal[3];
      for (int k = 0; k < 3; ++k)
        point[k] = test_rng_uniform(rng, lo[k], hi[k]), normal[k] = test_rng_normal(rng);
      assert_int_equal(piola_world_solid_cut(w, 0, point, normal, NULL), PIOLA_OK);
      assert_close(fracture_total_mass(w), mass, 1e-12 * mass);
      check_cut_solid(w, 1);
    }
    assert_int_equal(piola_world_advance_to(w, 0.01, NULL), PIOLA_OK);
    const double *x = piola_world_solid_positions(w, 0);
    for (int32_t i = 0; i < 3 * piola_elastic_body_vertex_count(piola_world_solid_body(w, 0)); ++i)
      assert_true(isfinite(x[i]));
    piola_world_destroy(w);
  }
}

static void random_cuts_keep_every_invariant(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(2026);
  const int trials = (int)test_samples(12, 2);
  piola_tet_mesh box;
  assert_int_equal(piola_tet_mesh_box_grid(4, 3, 3, (piola_vec3){0.1, 0.1, 0.1}, &box), PIOLA_OK);
  for (int32_t i = 0; i < box.vertex_count; ++i)
    for (int k = 0; k < 3; ++k) box.positions[3 * i + k] += test_rng_uniform(&rng, -0.02, 0.02);
  random_cuts_keep_every_invariant_mesh(&box, &rng, trials);
  free(box.positions), free(box.tets);
  static const char *const real[] = {"medit/unit_ball.mesh", "gmsh/bar-186.msh"};
  for (int r = 0; r < 2; ++r) {
    piola_tet_mesh mesh;
    assert_int_equal(piola_tet_mesh_read(test_data_path(real[r]), &mesh), PIOLA_OK);
    random_cuts_keep_every_invariant_mesh(&mesh, &rng, (trials + 1) / 2);
    piola_tet_mesh_free(&mesh);
  }
}

/* A sheet of (m - 1)^2 x 2 triangles: the square of half-size `half` around center spanned by
 * the unit vectors u, v, bent along n = u x v by bend (1/m) times the squared distance. */
static piola_tri_mesh sheet(const double center[3], const double u[3], const double v[3], double half,
                            double bend, int m) {
  piola_tri_mesh s = {.vertex_count = m * m, .triangle_count = 2 * (m - 1) * (m - 1)};
  s.positions = malloc(3 * sizeof(double) * (size_t)s.vertex_count);
  s.triangles = malloc(3 * sizeof(int32_t) * (size_t)s.triangle_count);
  assert_non_null(s.positions), assert_non_null(s.triangles);
  const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) {
      const double a = half * (2.0 * i / (m - 1) - 1), b = half * (2.0 * j / (m - 1) - 1);
      for (int k = 0; k < 3; ++k)
        s.positions[3 * (i * m + j) + k] = center[k] + a * u[k] + b * v[k] + bend * (a * a + b * b) * n[k];
    }
  int32_t *t = s.triangles;
  for (int i = 0; i + 1 < m; ++i)
    for (int j = 0; j + 1 < m; ++j) {
      const int32_t c = i * m + j;
      t[0] = c, t[1] = c + m, t[2] = c + m + 1, t[3] = c, t[4] = c + m + 1, t[5] = c + 1;
      t += 6;
    }
  return s;
}

/* A flat blade larger than the box cuts exactly as its plane does (same tets, fractions to
 * rounding); one that reaches only halfway through splits only the tets it passes all the way
 * through, on its side, and leaves one fragment whose closed surface holds the slit. */
static void blade_cuts_like_its_plane_and_only_where_it_reaches(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(5, 5, 5, (piola_vec3){0.2, 0.2, 0.2}, &mesh), PIOLA_OK);
  const double center[3] = {0.4, 0.5, 0.5}, normal[3] = {1, 0.2, 0.1};
  const double nn = sqrt(1.05), n[3] = {1 / nn, 0.2 / nn, 0.1 / nn};
  double u[3] = {-n[1], n[0], 0}, v[3];
  const double un = sqrt(u[0] * u[0] + u[1] * u[1]);
  u[0] /= un, u[1] /= un;
  v[0] = n[1] * u[2] - n[2] * u[1], v[1] = n[2] * u[0] - n[0] * u[2], v[2] = n[0] * u[1] - n[1] * u[0];
  piola_world *plane = weightless_world(1e-3), *blade = weightless_world(1e-3);
  fracture_add_solid(plane, &mesh, 0), fracture_add_solid(blade, &mesh, 0);
  int32_t by_plane = 0, by_blade = 0;
  assert_int_equal(piola_world_solid_cut(plane, 0, center, normal, &by_plane), PIOLA_OK);
  piola_tri_mesh big = sheet(center, u, v, 2.0, 0, 3);
  assert_int_equal(piola_world_solid_cut_by_surface(blade, 0, &big, &by_blade), PIOLA_OK);
  assert_int_equal(by_blade, by_plane);
  assert_int_equal(piola_world_solid_fragment_count(blade, 0), 2);
  const int32_t nt = piola_elastic_body_tet_count(piola_world_solid_body(blade, 0));
  assert_int_equal(nt, piola_elastic_body_tet_count(piola_world_solid_body(plane, 0)));
  for (int32_t t = 0; t < nt; ++t) {
    assert_int_equal(piola_world_solid_parent_tets(blade, 0)[t], piola_world_solid_parent_tets(plane, 0)[t]);
    assert_close(piola_world_solid_material_fractions(blade, 0)[t], piola_world_solid_material_fractions(plane, 0)[t], 1e-12);
  }
  check_cut_solid(blade, 1);
  piola_world_destroy(blade), piola_world_destroy(plane);
  piola_tri_mesh_free(&big);
  /* half a blade: a square of half-size 0.6 centred 0.6 m from the plane's point along u
   * (mostly +y) reaches into the box only for y > ~0.5 */
  blade = weightless_world(1e-3);
  fracture_add_solid(blade, &mesh, 0);
  double c2[3];
  if (u[1] < 0)
    for (int k = 0; k < 3; ++k) u[k] = -u[k], v[k] = -v[k];
  for (int k = 0; k < 3; ++k) c2[k] = center[k] + 0.6 * u[k];
  piola_tri_mesh half = sheet(c2, u, v, 0.6, 0, 4);
  int32_t count = 0;
  assert_int_equal(piola_world_solid_cut_by_surface(blade, 0, &half, &count), PIOLA_OK);
  assert_true(count > 0 && count < by_plane);
  assert_int_equal(piola_world_solid_fragment_count(blade, 0), 1);
  check_cut_solid(blade, 1);
  const piola_elastic_body *b = piola_world_solid_body(blade, 0);
  const double *rest = piola_elastic_body_rest_positions(b), *f = piola_world_solid_material_fractions(blade, 0);
  for (int32_t t = 0; t < piola_elastic_body_tet_count(b); ++t) {
    if (f[t] == 1) continue;
    double lowest = INFINITY; /* every cut tet lies where the blade is: its far corner beyond y ~ 0.5 */
    for (int k = 0; k < 4; ++k) lowest = fmin(lowest, rest[3 * piola_elastic_body_tets(b)[4 * t + k] + 1]);
    assert_true(lowest > 0.2);
  }
  piola_world_destroy(blade);
  piola_tri_mesh_free(&half);
  /* bad blades are refused */
  blade = weightless_world(1e-3);
  fracture_add_solid(blade, &mesh, 0);
  piola_tri_mesh bad = sheet(center, u, v, 1, 0, 2);
  bad.triangles[1] = 7;
  assert_int_equal(piola_world_solid_cut_by_surface(blade, 0, &bad, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  bad.triangles[1] = 1, bad.positions[4] = NAN;
  assert_int_equal(piola_world_solid_cut_by_surface(blade, 0, &bad, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  piola_tri_mesh_free(&bad);
  piola_world_destroy(blade);
  free(mesh.positions), free(mesh.tets);
}

/* Cracks grown by the stress criterion from a random stretch of a random mesh, then a random
 * bent blade: no NaN, fractions in (0, 1] summing to 1 per tet, the mass kept, every fragment's
 * surface closed around exactly its material (strictly, every edge paired, while only grown
 * cracks cut the body: they meet edge to edge), and the body steps on. */
static void grown_and_blade_cuts_keep_every_invariant_mesh(const piola_tet_mesh *mesh, test_rng *rng, int trials,
                                                           int32_t *grown_tets, int32_t *blade_tets) {
  double lo[3], hi[3];
  fracture_mesh_bounds(mesh, lo, hi);
  double size = 0;
  for (int k = 0; k < 3; ++k) size = fmax(size, hi[k] - lo[k]);
  for (int trial = 0; trial < trials; ++trial) {
    piola_world *w = weightless_world(1e-3);
    fracture_add_solid(w, mesh, 1);
    const double mass = fracture_total_mass(w);
    piola_fracture_def def = piola_default_fracture_def();
    def.criterion = PIOLA_FRACTURE_STRESS;
    def.threshold = test_rng_uniform(rng, 500, 3000);
    def.max_tets_per_step = (int32_t)test_rng_uniform(rng, 0, 4);
    assert_int_equal(piola_world_solid_set_fracture(w, 0, &def), PIOLA_OK);
    double stretch[9];
    for (int k = 0; k < 9; ++k) stretch[k] = (k % 4 == 0) + 0.3 * test_rng_normal(rng);
    for (int step = 0; step < 6; ++step) {
      /* stretch the current mesh about the rest box's corner and let the criterion act */
      const piola_elastic_body *b = piola_world_solid_body(w, 0);
      const int32_t n = piola_elastic_body_vertex_count(b);
      const double *rest = piola_elastic_body_rest_positions(b);
      double *x = malloc(3 * sizeof(double) * (size_t)n);
      for (int32_t i = 0; i < n; ++i)
        for (int r = 0; r < 3; ++r) {
          x[3 * i + r] = lo[r];
          for (int c = 0; c < 3; ++c) x[3 * i + r] += stretch[3 * r + c] * (rest[3 * i + c] - lo[c]);
          x[3 * i + r] += 0.01 * size * test_rng_normal(rng);
        }
      assert_int_equal(piola_world_solid_set_state(w, 0, x, NULL), PIOLA_OK);
      free(x);
      assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
    }
    /* the invariants at the rest shape (material volumes are rest volumes) */
    const piola_elastic_body *b = piola_world_solid_body(w, 0);
    assert_int_equal(piola_world_solid_set_state(w, 0, piola_elastic_body_rest_positions(b), NULL), PIOLA_OK);
    assert_close(fracture_total_mass(w), mass, 1e-12 * mass);
    check_cut_solid(w, 1);
    const int32_t grown = piola_world_solid_cut_tet_count(w, 0);
    *grown_tets += grown;
    /* a bent blade through a random point */
    double center[3], u[3], v[3], n[3];
    for (int k = 0; k < 3; ++k) center[k] = test_rng_uniform(rng, lo[k], hi[k]), n[k] = test_rng_normal(rng);
    const double nn = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int k = 0; k < 3; ++k) n[k] /= nn;
    const double a[3] = {fabs(n[0]) < 0.9 ? 1 : 0, fabs(n[0]) < 0.9 ? 0 : 1, 0};
    u[0] = a[1] * n[2] - a[2] * n[1], u[1] = a[2] * n[0] - a[0] * n[2], u[2] = a[0] * n[1] - a[1] * n[0];
    const double un = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int k = 0; k < 3; ++k) u[k] /= un;
    v[0] = n[1] * u[2] - n[2] * u[1], v[1] = n[2] * u[0] - n[0] * u[2], v[2] = n[0] * u[1] - n[1] * u[0];
    piola_tri_mesh blade = sheet(center, u, v, test_rng_uniform(rng, 0.3, 1.0) * size,
                                 test_rng_uniform(rng, -0.5, 0.5) / size, 6);
    int32_t count = 0;
    assert_int_equal(piola_world_solid_cut_by_surface(w, 0, &blade, &count), PIOLA_OK);
    piola_tri_mesh_free(&blade);
    *blade_tets += count;
    print_message("grown: %d tets cut, %d fragments; blade: %d tets\n", (int)grown,
                  (int)piola_world_solid_fragment_count(w, 0), (int)count);
    assert_close(fracture_total_mass(w), mass, 1e-12 * mass);
    check_cut_solid(w, 0); /* T-junctions where the blade meets grown cracks */
    assert_int_equal(piola_world_advance_to(w, piola_world_time(w) + 0.01, NULL), PIOLA_OK);
    check_cut_solid_positions_finite(w);
    piola_world_destroy(w);
  }
}

static void grown_and_blade_cuts_keep_every_invariant(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(1515);
  const int trials = (int)test_samples(10, 2);
  piola_tet_mesh box;
  assert_int_equal(piola_tet_mesh_box_grid(5, 4, 3, (piola_vec3){0.1, 0.1, 0.1}, &box), PIOLA_OK);
  for (int32_t i = 0; i < box.vertex_count; ++i)
    for (int k = 0; k < 3; ++k) box.positions[3 * i + k] += test_rng_uniform(&rng, -0.02, 0.02);
  int32_t grown = 0, bladed = 0;
  grown_and_blade_cuts_keep_every_invariant_mesh(&box, &rng, trials, &grown, &bladed);
  free(box.positions), free(box.tets);
  static const char *const real[] = {"medit/unit_ball.mesh", "gmsh/bar-186.msh"};
  for (int r = 0; r < 2; ++r) {
    piola_tet_mesh mesh;
    assert_int_equal(piola_tet_mesh_read(test_data_path(real[r]), &mesh), PIOLA_OK);
    grown_and_blade_cuts_keep_every_invariant_mesh(&mesh, &rng, (trials + 1) / 2, &grown, &bladed);
    piola_tet_mesh_free(&mesh);
  }
  assert_true(grown > 0 && bladed > 0); /* the cases happened */
}

/* A cut box collapsed to a point: its copies are inverted like any tet, and it recovers. */
static void cut_body_recovers_from_collapse(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(3, 3, 3, (piola_vec3){0.1, 0.1, 0.1}, &mesh), PIOLA_OK);
  piola_world *w = weightless_world(1e-3);
  fracture_add_solid(w, &mesh, 20);
  /* both fragments at least one and a half tets thick (docs/fracture.md: a fragment about
   * one tet thick, mostly virtual, can stay tangled after a collapse to a point) */
  const double point[3] = {0.16, 0.15, 0.15}, normal[3] = {1, 0.1, 0.05};
  assert_int_equal(piola_world_solid_cut(w, 0, point, normal, NULL), PIOLA_OK);
  assert_int_equal(piola_world_solid_fragment_count(w, 0), 2);
  int32_t n = piola_elastic_body_vertex_count(piola_world_solid_body(w, 0));
  double *x = malloc(3 * sizeof(double) * (size_t)n);
  for (int32_t i = 0; i < 3 * n; ++i) x[i] = 0.15;
  assert_int_equal(piola_world_solid_set_state(w, 0, x, NULL), PIOLA_OK);
  assert_true(piola_world_solid_stats(w, 0).min_det_f == 0);
  assert_int_equal(piola_world_advance_to(w, 2.0, NULL), PIOLA_OK);
  piola_solid_stats rec = piola_world_solid_stats(w, 0);
  if (!(rec.inverted_count == 0 && rec.min_det_f > 0.8))
    fail_msg("after collapse to a point: %d inverted, min det F %g", (int)rec.inverted_count, rec.min_det_f);
  free(x), free(mesh.positions), free(mesh.tets);
  piola_world_destroy(w);
}

/* A plastic cube squeezed until it yields, then cut: every copy has its original tet's Fp
 * (bit for bit), and the elastic energy is the same before and after (each copy has its
 * tet's F and Fp, and the fractions of a tet add up to 1). */
static void cut_keeps_plastic_state_and_energy(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(3, 3, 3, (piola_vec3){0.05, 0.05, 0.05}, &mesh), PIOLA_OK);
  piola_world *w = weightless_world(1e-3);
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = &mesh;
  sd.material.youngs_modulus = 1e5;
  sd.shear_viscosity = piola_track_constant(2);
  sd.initial_matrix = (piola_mat3){{{1.25, 0.1, 0}, {0, 1, 0}, {0, 0, 0.8}}};
  piola_plasticity_def plasticity = piola_default_plasticity_def();
  plasticity.yield = 0.02;
  sd.plasticity = &plasticity;
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  for (int s = 0; s < 5; ++s) assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
  double stretch = 0;
  piola_plastic_state_measure(piola_world_solid_plastic_state(w, 0), &stretch, NULL);
  assert_true(stretch > 0.01); /* it yielded */
  const int32_t nt = mesh.tet_count;
  double *fp = malloc(9 * sizeof(double) * (size_t)nt);
  memcpy(fp, piola_plastic_state_fp_inverse(piola_world_solid_plastic_state(w, 0)), 9 * sizeof(double) * (size_t)nt);
  /* refresh the forces and energy for the Fp the step's plastic update left */
  const int32_t n = mesh.vertex_count;
  double *x = malloc(3 * sizeof(double) * (size_t)n);
  memcpy(x, piola_world_solid_positions(w, 0), 3 * sizeof(double) * (size_t)n);
  assert_int_equal(piola_world_solid_set_state(w, 0, x, NULL), PIOLA_OK);
  free(x);
  const double energy = piola_world_solid_stats(w, 0).elastic_energy;
  assert_true(energy > 0);
  const double point[3] = {0.07, 0.08, 0.075}, normal[3] = {1, 0.4, -0.3};
  int32_t count = 0;
  assert_int_equal(piola_world_solid_cut(w, 0, point, normal, &count), PIOLA_OK);
  assert_true(count > 0);
  const piola_plastic_state *plastic = piola_world_solid_plastic_state(w, 0);
  const int32_t *parent = piola_world_solid_parent_tets(w, 0);
  assert_int_equal(piola_plastic_state_tet_count(plastic), nt + count);
  for (int32_t t = 0; t < nt + count; ++t)
    assert_memory_equal(piola_plastic_state_fp_inverse(plastic) + 9 * t, fp + 9 * parent[t], 9 * sizeof(double));
  assert_close(piola_world_solid_stats(w, 0).elastic_energy, energy, 1e-12 * energy);
  free(fp), free(mesh.positions), free(mesh.tets);
  piola_world_destroy(w);
}

/* Adds a solid of mesh (neo-Hookean, E = 100 kPa, nu = 0.3, damping 5 Pa s) whose nodes with
 * x <= fixed_to are fixed and those with x >= pulled_from driven along +x at 0.5 m/s. */
static void add_pulled_solid(piola_world *w, const piola_tet_mesh *mesh, double fixed_to,
                             double pulled_from) {
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = mesh;
  sd.material.youngs_modulus = 1e5;
  sd.material.poisson_ratio = 0.3;
  sd.shear_viscosity = piola_track_constant(5);
  sd.bulk_viscosity = piola_track_constant(5);
  piola_constraint_def ends[2];
  memset(ends, 0, sizeof ends);
  for (int k = 0; k < 2; ++k) {
    ends[k].selector.type = PIOLA_SELECT_BOX;
    ends[k].selector.box_min = (piola_vec3){k ? pulled_from : -1, -1, -1};
    ends[k].selector.box_max = (piola_vec3){k ? 1 : fixed_to, 1, 1};
  }
  ends[1].driven = true;
  ends[1].motion = piola_default_rigid_motion_def();
  ends[1].motion.velocity[0] = piola_track_constant(0.5);
  sd.constraints = ends, sd.constraint_count = 2;
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
}

/* A bar fixed at x = 0 and pulled at its other end at 0.5 m/s: with the stress criterion it
 * breaks once the tension passes the threshold (not before), the pulled end ends in another
 * fragment than the fixed one, and every invariant holds; with a threshold it never reaches
 * it stays whole. */
static int32_t pulled_bar(double threshold, double t_end, double *first_cut_time,
                          piola_world **out) {
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(12, 2, 2, (piola_vec3){0.025, 0.025, 0.025}, &mesh),
                   PIOLA_OK);
  piola_world *w = weightless_world(1e-3);
  add_pulled_solid(w, &mesh, 0.001, 0.299);
  piola_fracture_def def = piola_default_fracture_def();
  def.criterion = PIOLA_FRACTURE_STRESS, def.threshold = threshold;
  assert_int_equal(piola_world_solid_set_fracture(w, 0, &def), PIOLA_OK);
  *first_cut_time = INFINITY;
  while (piola_world_time(w) < t_end) {
    assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
    if (piola_world_solid_cut_tet_count(w, 0) > 0 && !isfinite(*first_cut_time)) *first_cut_time = piola_world_time(w);
  }
  free(mesh.positions), free(mesh.tets);
  *out = w;
  return piola_world_solid_fragment_count(w, 0);
}

static void stress_criterion_breaks_a_pulled_bar(void **state) {
  (void)state;
  piola_world *w;
  double first;
  assert_int_equal(pulled_bar(1e9, 0.2, &first, &w), 1);
  assert_false(isfinite(first));
  piola_world_destroy(w);
  assert_true(pulled_bar(1.5e4, 0.3, &first, &w) >= 2);
  assert_true(first > 0.02 && first < 0.3); /* the tension had to build up */
  /* the pulled end (x = 0.3 + 0.5 t) and the fixed end (x = 0) are in different fragments */
  const piola_elastic_body *b = piola_world_solid_body(w, 0);
  const double *x = piola_world_solid_positions(w, 0);
  const int32_t *tets = piola_elastic_body_tets(b), *frag = piola_world_solid_fragments(w, 0);
  int32_t fixed = -1, pulled = -1;
  for (int32_t t = 0; t < piola_elastic_body_tet_count(b); ++t)
    for (int k = 0; k < 4; ++k) {
      const double px = x[3 * tets[4 * t + k]];
      if (fabs(px) < 1e-9) fixed = frag[t];
      if (fabs(px - (0.3 + 0.5 * piola_world_time(w))) < 1e-6) pulled = frag[t];
    }
  assert_true(fixed >= 0 && pulled >= 0 && fixed != pulled);
  check_cut_solid_positions_finite(w);
  piola_world_destroy(w);
}

/* A crack the stress criterion starts and grows slowly (growth_threshold, max_crack_speed) in
 * Medit's cylinder, scaled to 0.3 m and pulled: while its front has not separated the nodes
 * around it, the two copies of its tets share their nodes. Every edge of every fragment's
 * surface has exactly two triangles after every step that cut: before, the crack's first tet
 * (and later the tets along its front) left its edge on the cylinder's surface with four
 * triangles, each side's boundary piece and crack polygon on the same two vertices. */
static void growing_crack_surfaces_are_manifold(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_read(test_data_path("medit/cylinder.mesh"), &mesh), PIOLA_OK);
  const piola_mat3 scale = {{{3, 0, 0}, {0, 3, 0}, {0, 0, 3}}};
  assert_int_equal(piola_tet_mesh_transform(&mesh, scale, (piola_vec3){0, 0, 0}), PIOLA_OK);
  piola_world *w = weightless_world(1e-3);
  add_pulled_solid(w, &mesh, 0.005, 0.295);
  piola_fracture_def def = piola_default_fracture_def();
  def.criterion = PIOLA_FRACTURE_STRESS, def.threshold = 1.2e4;
  def.growth_threshold = 6e3, def.max_crack_speed = 5;
  assert_int_equal(piola_world_solid_set_fracture(w, 0, &def), PIOLA_OK);
  const double t_end = test_scale() >= 1.0 ? 0.3 : 0.08;
  int32_t cut = 0, checks = 0;
  while (piola_world_time(w) < t_end) {
    assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
    const int32_t now = piola_world_solid_cut_tet_count(w, 0);
    if (now == cut) continue;
    cut = now, ++checks;
    piola_fracture_surface s;
    assert_int_equal(piola_world_solid_fracture_surface(w, 0, &s), PIOLA_OK);
    for (int32_t g = 0; g < s.fragment_count; ++g) {
      const int32_t bad = fracture_unpaired_edges(&s, s.fragment_start[g], s.fragment_start[g + 1]);
      if (bad)
        fail_msg(
            "t = %g s, %d tets cut: fragment %d has %d edges not shared by exactly two triangles",
            piola_world_time(w), (int)now, (int)g, (int)bad);
    }
    piola_fracture_surface_free(&s);
  }
  print_message("%d steps that cut checked, %d tets cut, %d fragments\n", (int)checks, (int)cut,
                (int)piola_world_solid_fragment_count(w, 0));
  assert_true(checks > 0);
  piola_tet_mesh_free(&mesh);
  piola_world_destroy(w);
}

/* Two cuts due at once with max_cuts_per_step 1: the first is applied when the def is set
 * (time 0), the second before the next step; parallel planes, 3 fragments. */
static void max_cuts_per_step_spreads_cuts(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(5, 5, 5, (piola_vec3){0.2, 0.2, 0.2}, &mesh), PIOLA_OK);
  piola_world *w = weightless_world(1e-3);
  fracture_add_solid(w, &mesh, 0);
  piola_fracture_cut cuts[2] = {{.time = 0, .point = {0.33, 0.5, 0.5}, .normal = {1, 0.1, 0}},
                                {.time = 0, .point = {0.67, 0.5, 0.5}, .normal = {1, 0.1, 0}}};
  piola_fracture_def def = piola_default_fracture_def();
  def.cuts = cuts, def.cut_count = 2, def.max_cuts_per_step = 1;
  assert_null(piola_world_split_unsupported(w));
  assert_int_equal(piola_world_solid_set_fracture(w, 0, &def), PIOLA_OK);
  /* a solid with fracture runs split (replicated mode, docs/mpi.md "Fracture") */
  assert_null(piola_world_split_unsupported(w));
  assert_int_equal(piola_world_solid_fragment_count(w, 0), 2);
  const int32_t first = piola_world_solid_cut_tet_count(w, 0);
  assert_true(first > 0);
  assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
  assert_int_equal(piola_world_solid_fragment_count(w, 0), 3);
  assert_true(piola_world_solid_cut_tet_count(w, 0) > first);
  check_cut_solid(w, 0);
  free(mesh.positions), free(mesh.tets);
  piola_world_destroy(w);
}

static void bad_cuts_are_refused(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(2, 2, 2, (piola_vec3){0.1, 0.1, 0.1}, &mesh), PIOLA_OK);
  piola_world *w = weightless_world(1e-3);
  fracture_add_solid(w, &mesh, 0);
  const double point[3] = {0.1, 0.1, 0.1}, zero[3] = {0, 0, 0}, nan_normal[3] = {NAN, 0, 1};
  assert_int_equal(piola_world_solid_cut(w, 0, point, zero, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_int_equal(piola_world_solid_cut(w, 0, point, nan_normal, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_int_equal(piola_world_solid_cut(w, 1, point, point, NULL), PIOLA_ERROR_INVALID_ARGUMENT);
  /* a plane that misses the body cuts nothing and leaves one fragment */
  const double far[3] = {5, 5, 5}, up[3] = {0, 0, 1};
  int32_t count = -1;
  assert_int_equal(piola_world_solid_cut(w, 0, far, up, &count), PIOLA_OK);
  assert_int_equal(count, 0);
  assert_int_equal(piola_world_solid_fragment_count(w, 0), 1);
  free(mesh.positions), free(mesh.tets);
  piola_world_destroy(w);
}

int main(void) {
  piola_set_thread_count(1);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(one_tet_matches_the_corner_volume),
      cmocka_unit_test(box_splits_into_the_analytic_volumes),
      cmocka_unit_test(cut_in_free_flight_keeps_momentum),
      cmocka_unit_test(grown_cracks_in_free_flight_keep_momentum),
      cmocka_unit_test(random_cuts_keep_every_invariant),
      cmocka_unit_test(blade_cuts_like_its_plane_and_only_where_it_reaches),
      cmocka_unit_test(grown_and_blade_cuts_keep_every_invariant),
      cmocka_unit_test(cut_body_recovers_from_collapse),
      cmocka_unit_test(cut_keeps_plastic_state_and_energy),
      cmocka_unit_test(max_cuts_per_step_spreads_cuts),
      cmocka_unit_test(stress_criterion_breaks_a_pulled_bar),
      cmocka_unit_test(growing_crack_surfaces_are_manifold),
      cmocka_unit_test(bad_cuts_are_refused),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
