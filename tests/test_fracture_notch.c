/* Cracks that grow tet by tet (src/sim/fracture.c, docs/fracture.md "Breaking criteria"): a
 * notched bar pulled apart by its driven ends breaks at the notch into two fragments, one
 * per end; with the ductile (plastic strain) criterion its ligament first necks (cross-section
 * down by at least 30%) and it breaks later than the brittle bar. */
#include "test_support.h"
#include "fracture_checks.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "piola/elastic_body.h"
#include "piola/mesh.h"
#include "piola/plasticity.h"
#include "piola/work_split.h"
#include "piola/world.h"
#include "piola/world_fracture.h"
#include "sim/fracture_internal.h"

/* The bar: 16 x 4 x 4 cells of 2 cm along x, minus the cells of the notch: the column of
 * cells x in [0.16, 0.18] above z = 0.04 (half the height). */
#define CELL 0.02
#define LENGTH (16 * CELL)
#define NOTCH_X 0.17
#define PULL 0.25 /* m/s, each end */

static void notched_bar_mesh(piola_tet_mesh *out) {
  piola_tet_mesh box;
  assert_int_equal(piola_tet_mesh_box_grid(16, 4, 4, (piola_vec3){CELL, CELL, CELL}, &box), PIOLA_OK);
  int32_t *keep = malloc(sizeof(int32_t) * (size_t)box.vertex_count);
  int32_t *tets = malloc(4 * sizeof(int32_t) * (size_t)box.tet_count);
  assert_non_null(keep), assert_non_null(tets);
  for (int32_t i = 0; i < box.vertex_count; ++i) keep[i] = -1;
  int32_t nt = 0;
  for (int32_t t = 0; t < box.tet_count; ++t) {
    double c[3] = {0, 0, 0};
    for (int k = 0; k < 4; ++k)
      for (int a = 0; a < 3; ++a) c[a] += 0.25 * box.positions[3 * box.tets[4 * t + k] + a];
    if (fabs(c[0] - NOTCH_X) < 0.5 * CELL && c[2] > 2 * CELL) continue;
    for (int k = 0; k < 4; ++k) keep[box.tets[4 * t + k]] = 1, tets[4 * nt + k] = box.tets[4 * t + k];
    ++nt;
  }
  int32_t nv = 0;
  double *x = malloc(3 * sizeof(double) * (size_t)box.vertex_count);
  assert_non_null(x);
  for (int32_t i = 0; i < box.vertex_count; ++i)
    if (keep[i] > 0) {
      memcpy(x + 3 * nv, box.positions + 3 * i, 3 * sizeof(double));
      keep[i] = nv++;
    }
  for (int32_t i = 0; i < 4 * nt; ++i) tets[i] = keep[tets[i]];
  free(keep), free(box.positions), free(box.tets);
  *out = (piola_tet_mesh){.vertex_count = nv, .positions = x, .tet_count = nt, .tets = tets};
}

typedef struct pull_result {
  int32_t fragments;
  double first_cut;     /* s: the first tet cut, inf if none */
  double broken;        /* s: two fragments, inf if never */
  double section_ratio; /* the notch's cross-section just before the first cut over its rest area */
  int ends_apart;       /* the two driven ends are in different fragments */
  double farthest_cut;  /* m: largest distance of a cut tet's rest centroid from the notch plane */
  int32_t far_cuts;     /* copies of tets cut farther than 1.5 cells from it */
  double reach;         /* m: how far past the notch plane a fragment's material reaches
                           (rest centroids of the left end's fragment right of it and
                           vice versa): the break is at the notch when this is small */
} pull_result;

/* The bar with both ends driven apart at PULL, until t_end or until it breaks. plastic:
 * volume preserving plasticity (yield 0.02, hardening 0.5); criterion and threshold of the
 * fracture def. */
