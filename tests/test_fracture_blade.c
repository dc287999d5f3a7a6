/* Moving blades (src/sim/fracture_blade.c, docs/fracture.md "A moving blade"): a flat blade
 * sliding down through a bar that flies along the blade's plane cuts it step by step; the bar
 * stays one fragment until the blade's edge has passed its far side and is two after the
 * sweep, linear and angular momentum are kept to rounding by every step, the crack grown
 * over many steps cuts the same tets as the blade's plane cut at once, and the two fragments'
 * closed surfaces enclose the analytic volumes of the plane's split. Random blades through
 * random meshes that fly, spin and stretch while they are cut keep every invariant. A run
 * checkpointed in the middle of the sweep resumes bit for bit. Bad motions are refused by the
 * C API and by the scene parser, naming the key path. */
#include "test_support.h"
#include "block_scenes.h"
#include "fracture_checks.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "piola/checkpoint.h"
#include "piola/elastic_body.h"
#include "piola/mesh.h"
#include "piola/mesh_io.h"
#include "piola/world.h"
#include "piola/world_fracture.h"
#include "scene_cases.h"

/* The bar [0, 0.4] x [0, 0.12] x [0, 0.12] (10 x 3 x 3 cubes of 6 tets), flying at 0.2 m/s
 * along the blade's plane x + 0.15 y = 0.219 (so every material point keeps its distance to
 * that plane), no gravity. */
static const double normal[3] = {1, 0.15, 0}, along[3] = {-0.15, 1, 0}, plane_c = 0.219;

static piola_world *flying_bar(piola_tet_mesh *mesh) {
  assert_int_equal(piola_tet_mesh_box_grid(10, 3, 3, (piola_vec3){0.04, 0.04, 0.04}, mesh), PIOLA_OK);
  piola_world_def wd = piola_default_world_def();
  for (int k = 0; k < 3; ++k) wd.gravity[k] = piola_track_constant(0);
  wd.max_dt = 2e-3;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = mesh;
  sd.material.youngs_modulus = 2e4;
  sd.material.poisson_ratio = 0.3;
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  const int32_t n = mesh->vertex_count;
  double *v = malloc(3 * sizeof(double) * (size_t)n);
  assert_non_null(v);
  const double len = sqrt(along[0] * along[0] + along[1] * along[1]);
  for (int32_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) v[3 * i + k] = 0.2 * along[k] / len;
  assert_int_equal(piola_world_solid_set_state(w, 0, mesh->positions, v), PIOLA_OK);
  free(v);
  return w;
}

/* A rectangle in the plane x + 0.15 y = 0.219, normal along +normal, wide in `along` (well
 * past the bar's sides), from z = bottom to z = bottom + 0.4. */
static piola_tri_mesh blade_at(double bottom) {
  piola_tri_mesh s = {.vertex_count = 4, .triangle_count = 2};
  s.positions = malloc(12 * sizeof(double));
  s.triangles = malloc(6 * sizeof(int32_t));
  assert_non_null(s.positions), assert_non_null(s.triangles);
  const double nn = normal[0] * normal[0] + normal[1] * normal[1], len = sqrt(along[0] * along[0] + along[1] * along[1]);
  const double center[2] = {plane_c * normal[0] / nn + 0.06 * along[0] / len, plane_c * normal[1] / nn + 0.06 * along[1] / len};
  const double a[4] = {-0.3, 0.3, 0.3, -0.3}, z[4] = {bottom, bottom, bottom + 0.4, bottom + 0.4};
  for (int i = 0; i < 4; ++i) {
    s.positions[3 * i] = center[0] + a[i] * along[0] / len;
    s.positions[3 * i + 1] = center[1] + a[i] * along[1] / len;
    s.positions[3 * i + 2] = z[i];
  }
  /* counterclockwise seen from +normal: (along, z) is a right-handed pair with normal */
  const int32_t t[6] = {0, 1, 2, 0, 2, 3};
  memcpy(s.triangles, t, sizeof t);
  return s;
}

/* The blade: bottom edge at z = 0.14 (above the bar) at t = 0, moving down at 1 m/s until
 * t = 0.2 s (bottom edge at z = -0.06, below it). */
