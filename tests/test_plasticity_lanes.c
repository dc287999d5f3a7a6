/* The blocked (8-lane) plastic update against the scalar per-tet reference: from the same
 * state and the same diagonalization, both must give the same Fp^-1, accumulated strain,
 * effective Dm^-1 and statistics, over random large, flat, collapsed, inverted and barely
 * moving deformations, with and without hardening and volume preservation; tets that do not
 * yield keep their bits; results do not depend on the thread count. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "force/effective_dm_inv.h"
#include "piola/threads.h"
#include "plasticity/plastic_state.h"
#include "test_elastic_body_fixtures.h"
#include "test_support.h"

enum { LARGE, CHAOS, FLAT, COLLAPSED, INVERTED, BARELY, MIXED, ISOTROPIC, EXTREME, KIND_COUNT };

/* Positions of deformation `kind` around the rest positions. */
static void random_positions(const piola_elastic_body *body, int kind, test_rng *rng, double *x) {
  int32_t n = piola_elastic_body_vertex_count(body);
  const double *rest = piola_elastic_body_rest_positions(body);
  double a[9];
  for (int i = 0; i < 9; ++i) a[i] = (i % 4 == 0 ? 1.0 : 0.0) + 0.5 * test_rng_normal(rng);
  if (kind == FLAT) a[6] = a[7] = a[8] = 0; /* every tet rank 2 */
  if (kind == INVERTED) a[0] = -fabs(a[0]) - 0.5, a[4] = fabs(a[4]) + 0.5, a[8] = fabs(a[8]) + 0.5;
  if (kind == ISOTROPIC) { /* equal singular values: the exact limit's degenerate case */
    double k = test_rng_uniform(rng, 0, 1) < 0.5 ? test_rng_uniform(rng, 2, 5) : test_rng_uniform(rng, 0.2, 0.5);
    for (int i = 0; i < 9; ++i) a[i] = (i % 4 == 0) ? k : 0.0;
  }
  if (kind == EXTREME) { /* R1 diag(30, 1, 1/30) R2: far past the limit both ways */
    double r1[9], r2[9], m[9];
    fixture_random_rotation(rng, r1);
    fixture_random_rotation(rng, r2);
    const double d[3] = {30.0, 1.0, 1.0 / 30.0};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) m[3 * i + j] = r1[3 * i + j] * d[j];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) a[3 * i + j] = m[3 * i] * r2[j] + m[3 * i + 1] * r2[3 + j] + m[3 * i + 2] * r2[6 + j];
  }
  for (int32_t v = 0; v < n; ++v) {
    const double *p = rest + 3 * v;
    for (int r = 0; r < 3; ++r) {
      double y = a[3 * r] * p[0] + a[3 * r + 1] * p[1] + a[3 * r + 2] * p[2];
      switch (kind) {
        case CHAOS: y = p[r] + 0.3 * test_rng_normal(rng); break; /* many tets inverted */
        case COLLAPSED: y = 0.25; break;                           /* F = 0 */
        case BARELY: y = p[r] * (1 + 1e-3) + 1e-4 * test_rng_normal(rng); break;
        case MIXED: y = (v % 3 == 0) ? p[r] + 0.2 * test_rng_normal(rng) : p[r]; break;
        case ISOTROPIC: case EXTREME: break;
        case FLAT: y += 1e-9 * (r == 2) * test_rng_normal(rng); break;
        default: y += 0.01 * test_rng_normal(rng); break;
      }
      x[3 * v + r] = y;
    }
  }
}

/* dst <- src: the plastic state and the effective Dm^-1 it wrote into its body. */
static void copy_state(piola_plastic_state *dst, const piola_plastic_state *src) {
  size_t np = (size_t)src->padded_count;
  memcpy(dst->fp_inv, src->fp_inv, 9 * np * sizeof(double));
  memcpy(dst->alpha, src->alpha, np * sizeof(double));
  memcpy(dst->stretch_bound, src->stretch_bound, np * sizeof(double));
  memcpy(dst->block_bound, src->block_bound, np / PIOLA_PLASTIC_LANES * sizeof(double));
  for (int32_t t = 0; t < src->tet_count; ++t) {
    double m[9];
    piola__elastic_body_get_dm_inv(src->body, t, m);
    piola__elastic_body_set_dm_inv(dst->body, t, m);
  }
}