static pull_result pull_notched_bar(int plastic, piola_fracture_criterion criterion, double threshold,
                                    double t_end) {
  piola_tet_mesh mesh;
  notched_bar_mesh(&mesh);
  piola_world_def wd = piola_default_world_def();
  for (int k = 0; k < 3; ++k) wd.gravity[k] = piola_track_constant(0);
  wd.max_dt = 1e-3;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = &mesh;
  sd.material.youngs_modulus = 1e5;
  sd.material.poisson_ratio = 0.3;
  sd.shear_viscosity = piola_track_constant(5);
  sd.bulk_viscosity = piola_track_constant(5);
  piola_plasticity_def plasticity = piola_default_plasticity_def();
  plasticity.yield = 0.02, plasticity.limit = 3, plasticity.volume_preserving = true;
  plasticity.hardening = 0.5; /* spreads the flow over the ligament, so it necks */
  if (plastic) sd.plasticity = &plasticity;
  piola_constraint_def ends[2];
  memset(ends, 0, sizeof ends);
  for (int k = 0; k < 2; ++k) {
    ends[k].selector.type = PIOLA_SELECT_BOX;
    ends[k].selector.box_min = (piola_vec3){k ? LENGTH - 1e-3 : -1e-3, -1, -1};
    ends[k].selector.box_max = (piola_vec3){k ? LENGTH + 1e-3 : 1e-3, 1, 1};
    ends[k].driven = true;
    ends[k].motion = piola_default_rigid_motion_def();
    ends[k].motion.velocity[0] = piola_track_constant(k ? PULL : -PULL);
  }
  sd.constraints = ends, sd.constraint_count = 2;
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  piola_fracture_def def = piola_default_fracture_def();
  def.criterion = criterion, def.threshold = threshold;
  assert_int_equal(piola_world_solid_set_fracture(w, 0, &def), PIOLA_OK);
  pull_result r = {.first_cut = INFINITY, .broken = INFINITY};
  const double rest_section = fracture_rest_section_area(w, NOTCH_X);
  assert_close(rest_section, 2 * CELL * 4 * CELL, 1e-12);
  r.section_ratio = 1;
  while (piola_world_time(w) < t_end && !isfinite(r.broken)) {
    if (!isfinite(r.first_cut)) r.section_ratio = fracture_rest_section_area(w, NOTCH_X) / rest_section;
    assert_int_equal(piola_world_step(w, 0, NULL), PIOLA_OK);
    if (piola_world_solid_cut_tet_count(w, 0) > 0 && !isfinite(r.first_cut)) r.first_cut = piola_world_time(w);
    if (piola_world_solid_fragment_count(w, 0) >= 2) r.broken = piola_world_time(w);
  }
  /* where the cracks are, and which fragment holds each driven end */
  const piola_elastic_body *b = piola_world_solid_body(w, 0);
  const double *x = piola_world_solid_positions(w, 0), *f = piola_world_solid_material_fractions(w, 0);
  const int32_t *tets = piola_elastic_body_tets(b), *frag = piola_world_solid_fragments(w, 0);
  const int32_t *parent = piola_world_solid_parent_tets(w, 0);
  const double t = piola_world_time(w);
  int32_t left = -1, right = -1;
  for (int32_t c = 0; c < piola_elastic_body_tet_count(b); ++c) {
    assert_true(f[c] > 0 && f[c] <= 1);
    for (int k = 0; k < 4; ++k) {
      const double px = x[3 * tets[4 * c + k]];
      assert_true(isfinite(px));
      if (fabs(px + PULL * t) < 1e-6) left = frag[c];
      if (fabs(px - LENGTH - PULL * t) < 1e-6) right = frag[c];
    }
    if (f[c] < 1) {
      double cx = 0;
      for (int k = 0; k < 4; ++k) cx += 0.25 * mesh.positions[3 * mesh.tets[4 * parent[c] + k]];
      r.farthest_cut = fmax(r.farthest_cut, fabs(cx - NOTCH_X));
      r.far_cuts += fabs(cx - NOTCH_X) > 1.5 * CELL;
    }
  }
  r.ends_apart = left >= 0 && right >= 0 && left != right;
  for (int32_t c = 0; r.ends_apart && c < piola_elastic_body_tet_count(b); ++c) {
    double cx = 0;
    for (int k = 0; k < 4; ++k) cx += 0.25 * mesh.positions[3 * mesh.tets[4 * parent[c] + k]];
    if (frag[c] == left) r.reach = fmax(r.reach, cx - NOTCH_X);
    if (frag[c] == right) r.reach = fmax(r.reach, NOTCH_X - cx);
  }
  r.fragments = piola_world_solid_fragment_count(w, 0);
  piola_world_destroy(w);
  free(mesh.positions), free(mesh.tets);
  return r;
}