static piola_fracture_def blade_def(piola_fracture_cut *cut, const piola_tri_mesh *blade) {
  *cut = (piola_fracture_cut){.time = 0, .blade = blade, .end_time = 0.2, .velocity = {0, 0, -1}};
  piola_fracture_def def = piola_default_fracture_def();
  def.cuts = cut, def.cut_count = 1;
  return def;
}

static void blade_cuts_a_flying_bar_step_by_step(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  piola_world *w = flying_bar(&mesh);
  piola_tri_mesh blade = blade_at(0.14);
  piola_fracture_cut cut;
  piola_fracture_def def = blade_def(&cut, &blade);
  assert_int_equal(piola_world_solid_set_fracture(w, 0, &def), PIOLA_OK);
  piola_tri_mesh_free(&blade); /* the def keeps a copy */
  assert_int_equal(piola_world_solid_cut_tet_count(w, 0), 0); /* above the bar at t = 0 */
  double p0[3], l0[3];
  solid_momenta(w, p0, l0, NULL);
  const double ps = sqrt(p0[0] * p0[0] + p0[1] * p0[1] + p0[2] * p0[2]);
  const double ls = sqrt(l0[0] * l0[0] + l0[1] * l0[1] + l0[2] * l0[2]);
  int cutting_steps = 0;
  while (piola_world_time(w) < 0.21) {
    const double start = piola_world_time(w), edge = 0.14 - start; /* the blade's cut is at start */
    const int32_t before = piola_world_solid_cut_tet_count(w, 0);
    double pa[3], la[3], pb[3], lb[3];
    solid_momenta(w, pa, la, NULL);
    assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
    solid_momenta(w, pb, lb, NULL);
    for (int k = 0; k < 3; ++k) {
      assert_close(pb[k], pa[k], 1e-12 * ps);
      assert_close(lb[k], la[k], 1e-11 * ls);
    }
    const int32_t after = piola_world_solid_cut_tet_count(w, 0);
    cutting_steps += after > before;
    if (edge > 1e-9 && piola_world_solid_fragment_count(w, 0) != 1)
      fail_msg("%d fragments at t = %g s with the blade's edge at z = %g, above the bar's bottom",
               (int)piola_world_solid_fragment_count(w, 0), start, edge);
    if (edge > 0.12 + 1e-9) assert_int_equal(after, 0);
    /* nothing is cut ahead of the blade: in every cut copy, the blade's plane crosses its
     * edges above the blade's edge (the bar moves along the plane, z does not change) */
    const piola_elastic_body *b = piola_world_solid_body(w, 0);
    const double *x = piola_world_solid_positions(w, 0), *f = piola_world_solid_material_fractions(w, 0);
    const int32_t *tets = piola_elastic_body_tets(b);
    for (int32_t t = 0; t < piola_elastic_body_tet_count(b); ++t) {
      if (f[t] == 1) continue;
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) {
          const double *p = x + 3 * tets[4 * t + i], *q = x + 3 * tets[4 * t + j];
          const double dp = p[0] * normal[0] + p[1] * normal[1] - plane_c, dq = q[0] * normal[0] + q[1] * normal[1] - plane_c;
          if ((dp > 0) == (dq > 0)) continue;
          const double z = p[2] + (q[2] - p[2]) * dp / (dp - dq);
          if (z < edge - 1e-6)
            fail_msg("tet %d cut at t = %g s: its crack reaches z = %g below the blade's edge %g", (int)t, start, z, edge);
        }
    }
  }
  assert_int_equal(piola_world_solid_fragment_count(w, 0), 2);
  assert_true(cutting_steps >= 10); /* progressively: the bar is 3 tets high, 2 mm per step */
  /* the same tets as the blade's plane cut at once, and the analytic split */
  piola_tet_mesh again;
  piola_world *once = flying_bar(&again);
  const double point[3] = {plane_c, 0, 0};
  int32_t count = 0;
  assert_int_equal(piola_world_solid_cut(once, 0, point, normal, &count), PIOLA_OK);
  assert_int_equal(piola_world_solid_cut_tet_count(w, 0), count);
  piola_fracture_surface s;
  assert_int_equal(piola_world_solid_fracture_surface(w, 0, &s), PIOLA_OK);
  assert_int_equal(s.fragment_count, 2);
  /* the side x + 0.15 y < 0.219: 0.12 * (0.12 * 0.219 - 0.15 * 0.12^2 / 2) m^3 */
  const double behind = 0.12 * (0.12 * plane_c - 0.15 * 0.0072), whole = 0.4 * 0.12 * 0.12;
  double v[2];
  for (int g = 0; g < 2; ++g) {
    v[g] = fracture_enclosed_volume(&s, s.fragment_start[g], s.fragment_start[g + 1]);
    assert_int_equal(fracture_unpaired_edges(&s, s.fragment_start[g], s.fragment_start[g + 1]), 0);
  }
  const double small = fmin(v[0], v[1]), large = fmax(v[0], v[1]);
  assert_true(fabs(small - (whole - behind)) <= 1e-4 * (whole - behind)); /* within the snap */
  assert_true(fabs(large - behind) <= 1e-4 * behind);
  piola_fracture_surface_free(&s);
  piola_world_destroy(once), piola_tet_mesh_free(&again);
  piola_world_destroy(w), piola_tet_mesh_free(&mesh);
}