static double rel_diff9(const double *a, const double *b) {
  double d = 0, s = 0;
  for (int k = 0; k < 9; ++k) d = fmax(d, fabs(a[k] - b[k])), s = fmax(s, fabs(b[k]));
  return d / fmax(s, 1e-300);
}

static void compare_with_reference(double hardening, int volume_preserving, uint64_t seed) {
  piola_tet_mesh mesh;
  /* 7^3 cells = 2058 tets: a partial last block, and enough blocks for the parallel loop */
  assert_int_equal(piola_tet_mesh_box_grid(7, 7, 7, (piola_vec3){0.1, 0.1, 0.1}, &mesh), PIOLA_OK);
  piola_material mat = fixture_material(PIOLA_MODEL_NEOHOOKEAN);
  piola_elastic_body *body_a = fixture_body(&mesh, &mat), *body_b = fixture_body(&mesh, &mat);
  piola_plasticity_def def = piola_default_plasticity_def();
  def.yield = 0.04;
  def.limit = 0.9;
  def.hardening = hardening;
  def.volume_preserving = volume_preserving;
  piola_plastic_state *pa, *pb;
  assert_int_equal(piola_plastic_state_create(body_a, &def, &pa), PIOLA_OK);
  assert_int_equal(piola_plastic_state_create(body_b, &def, &pb), PIOLA_OK);
  int32_t nv = piola_elastic_body_vertex_count(body_a), nt = piola_elastic_body_tet_count(body_a);
  assert_true(nt % PIOLA_PLASTIC_LANES != 0);
  double *x = malloc(sizeof(double) * 3 * (size_t)nv), *f = malloc(sizeof(double) * 3 * (size_t)nv);
  double *before = malloc(sizeof(double) * 9 * (size_t)nt), *alpha_before = malloc(sizeof(double) * (size_t)nt);
  test_rng rng = test_rng_seeded(seed);
  long rounds = test_samples(6 * KIND_COUNT, KIND_COUNT);
  int32_t total_yielded = 0, total_limited = 0, total_kept = 0;
  double worst_fp = 0, worst_eff = 0, worst_alpha = 0;
  for (long round = 0; round < rounds; ++round) {
    int kind = (int)(round % KIND_COUNT);
    random_positions(body_a, kind, &rng, x);
    copy_state(pb, pa);
    assert_int_equal(piola_elastic_body_update(body_a, x, 1.0, f, NULL), PIOLA_OK);
    assert_int_equal(piola_elastic_body_update(body_b, x, 1.0, f, NULL), PIOLA_OK);
    memcpy(before, pa->fp_inv, sizeof(double) * 9 * (size_t)nt);
    memcpy(alpha_before, pa->alpha, sizeof(double) * (size_t)nt);
    const double *fhat = piola_elastic_body_fhat(body_a);
    piola_plastic_stats sa, sb;
    assert_int_equal(piola_plastic_state_update(pa, 1e-3, &sa), PIOLA_OK);
    piola__plastic_state_update_scalar(pb, 1e-3, &sb);
    assert_int_equal(sa.yielded_count, sb.yielded_count);
    assert_int_equal(sa.limited_count, sb.limited_count);
    assert_close(sa.max_fp_stretch, sb.max_fp_stretch, 1e-12 * sb.max_fp_stretch);
    total_yielded += sa.yielded_count, total_limited += sa.limited_count;
    for (int32_t t = 0; t < nt; ++t) {
      const double *fa = pa->fp_inv + 9 * t, *fb = pb->fp_inv + 9 * t;
      for (int k = 0; k < 9; ++k) assert_true(isfinite(fa[k]));
      worst_fp = fmax(worst_fp, rel_diff9(fa, fb));
      worst_alpha = fmax(worst_alpha, fabs(pa->alpha[t] - pb->alpha[t]));
      double ea[9], eb[9];
      piola__elastic_body_get_dm_inv(body_a, t, ea);
      piola__elastic_body_get_dm_inv(body_b, t, eb);
      worst_eff = fmax(worst_eff, rel_diff9(ea, eb));
      double delta[3], dl;
      if (!piola__plastic_return_map(&pa->params, fhat + 3 * t, alpha_before[t], delta, &dl)) {
        /* the scalar return mapping says no yield: the blocked update must not touch a bit */
        if (memcmp(fa, before + 9 * t, sizeof(double) * 9) != 0)
          fail_msg("round %ld kind %d tet %d: not yielded, but Fp^-1 changed (fhat %.17g %.17g %.17g, alpha %.17g)",
                   round, kind, (int)t, fhat[3 * t], fhat[3 * t + 1], fhat[3 * t + 2], alpha_before[t]);
        assert_true(pa->alpha[t] == alpha_before[t]);
        ++total_kept;
      }
    }
  }
  /* the blocked update carries the effective Dm^-1 forward (old one times the increment):
   * after all those rounds it still equals Dm^-1,rest Fp^-1 */
  double worst_drift = 0;
  for (int32_t t = 0; t < nt; ++t) {
    double eff[9], want[9];
    piola__elastic_body_get_dm_inv(body_a, t, eff);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        want[3 * i + j] = 0;
        for (int k = 0; k < 3; ++k)
          want[3 * i + j] += piola__plastic_rest_entry(pa, t, 3 * i + k) * pa->fp_inv[9 * t + 3 * k + j];
      }
    worst_drift = fmax(worst_drift, rel_diff9(eff, want));
  }
  assert_true(worst_drift < 1e-12);
  print_message("hardening %g, volume %d: %d yielded, %d limited, %d kept; worst differences Fp^-1 %.2g, "
                "Dm^-1 %.2g, alpha %.2g; Dm^-1 vs rest Fp^-1 %.2g\n",
                hardening, volume_preserving, (int)total_yielded, (int)total_limited, (int)total_kept, worst_fp,
                worst_eff, worst_alpha, worst_drift);
  assert_true(worst_fp < 1e-12);
  assert_true(worst_eff < 1e-12);
  assert_true(worst_alpha < 1e-12);
  /* every path was exercised */
  assert_true(total_yielded > 0 && total_limited > 0 && total_kept > 0);
  free(x), free(f), free(before), free(alpha_before);
  piola_plastic_state_destroy(pa);
  piola_plastic_state_destroy(pb);
  piola_elastic_body_destroy(body_a);
  piola_elastic_body_destroy(body_b);
  fixture_mesh_free(&mesh);
}