#define BRITTLE_THRESHOLD 1.2e4 /* Pa */
#define DUCTILE_THRESHOLD 1.2   /* accumulated plastic log strain */

static void brittle_notched_bar_breaks_at_the_notch(void **state) {
  (void)state;
  pull_result r = pull_notched_bar(0, PIOLA_FRACTURE_STRESS, BRITTLE_THRESHOLD, 0.6);
  print_message("brittle: first cut %g s, broken %g s, %d fragments reaching %g m past the notch, "
                "cuts up to %g m from it (%d copies farther than 1.5 cells)\n", r.first_cut, r.broken,
                (int)r.fragments, r.reach, r.farthest_cut, (int)r.far_cuts);
  assert_true(isfinite(r.broken));
  assert_true(r.first_cut > 0.005); /* the tension had to build up */
  assert_int_equal(r.fragments, 2);
  assert_true(r.ends_apart);
  assert_true(r.reach < CELL); /* broken at the notch */
  assert_true(r.far_cuts < 30); /* a crack surface, no cloud of cuts (short cracks at the
                                   clamped ends' corners, where the stress is singular) */
}

static void ductile_notched_bar_necks_then_breaks_later(void **state) {
  (void)state;
  pull_result brittle = pull_notched_bar(0, PIOLA_FRACTURE_STRESS, BRITTLE_THRESHOLD, 0.6);
  pull_result r = pull_notched_bar(1, PIOLA_FRACTURE_PLASTIC_STRAIN, DUCTILE_THRESHOLD, 1.0);
  print_message("ductile: first cut %g s, broken %g s, section %g of rest, %d fragments reaching %g m past "
                "the notch, cuts up to %g m from it\n", r.first_cut, r.broken, r.section_ratio,
                (int)r.fragments, r.reach, r.farthest_cut);
  assert_true(isfinite(r.broken));
  assert_true(r.section_ratio <= 0.7); /* necked before the first crack */
  assert_true(r.broken > brittle.broken);
  assert_int_equal(r.fragments, 2);
  assert_true(r.ends_apart);
  assert_true(r.reach < CELL);
  assert_true(r.far_cuts < 30);
}

/* The plastic strain criterion needs plasticity. */
static void plastic_strain_needs_plasticity(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  notched_bar_mesh(&mesh);
  piola_world_def wd = piola_default_world_def();
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = &mesh;
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  piola_fracture_def def = piola_default_fracture_def();
  def.criterion = PIOLA_FRACTURE_PLASTIC_STRAIN, def.threshold = 0.5;
  assert_int_equal(piola_world_solid_set_fracture(w, 0, &def), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "plasticity"));
  def.criterion = PIOLA_FRACTURE_STRESS, def.threshold = 0;
  assert_int_equal(piola_world_solid_set_fracture(w, 0, &def), PIOLA_ERROR_INVALID_ARGUMENT);
  piola_world_destroy(w);
  free(mesh.positions), free(mesh.tets);
}

int main(void) {
  piola_set_thread_count(1);
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(plastic_strain_needs_plasticity),
      cmocka_unit_test(brittle_notched_bar_breaks_at_the_notch),
      cmocka_unit_test(ductile_notched_bar_necks_then_breaks_later),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