/* Current volume of tet t of the solid's current mesh (m^3). */
static double current_volume(const piola_world *w, int32_t t) {
  const double *x = piola_world_solid_positions(w, 0);
  const int32_t *c = piola_elastic_body_tets(piola_world_solid_body(w, 0)) + 4 * t;
  double a[3], b[3], d[3];
  for (int k = 0; k < 3; ++k)
    a[k] = x[3 * c[1] + k] - x[3 * c[0] + k], b[k] = x[3 * c[2] + k] - x[3 * c[0] + k], d[k] = x[3 * c[3] + k] - x[3 * c[0] + k];
  return (a[0] * (b[1] * d[2] - b[2] * d[1]) - a[1] * (b[0] * d[2] - b[2] * d[0]) + a[2] * (b[0] * d[1] - b[1] * d[0])) / 6.0;
}

/* Random moving blades through a random mesh that flies, spins and is stretched while it is
 * cut (so it also moves across the blade between cuts): every step keeps the mass and the
 * linear and angular momentum; after the sweep no position is NaN, every fraction is in
 * (0, 1] and those of each original tet add up to 1, and every fragment's surface is closed
 * and consistently oriented and encloses its copies' material (fraction x current volume)
 * within 1e-4 (docs/fracture.md, "A moving blade"). */