static void blocked_matches_reference(void **state) {
  (void)state;
  compare_with_reference(0.0, 0, 31);
}

static void blocked_matches_reference_with_hardening(void **state) {
  (void)state;
  compare_with_reference(0.7, 0, 32);
}

static void blocked_matches_reference_volume_preserving(void **state) {
  (void)state;
  compare_with_reference(0.2, 1, 33);
}

/* Many yielding steps far from the limit (no exact projection resets a tet): the effective
 * Dm^-1 carried forward by the blocked update stays Dm^-1,rest Fp^-1 to rounding. */
static void effective_dm_inv_does_not_drift(void **state) {
  (void)state;
  piola_tet_mesh mesh = fixture_grid(3, 0.1);
  piola_material mat = fixture_material(PIOLA_MODEL_NEOHOOKEAN);
  piola_elastic_body *body = fixture_body(&mesh, &mat);
  piola_plasticity_def def = piola_default_plasticity_def();
  def.yield = 0.01;
  def.limit = 20;
  piola_plastic_state *p;
  assert_int_equal(piola_plastic_state_create(body, &def, &p), PIOLA_OK);
  int32_t nv = piola_elastic_body_vertex_count(body), nt = piola_elastic_body_tet_count(body);
  double *x = malloc(sizeof(double) * 3 * (size_t)nv), *f = malloc(sizeof(double) * 3 * (size_t)nv);
  const double *rest = piola_elastic_body_rest_positions(body);
  test_rng rng = test_rng_seeded(35);
  long steps = test_samples(2000, 50), yielded = 0;
  for (long step = 0; step < steps; ++step) {
    /* a wobble of +-10% that keeps changing direction: every tet yields most steps */
    double a[9];
    for (int i = 0; i < 9; ++i) a[i] = (i % 4 == 0 ? 1.0 : 0.0) + 0.1 * test_rng_normal(&rng);
    for (int32_t v = 0; v < nv; ++v)
      for (int r = 0; r < 3; ++r)
        x[3 * v + r] = a[3 * r] * rest[3 * v] + a[3 * r + 1] * rest[3 * v + 1] + a[3 * r + 2] * rest[3 * v + 2] +
                       0.002 * test_rng_normal(&rng);
    assert_int_equal(piola_elastic_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
    piola_plastic_stats st;
    assert_int_equal(piola_plastic_state_update(p, 1e-3, &st), PIOLA_OK);
    assert_int_equal(st.limited_count, 0);
    yielded += st.yielded_count;
  }
  assert_true(yielded > steps * nt / 2);
  double worst = 0;
  for (int32_t t = 0; t < nt; ++t) {
    double eff[9], want[9];
    piola__elastic_body_get_dm_inv(body, t, eff);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        want[3 * i + j] = 0;
        for (int k = 0; k < 3; ++k)
          want[3 * i + j] += piola__plastic_rest_entry(p, t, 3 * i + k) * p->fp_inv[9 * t + 3 * k + j];
      }
    worst = fmax(worst, rel_diff9(eff, want));
  }
  print_message("%ld steps, %ld tet yields: effective Dm^-1 vs rest Dm^-1 Fp^-1 %.2g\n", steps, yielded, worst);
  assert_true(worst < 1e-12);
  free(x), free(f);
  piola_plastic_state_destroy(p);
  piola_elastic_body_destroy(body);
  fixture_mesh_free(&mesh);
}