static void random_moving_blades_mesh(const piola_tet_mesh *mesh, test_rng *rng, int trials, int32_t *cut_total) {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, mid[3], size = 0;
  for (int32_t i = 0; i < mesh->vertex_count; ++i)
    for (int k = 0; k < 3; ++k)
      lo[k] = fmin(lo[k], mesh->positions[3 * i + k]), hi[k] = fmax(hi[k], mesh->positions[3 * i + k]);
  for (int k = 0; k < 3; ++k) mid[k] = 0.5 * (lo[k] + hi[k]), size = fmax(size, hi[k] - lo[k]);
  for (int trial = 0; trial < trials; ++trial) {
    piola_world_def wd = piola_default_world_def();
    for (int k = 0; k < 3; ++k) wd.gravity[k] = piola_track_constant(0);
    wd.max_dt = 2e-3;
    piola_world *w = NULL;
    assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
    piola_solid_def sd = piola_default_solid_def();
    sd.mesh = mesh;
    sd.material.youngs_modulus = 2e4 * size;
    sd.material.poisson_ratio = 0.3;
    assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
    /* stretched, spinning and flying */
    const int32_t n = mesh->vertex_count;
    double *x = malloc(3 * sizeof(double) * (size_t)n), *v = malloc(3 * sizeof(double) * (size_t)n);
    assert_non_null(x), assert_non_null(v);
    double stretch[3], spin[3], drift[3];
    for (int k = 0; k < 3; ++k)
      stretch[k] = test_rng_uniform(rng, 0.9, 1.2), spin[k] = test_rng_normal(rng) * 0.3 / 0.1,
      drift[k] = test_rng_normal(rng) * 0.1 * size / 0.1;
    for (int32_t i = 0; i < n; ++i) {
      double r[3];
      for (int k = 0; k < 3; ++k) r[k] = mesh->positions[3 * i + k] - mid[k];
      for (int k = 0; k < 3; ++k) x[3 * i + k] = mid[k] + stretch[k] * r[k];
      v[3 * i] = drift[0] + spin[1] * r[2] - spin[2] * r[1];
      v[3 * i + 1] = drift[1] + spin[2] * r[0] - spin[0] * r[2];
      v[3 * i + 2] = drift[2] + spin[0] * r[1] - spin[1] * r[0];
    }
    assert_int_equal(piola_world_solid_set_state(w, 0, x, v), PIOLA_OK);
    free(x), free(v);
    /* a square blade through a random point near the middle, normal nrm, sliding along u
     * (plus a little along nrm) from outside the body through it in 0.1 s */
    double nrm[3], u[3], e[3], nn = 0, un = 0, dot = 0;
    for (int k = 0; k < 3; ++k) nrm[k] = test_rng_normal(rng), u[k] = test_rng_normal(rng), nn += nrm[k] * nrm[k];
    for (int k = 0; k < 3; ++k) nrm[k] /= sqrt(nn), dot += u[k] * nrm[k];
    for (int k = 0; k < 3; ++k) u[k] -= dot * nrm[k], un += u[k] * u[k];
    for (int k = 0; k < 3; ++k) u[k] /= sqrt(un);
    e[0] = nrm[1] * u[2] - nrm[2] * u[1], e[1] = nrm[2] * u[0] - nrm[0] * u[2], e[2] = nrm[0] * u[1] - nrm[1] * u[0];
    const double across = test_rng_uniform(rng, 0, 0.05) * size / 0.1; /* m/s along nrm */
    double center[3];
    for (int k = 0; k < 3; ++k) center[k] = mid[k] + test_rng_uniform(rng, -0.2, 0.2) * size - 1.5 * size * u[k];
    piola_tri_mesh blade = {.vertex_count = 4, .triangle_count = 2};
    blade.positions = malloc(12 * sizeof(double)), blade.triangles = malloc(6 * sizeof(int32_t));
    assert_non_null(blade.positions), assert_non_null(blade.triangles);
    const double a[4] = {-1, 1, 1, -1}, b[4] = {-1, -1, 1, 1};
    for (int i = 0; i < 4; ++i)
      for (int k = 0; k < 3; ++k) blade.positions[3 * i + k] = center[k] + size * (a[i] * u[k] + 1.5 * b[i] * e[k]);
    const int32_t tris[6] = {0, 1, 2, 0, 2, 3};
    memcpy(blade.triangles, tris, sizeof tris);
    piola_fracture_cut cut = {.time = 0, .blade = &blade, .end_time = 0.1,
                              .velocity = {(2 * size * u[0] + across * nrm[0]) / 0.1, (2 * size * u[1] + across * nrm[1]) / 0.1,
                                           (2 * size * u[2] + across * nrm[2]) / 0.1}};
    fracture_set_cuts(w, &cut, 1);
    piola_tri_mesh_free(&blade);
    const double mass = fracture_total_mass(w);
    while (piola_world_time(w) < 0.104) {
      double pa[3], la[3], pb[3], lb[3];
      solid_momenta(w, pa, la, NULL);
      assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
      solid_momenta(w, pb, lb, NULL);
      const double ps = fmax(sqrt(pa[0] * pa[0] + pa[1] * pa[1] + pa[2] * pa[2]), 1e-300);
      const double ls = fmax(sqrt(la[0] * la[0] + la[1] * la[1] + la[2] * la[2]), 1e-300);
      for (int k = 0; k < 3; ++k) {
        assert_close(pb[k], pa[k], 1e-11 * ps);
        assert_close(lb[k], la[k], 1e-9 * ls);
      }
      assert_close(fracture_total_mass(w), mass, 1e-12 * mass);
    }
    *cut_total += piola_world_solid_cut_tet_count(w, 0);
    const piola_elastic_body *body = piola_world_solid_body(w, 0);
    const int32_t nt = piola_elastic_body_tet_count(body), *parent = piola_world_solid_parent_tets(w, 0);
    const int32_t *frag = piola_world_solid_fragments(w, 0);
    const double *f = piola_world_solid_material_fractions(w, 0), *xs = piola_world_solid_positions(w, 0);
    for (int32_t i = 0; i < 3 * piola_elastic_body_vertex_count(body); ++i) assert_true(isfinite(xs[i]));
    double *sum = calloc((size_t)mesh->tet_count, sizeof(double));
    double *material = calloc((size_t)piola_world_solid_fragment_count(w, 0), sizeof(double));
    assert_non_null(sum), assert_non_null(material);
    for (int32_t t = 0; t < nt; ++t) {
      if (!(f[t] > 0 && f[t] <= 1)) fail_msg("tet %d has material fraction %g", (int)t, f[t]);
      sum[parent[t]] += f[t];
      material[frag[t]] += f[t] * current_volume(w, t);
    }
    for (int32_t t = 0; t < mesh->tet_count; ++t) assert_close(sum[t], 1.0, 1e-12);
    piola_fracture_surface s;
    assert_int_equal(piola_world_solid_fracture_surface(w, 0, &s), PIOLA_OK);
    for (int32_t g = 0; g < s.fragment_count; ++g) {
      const int32_t open = fracture_unpaired_edges(&s, s.fragment_start[g], s.fragment_start[g + 1]);
      if (open) fail_msg("trial %d: fragment %d has %d edges without their opposite", trial, (int)g, (int)open);
      const double enclosed = fracture_enclosed_volume(&s, s.fragment_start[g], s.fragment_start[g + 1]);
      /* exact to rounding, but where the body crossed the blade between two cuts the
       * neighbouring copies' crossings can differ and the surface takes one of them */
      if (!(fabs(enclosed - material[g]) <= 1e-4 * fabs(material[g])))
        fail_msg("trial %d: fragment %d encloses %.12g m^3, holds %.12g m^3", trial, (int)g, enclosed, material[g]);
    }
    piola_fracture_surface_free(&s);
    free(sum), free(material);
    piola_world_destroy(w);
  }
}

static void random_moving_blades_keep_every_invariant(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(1515);
  const int trials = (int)test_samples(6, 2);
  int32_t cut_total = 0;
  piola_tet_mesh box;
  assert_int_equal(piola_tet_mesh_box_grid(4, 3, 3, (piola_vec3){0.1, 0.1, 0.1}, &box), PIOLA_OK);
  for (int32_t i = 0; i < box.vertex_count; ++i)
    for (int k = 0; k < 3; ++k) box.positions[3 * i + k] += test_rng_uniform(&rng, -0.02, 0.02);
  random_moving_blades_mesh(&box, &rng, trials, &cut_total);
  piola_tet_mesh_free(&box);
  static const char *const real[] = {"medit/unit_ball.mesh", "gmsh/bar-186.msh"};
  for (int r = 0; r < 2; ++r) {
    piola_tet_mesh mesh;
    assert_int_equal(piola_tet_mesh_read(test_data_path(real[r]), &mesh), PIOLA_OK);
    random_moving_blades_mesh(&mesh, &rng, (trials + 1) / 2, &cut_total);
    piola_tet_mesh_free(&mesh);
  }
  assert_true(cut_total > 0); /* the blades did cut */
}

/* Checkpointed halfway down the bar, a fresh world resumes the sweep bit for bit. */
static void moving_blade_resumes_bit_for_bit(void **state) {
  (void)state;
  piola_tet_mesh mesh, again;
  piola_world *a = flying_bar(&mesh), *b = flying_bar(&again);
  piola_tri_mesh blade = blade_at(0.14);
  piola_fracture_cut cut;
  piola_fracture_def def = blade_def(&cut, &blade);
  assert_int_equal(piola_world_solid_set_fracture(a, 0, &def), PIOLA_OK);
  assert_int_equal(piola_world_solid_set_fracture(b, 0, &def), PIOLA_OK);
  piola_tri_mesh_free(&blade);
  assert_int_equal(piola_world_advance_to(a, 0.09, NULL), PIOLA_OK);
  const int32_t halfway = piola_world_solid_cut_tet_count(a, 0);
  assert_true(halfway > 0);
  assert_int_equal(piola_world_solid_fragment_count(a, 0), 1);
  fracture_checkpoint_round_trip_via_temp_file(a, b, 3);
  fracture_same_state(a, b);
  assert_int_equal(piola_world_advance_to(a, 0.22, NULL), PIOLA_OK);
  assert_int_equal(piola_world_advance_to(b, 0.22, NULL), PIOLA_OK);
  fracture_same_state(a, b);
  assert_true(piola_world_solid_cut_tet_count(b, 0) > halfway);
  assert_int_equal(piola_world_solid_fragment_count(b, 0), 2);
  piola_world_destroy(a), piola_world_destroy(b), piola_tet_mesh_free(&mesh), piola_tet_mesh_free(&again);
}