/* The same sequence of deformations with 1 and 2 threads: bit-for-bit the same state. */
static void independent_of_thread_count(void **state) {
  (void)state;
  piola_tet_mesh mesh;
  assert_int_equal(piola_tet_mesh_box_grid(7, 7, 7, (piola_vec3){0.1, 0.1, 0.1}, &mesh), PIOLA_OK);
  piola_material mat = fixture_material(PIOLA_MODEL_NEOHOOKEAN);
  piola_elastic_body *body[2];
  piola_plastic_state *p[2];
  piola_plasticity_def def = piola_default_plasticity_def();
  def.hardening = 0.3;
  for (int i = 0; i < 2; ++i) {
    body[i] = fixture_body(&mesh, &mat);
    assert_int_equal(piola_plastic_state_create(body[i], &def, &p[i]), PIOLA_OK);
  }
  int32_t nv = piola_elastic_body_vertex_count(body[0]), nt = piola_elastic_body_tet_count(body[0]);
  double *x = malloc(sizeof(double) * 3 * (size_t)nv), *f = malloc(sizeof(double) * 3 * (size_t)nv);
  test_rng rng = test_rng_seeded(34);
  piola_plastic_stats st[2];
  for (int round = 0; round < 2 * KIND_COUNT; ++round) {
    random_positions(body[0], round % KIND_COUNT, &rng, x);
    for (int i = 0; i < 2; ++i) {
      piola_set_thread_count(i + 1);
      assert_int_equal(piola_elastic_body_update(body[i], x, 1.0, f, NULL), PIOLA_OK);
      assert_int_equal(piola_plastic_state_update(p[i], 1e-3, &st[i]), PIOLA_OK);
    }
    assert_int_equal(st[0].yielded_count, st[1].yielded_count);
    assert_true(st[0].max_fp_stretch == st[1].max_fp_stretch);
  }
  piola_set_thread_count(0);
  assert_memory_equal(p[0]->fp_inv, p[1]->fp_inv, sizeof(double) * 9 * (size_t)nt);
  assert_memory_equal(p[0]->alpha, p[1]->alpha, sizeof(double) * (size_t)nt);
  free(x), free(f);
  for (int i = 0; i < 2; ++i) {
    piola_plastic_state_destroy(p[i]);
    piola_elastic_body_destroy(body[i]);
  }
  fixture_mesh_free(&mesh);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(blocked_matches_reference),
      cmocka_unit_test(blocked_matches_reference_with_hardening),
      cmocka_unit_test(blocked_matches_reference_volume_preserving),
      cmocka_unit_test(effective_dm_inv_does_not_drift),
      cmocka_unit_test(independent_of_thread_count),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