static void bad_motions_are_refused(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  piola_world *w = flying_bar(&mesh);
  piola_tri_mesh blade = blade_at(0.14);
  piola_fracture_def def = piola_default_fracture_def();
  piola_fracture_cut cut = {.time = 0.1, .point = {0, 0, 0}, .normal = {0, 0, 1}, .end_time = 0.2};
  def.cuts = &cut, def.cut_count = 1;
  assert_int_equal(piola_world_solid_set_fracture(w, 0, &def), PIOLA_ERROR_INVALID_ARGUMENT); /* a plane */
  cut = (piola_fracture_cut){.time = 0.1, .blade = &blade, .velocity = {0, 0, -1}};
  assert_int_equal(piola_world_solid_set_fracture(w, 0, &def), PIOLA_ERROR_INVALID_ARGUMENT); /* no end_time */
  cut.end_time = 0.05; /* before time */
  assert_int_equal(piola_world_solid_set_fracture(w, 0, &def), PIOLA_ERROR_INVALID_ARGUMENT);
  cut.end_time = 0.3, cut.velocity.y = NAN;
  assert_int_equal(piola_world_solid_set_fracture(w, 0, &def), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_false(piola_world_solid_has_fracture(w, 0));
  piola_tri_mesh_free(&blade);
  piola_world_destroy(w), piola_tet_mesh_free(&mesh);
  /* the scene parser names the key path */
#define SOLID(cut) "{\"solids\": [{\"mesh\": {\"generate\": \"box\", \"half_extents\": [0.1, 0.1, 0.1], \"cell_size\": 0.1}, \"fracture\": {\"cuts\": [" cut "]}}]}"
  static const bad_scene_case cases[] = {
      {SOLID("{\"time\": 0.1, \"mesh\": \"b.obj\", \"end_time\": 0.05, \"velocity\": [0, 0, -1]}"),
       "solids[0].fracture.cuts[0].end_time"},
      {SOLID("{\"time\": 0.1, \"mesh\": \"b.obj\", \"end_time\": 0.1, \"velocity\": [0, 0, -1]}"),
       "solids[0].fracture.cuts[0].end_time"},
      {SOLID("{\"time\": 0.1, \"mesh\": \"b.obj\", \"end_time\": -1, \"velocity\": [0, 0, -1]}"),
       "solids[0].fracture.cuts[0].end_time"},
      {SOLID("{\"time\": 0, \"mesh\": \"b.obj\", \"end_time\": \"late\", \"velocity\": [0, 0, -1]}"),
       "solids[0].fracture.cuts[0].end_time"},
      {SOLID("{\"time\": 0, \"mesh\": \"b.obj\", \"end_time\": 1}"), "solids[0].fracture.cuts[0].velocity"},
      {SOLID("{\"time\": 0, \"mesh\": \"b.obj\", \"velocity\": [0, 0, 1]}"), "solids[0].fracture.cuts[0].end_time"},
      {SOLID("{\"time\": 0, \"mesh\": \"b.obj\", \"end_time\": 1, \"velocity\": [0, 1]}"),
       "solids[0].fracture.cuts[0].velocity"},
      {SOLID("{\"time\": 0, \"mesh\": \"b.obj\", \"end_time\": 1, \"velocity\": [0, \"a\", 1]}"),
       "solids[0].fracture.cuts[0].velocity"},
      {SOLID("{\"time\": 0, \"plane\": {\"point\": [0, 0, 0], \"normal\": [0, 0, 1]}, \"end_time\": 1, "
             "\"velocity\": [0, 0, 1]}"),
       "solids[0].fracture.cuts[0].end_time"},
      {SOLID("{\"time\": 0, \"mesh\": \"b.obj\", \"end_time\": 1, \"velocity\": [0, 0, 1], \"speed\": 2}"),
       "solids[0].fracture.cuts[0]"},
  };
#undef SOLID
  assert_bad_scenes_refused(cases, sizeof cases / sizeof cases[0]);
}

int main(void) {
  piola_set_thread_count(1);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(blade_cuts_a_flying_bar_step_by_step),
      cmocka_unit_test(random_moving_blades_keep_every_invariant),
      cmocka_unit_test(moving_blade_resumes_bit_for_bit),
      cmocka_unit_test(bad_motions_are_refused),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
