/* The kernels built once per instruction set (common/isa.h): the variant chosen follows the
 * CPU and PIOLA_ISA, the plain-named entry points run that variant bit for bit, and every
 * variant the CPU runs gives the same physics to rounding (the AVX-512 one starts its
 * square roots from the hardware estimate, the others from a bit-level guess, so their last
 * bits differ). ctest also runs the force, damping, muscle and plasticity tests under each
 * PIOLA_ISA value (CMakeLists.txt). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/isa.h"
#include "force/damping_matrix.h"
#include "force/elastic_body_internal.h"
#include "force/element_stiffness.h"
#include "force/force_lanes.h"
#include "force/stable_step.h"
#include "force/stable_step_modulus.h"
#include "force/stiffness_lanes.h"
#include "force/stiffness_matrix.h"
#include "force/svd_kernel.h"
#include "piola/kernels.h"
#include "test_elastic_body_fixtures.h"

typedef void (*svd_batch_fn)(int32_t, const double *, double *, double *, double *);
typedef void (*block_range_fn)(piola_elastic_body *, const double *, double, int, int32_t, int32_t,
                               double *);
typedef void (*damping_assemble_fn)(piola__damping_matrix *, const piola_elastic_body *, double,
                                    double);
typedef double (*state_rate2_fn)(piola_elastic_body *, int32_t *);
typedef void (*stiffness_lanes_fn)(const piola_elastic_body *, int32_t, double[54][PIOLA_TET_BLOCK]);

/* The variants of this build, indexed by piola__isa (NULL where a build has fewer: a
 * sanitizer build has no AVX2 variant, CMakeLists.txt). */
#if defined(PIOLA_KERNEL_DISPATCH)
#define VARIANTS_OF(f) {f##_baseline, PIOLA_ISA_AVX2_OR(f, NULL), PIOLA_ISA_AVX512_OR(f, NULL)}
static const svd_batch_fn SVD[] = VARIANTS_OF(piola__svd3_kernel_batch);
static const block_range_fn FORCES[] = VARIANTS_OF(piola__force_block_range);
static const damping_assemble_fn DAMPING[] = VARIANTS_OF(piola__damping_matrix_assemble);
static const state_rate2_fn RATE2[] = VARIANTS_OF(piola__elastic_body_state_rate2);
static const stiffness_lanes_fn STIFFNESS[] = VARIANTS_OF(piola__stiffness_block_lanes);
#else
static const svd_batch_fn SVD[] = {PIOLA_ISA_SELECT(piola__svd3_kernel_batch), NULL, NULL};
static const block_range_fn FORCES[] = {PIOLA_ISA_SELECT(piola__force_block_range), NULL, NULL};
static const damping_assemble_fn DAMPING[] = {PIOLA_ISA_SELECT(piola__damping_matrix_assemble),
                                              NULL, NULL};
static const state_rate2_fn RATE2[] = {PIOLA_ISA_SELECT(piola__elastic_body_state_rate2), NULL, NULL};
static const stiffness_lanes_fn STIFFNESS[] = {PIOLA_ISA_SELECT(piola__stiffness_block_lanes), NULL,
                                               NULL};
#endif
enum { VARIANTS = 3 };

static int runs(int isa) { return piola__isa_supported((piola__isa)isa); }

static void chosen_variant_follows_cpu_and_environment(void **state) {
  (void)state;
  const char *name = piola_kernel_isa();
  int chosen = piola__isa_variant();
  assert_true(runs(chosen));
  assert_string_equal(name, piola__isa_name((piola__isa)chosen));
#if defined(PIOLA_KERNEL_DISPATCH)
  int best = 0;
  for (int i = 0; i < VARIANTS; ++i)
    if (runs(i)) {
      best = i;
      /* a variant this build leaves out is never offered */
      if (!SVD[i] || !FORCES[i] || !DAMPING[i] || !RATE2[i] || !STIFFNESS[i])
        fail_msg("%s is not built but reported as supported", piola__isa_name((piola__isa)i));
    }
  const char *asked = getenv("PIOLA_ISA");
  int asked_index = -1;
  for (int i = 0; asked && i < VARIANTS; ++i)
    if (strcmp(asked, piola__isa_name((piola__isa)i)) == 0) asked_index = i;
  /* the best variant built and run by the CPU that is not above the one asked for */
  int expected = best;
  if (asked_index >= 0)
    for (expected = asked_index; expected > 0 && !runs(expected);) --expected;
  if (chosen != expected)
    fail_msg("PIOLA_ISA=%s, best %s: chose %s", asked ? asked : "(unset)",
             piola__isa_name((piola__isa)best), name);
#else
  assert_true(strcmp(name, "native") == 0 || strcmp(name, "portable") == 0);
#endif
}

/* Random, rank-2, rank-1, zero, near-identity, tiny, huge and inverted matrices. */
static void hard_matrices(test_rng *rng, int n, double *f) {
  for (int t = 0; t < n; ++t) {
    double *m = f + 9 * t;
    for (int k = 0; k < 9; ++k) m[k] = test_rng_uniform(rng, -1, 1);
    switch (t % 8) {
      case 1: for (int r = 0; r < 3; ++r) m[3 * r + 2] = 0.5 * m[3 * r] - 0.25 * m[3 * r + 1]; break;
      case 2: for (int r = 0; r < 3; ++r) { m[3 * r + 1] = 2 * m[3 * r]; m[3 * r + 2] = -m[3 * r]; } break;
      case 3: memset(m, 0, 9 * sizeof(double)); break;
      case 4: for (int k = 0; k < 9; ++k) m[k] = (k % 4 == 0) + 1e-9 * m[k]; break;
      case 5: for (int k = 0; k < 9; ++k) m[k] *= 1e-120; break;
      case 6: for (int k = 0; k < 9; ++k) m[k] *= 1e120; break;
      case 7: for (int k = 0; k < 9; ++k) m[k] = (k == 0 ? 2.0 : k == 4 ? 2.0 : k == 8 ? -1e-3 : 0.0); break;
      default: break;
    }
  }
}

/* Each variant reconstructs F to 1e-13 with proper rotations; the singular values of any
 * two agree to 1e-13 of the largest; the plain name gives the chosen variant's bits. */
static void svd_variants_agree(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(31);
  const int n = (int)test_samples(20000, 800);
  double *f = malloc(sizeof(double) * 9 * (size_t)n);
  double *u[VARIANTS + 1], *v[VARIANTS + 1], *s[VARIANTS + 1];
  for (int i = 0; i <= VARIANTS; ++i) {
    u[i] = malloc(sizeof(double) * 9 * (size_t)n);
    v[i] = malloc(sizeof(double) * 9 * (size_t)n);
    s[i] = malloc(sizeof(double) * 3 * (size_t)n);
  }
  hard_matrices(&rng, n, f);
  piola__svd3_kernel_batch(n, f, u[VARIANTS], s[VARIANTS], v[VARIANTS]);
  int first = -1;
  for (int isa = 0; isa < VARIANTS; ++isa) {
    if (!SVD[isa] || !runs(isa)) continue;
    SVD[isa](n, f, u[isa], s[isa], v[isa]);
    double worst = 0;
    for (int t = 0; t < n; ++t) {
      const double *m = f + 9 * t, *um = u[isa] + 9 * t, *vm = v[isa] + 9 * t, *sm = s[isa] + 3 * t;
      double err = 0, norm = 0, orth = 0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          double r = 0, uu = 0, vv = 0;
          for (int k = 0; k < 3; ++k) {
            r += um[3 * i + k] * sm[k] * vm[3 * j + k];
            uu += um[3 * k + i] * um[3 * k + j];
            vv += vm[3 * k + i] * vm[3 * k + j];
          }
          err += (r - m[3 * i + j]) * (r - m[3 * i + j]);
          norm += m[3 * i + j] * m[3 * i + j];
          orth = fmax(orth, fmax(fabs(uu - (i == j)), fabs(vv - (i == j))));
        }
      if (!(sqrt(err) <= 1e-13 * sqrt(norm) + 1e-300) || !(orth <= 1e-13))
        fail_msg("%s, matrix %d: reconstruction %g of %g, orthogonality %g",
                 piola__isa_name((piola__isa)isa), t, sqrt(err), sqrt(norm), orth);
      if (first >= 0)
        for (int k = 0; k < 3; ++k) {
          double a = s[isa][3 * t + k], b = s[first][3 * t + k];
          if (s[first][3 * t] > 0) worst = fmax(worst, fabs(a - b) / s[first][3 * t]);
          if (!(fabs(a - b) <= 1e-13 * fabs(s[first][3 * t]) + 1e-300))
            fail_msg("matrix %d: singular value %d is %.17g (%s) and %.17g (%s)", t, k, a,
                     piola__isa_name((piola__isa)isa), b, piola__isa_name((piola__isa)first));
        }
    }
    if (first >= 0)
      print_message("%s vs %s: singular values differ by up to %.2g of the largest\n",
                    piola__isa_name((piola__isa)isa), piola__isa_name((piola__isa)first), worst);
    if (first < 0) first = isa;
  }
  assert_true(first >= 0);
  int chosen = piola__isa_variant();
  assert_memory_equal(s[chosen], s[VARIANTS], sizeof(double) * 3 * (size_t)n);
  assert_memory_equal(u[chosen], u[VARIANTS], sizeof(double) * 9 * (size_t)n);
  assert_memory_equal(v[chosen], v[VARIANTS], sizeof(double) * 9 * (size_t)n);
  free(f);
  for (int i = 0; i <= VARIANTS; ++i) {
    free(u[i]);
    free(v[i]);
    free(s[i]);
  }
}

static piola_material muscle(void) {
  piola_material_def def = piola_default_material_def();
  def.model = PIOLA_MODEL_MUSCLE;
  def.youngs_modulus = 3e4;
  def.poisson_ratio = 0.45;
  def.muscle.max_active_stress = 4e4;
  def.muscle.passive_stiffness = 5e4;
  def.muscle.optimal_stretch = 1.02;
  piola_material m;
  assert_int_equal(piola_material_init(&def, &m), PIOLA_OK);
  return m;
}

/* A 4 x 4 x 4 grid (48 blocks, one range: the serial path) of neo-Hookean, corotated and
 * muscle tets with random fibres, randomly deformed with some tets inverted: the step bound
 * of every variant is the same to the bit; the forces, energy densities and damping blocks
 * agree to 1e-13 of their largest entry; the update (the plain names) gives the chosen
 * variant's bits. */
static void force_damping_and_step_variants_agree(void **state) {
  (void)state;
  test_rng rng = test_rng_seeded(77);
  piola_tet_mesh mesh = fixture_grid(4, 0.1);
  piola_material mats[3] = {fixture_material(PIOLA_MODEL_NEOHOOKEAN),
                            fixture_material(PIOLA_MODEL_COROTATED), muscle()};
  int32_t *which = malloc(sizeof(int32_t) * (size_t)mesh.tet_count);
  double *fibers = malloc(sizeof(double) * 3 * (size_t)mesh.tet_count);
  for (int32_t t = 0; t < mesh.tet_count; ++t) {
    which[t] = t % 3;
    for (int k = 0; k < 3; ++k) fibers[3 * t + k] = test_rng_uniform(&rng, -1, 1) + (k == 0);
  }
  piola_elastic_body_def def = piola_default_elastic_body_def();
  def.rest_mesh = &mesh;
  def.materials = mats;
  def.material_count = 3;
  def.tet_materials = which;
  def.fiber_directions = fibers;
  piola_elastic_body *body = NULL;
  assert_int_equal(piola_elastic_body_create(&def, &body), PIOLA_OK);
  piola_elastic_body_set_activation(body, 0.6);
  const int n = 3 * mesh.vertex_count;
  double *x = malloc(sizeof(double) * (size_t)n);
  for (int i = 0; i < n; ++i) x[i] = mesh.positions[i] * 1.1 + test_rng_uniform(&rng, -0.04, 0.04);
  /* a few vertices pushed through their neighbours: inverted tets */
  for (int i = 0; i < n; i += 37) x[i] -= 0.15;
  const int32_t blocks = body->padded_tet_count / PIOLA_TET_BLOCK;
  assert_true(blocks < PIOLA_PARALLEL_MIN_BLOCKS);
  const size_t edge_values = 9 * (size_t)body->damping.edge_count;
  const size_t tets = (size_t)body->padded_tet_count;

  double *f[VARIANTS + 1], *psi[VARIANTS + 1], *damp[VARIANTS + 1];
  for (int i = 0; i <= VARIANTS; ++i) {
    f[i] = calloc((size_t)n, sizeof(double));
    psi[i] = malloc(sizeof(double) * tets);
    damp[i] = malloc(sizeof(double) * edge_values);
  }
  piola_elastic_stats stats;
  assert_int_equal(piola_elastic_body_update(body, x, 1.0, f[VARIANTS], &stats), PIOLA_OK);
  assert_true(stats.inverted_count > 0);
  memcpy(psi[VARIANTS], body->energy_density, sizeof(double) * tets);
  double *v = malloc(sizeof(double) * (size_t)n), *fd = malloc(sizeof(double) * (size_t)n);
  for (int i = 0; i < n; ++i) v[i] = test_rng_uniform(&rng, -1, 1);
  piola_elastic_body_damping_forces(body, v, 2.0, 0.5, fd);
  memcpy(damp[VARIANTS], body->damping.blocks, sizeof(double) * edge_values);

  /* the step bound: no fused multiply-adds, only max reductions, so the same bits (a body of
   * mixed materials has no cache of k from the force loop; cached_step_bound_variants_agree
   * checks the bodies that do) */
  int32_t worst_chosen = -2;
  const double rate2_chosen = piola__elastic_body_state_rate2(body, &worst_chosen);
  assert_true(rate2_chosen > 0 && worst_chosen >= 0);
  for (int isa = 0; isa < VARIANTS; ++isa) {
    if (!RATE2[isa] || !runs(isa)) continue;
    int32_t worst = -2;
    const double rate2 = RATE2[isa](body, &worst);
    if (rate2 != rate2_chosen || worst != worst_chosen)
      fail_msg("step bound rate^2 %.17g (tet %d) under %s, %.17g (tet %d) chosen", rate2,
               (int)worst, piola__isa_name((piola__isa)isa), rate2_chosen, (int)worst_chosen);
  }

  int first = -1;
  for (int isa = 0; isa < VARIANTS; ++isa) {
    if (!FORCES[isa] || !runs(isa)) continue;
    FORCES[isa](body, x, 1.0, 1, 0, blocks, f[isa]);
    memcpy(psi[isa], body->energy_density, sizeof(double) * tets);
    DAMPING[isa](&body->damping, body, 2.0, 0.5);
    memcpy(damp[isa], body->damping.blocks, sizeof(double) * edge_values);
    if (first >= 0) {
      const struct { const char *what; const double *a, *b; size_t count; } pairs[3] = {
          {"forces", f[isa], f[first], (size_t)n},
          {"energy densities", psi[isa], psi[first], (size_t)mesh.tet_count},
          {"damping block entries", damp[isa], damp[first], edge_values}};
      for (int p = 0; p < 3; ++p) {
        double largest = fixture_max_abs(pairs[p].b, (int)pairs[p].count), worst = 0;
        assert_true(largest > 0);
        for (size_t i = 0; i < pairs[p].count; ++i) {
          worst = fmax(worst, fabs(pairs[p].a[i] - pairs[p].b[i]) / largest);
          if (!(fabs(pairs[p].a[i] - pairs[p].b[i]) <= 1e-13 * largest))
            fail_msg("%s, entry %zu: %.17g (%s) and %.17g (%s), largest %g", pairs[p].what, i,
                     pairs[p].a[i], piola__isa_name((piola__isa)isa), pairs[p].b[i],
                     piola__isa_name((piola__isa)first), largest);
        }
        print_message("%s vs %s: %s differ by up to %.2g of the largest\n",
                      piola__isa_name((piola__isa)isa), piola__isa_name((piola__isa)first),
                      pairs[p].what, worst);
      }
    }
    if (first < 0) first = isa;
  }
  assert_true(first >= 0);
  int chosen = piola__isa_variant();
  assert_memory_equal(f[chosen], f[VARIANTS], sizeof(double) * (size_t)n);
  assert_memory_equal(psi[chosen], psi[VARIANTS], sizeof(double) * (size_t)mesh.tet_count);
  assert_memory_equal(damp[chosen], damp[VARIANTS], sizeof(double) * edge_values);

  for (int i = 0; i <= VARIANTS; ++i) {
    free(f[i]);
    free(psi[i]);
    free(damp[i]);
  }
  free(v);
  free(fd);
  free(x);
  free(which);
  free(fibers);
  piola_elastic_body_destroy(body);
  fixture_mesh_free(&mesh);
}

/* Bodies of one material whose force loop forms the step bound's k (stable_step_modulus.h):
 * each variant's force loop and then its bound, on the grid randomly deformed with some tets
 * inverted (those blocks computed by the pass, the others read from the cache). Not the same
 * bits: the cached k is the force loop's arithmetic, with fused multiply-adds where the
 * variant has them, from that variant's Fhat, whose last bits differ too (the forces above
 * agree to 1e-13 of their largest entry, not to the bit). A few roundings of k, so the bound
 * agrees to 1e-13 relative, and the worst tet is the same. */
static void cached_step_bound_variants_agree(void **state) {
  (void)state;
  const piola_material_model models[] = {PIOLA_MODEL_NEOHOOKEAN, PIOLA_MODEL_COROTATED, PIOLA_MODEL_STVK};
  for (int mi = 0; mi < 3; ++mi) {
    test_rng rng = test_rng_seeded(79);
    piola_tet_mesh mesh = fixture_grid(4, 0.1);
    piola_material m = fixture_material(models[mi]);
    piola_elastic_body_def def = piola_default_elastic_body_def();
    def.rest_mesh = &mesh;
    def.materials = &m;
    def.material_count = 1;
    piola_elastic_body *body = NULL;
    assert_int_equal(piola_elastic_body_create(&def, &body), PIOLA_OK);
    assert_non_null(body->step_cache);
    const int n = 3 * mesh.vertex_count;
    double *x = malloc(sizeof(double) * (size_t)n), *f = calloc((size_t)n, sizeof(double));
    for (int i = 0; i < n; ++i) x[i] = mesh.positions[i] * 1.1 + test_rng_uniform(&rng, -0.04, 0.04);
    for (int i = 0; i < n; i += 37) x[i] -= 0.15; /* inverted tets */
    const int32_t blocks = body->padded_tet_count / PIOLA_TET_BLOCK;
    assert_int_equal(piola_elastic_body_update(body, x, 1.0, f, NULL), PIOLA_OK);
    int32_t held = 0; /* blocks the update cached (stable_step_modulus.h) */
    const int32_t full_blocks = mesh.tet_count / PIOLA_TET_BLOCK;
    for (int32_t b = 0; b < full_blocks; ++b)
      held += body->step_cache[(size_t)b * STEP_CACHE_SLOTS + STEP_CACHE_KEY] == (double)body->step_generation;
    assert_true(held > 0 && held < full_blocks); /* both paths of the pass */
    double first_rate2 = -1;
    int32_t first_worst = -2;
    int first = -1;
    for (int isa = 0; isa < VARIANTS; ++isa) {
      if (!FORCES[isa] || !RATE2[isa] || !runs(isa)) continue;
      FORCES[isa](body, x, 1.0, 0, 0, blocks, f);
      int32_t worst = -2;
      const double rate2 = RATE2[isa](body, &worst);
      assert_true(rate2 > 0 && worst >= 0);
      if (first < 0) {
        first = isa, first_rate2 = rate2, first_worst = worst;
        continue;
      }
      print_message("%s: step bound rate^2 %s vs %s differ by %.2g relative\n", piola_material_model_name(m.model),
                    piola__isa_name((piola__isa)isa), piola__isa_name((piola__isa)first),
                    fabs(rate2 - first_rate2) / first_rate2);
      if (!(fabs(rate2 - first_rate2) <= 1e-13 * first_rate2) || worst != first_worst)
        fail_msg("%s: step bound rate^2 %.17g (tet %d) under %s, %.17g (tet %d) under %s",
                 piola_material_model_name(m.model), rate2, (int)worst, piola__isa_name((piola__isa)isa),
                 first_rate2, (int)first_worst, piola__isa_name((piola__isa)first));
    }
    assert_true(first >= 0);
    free(x), free(f);
    piola_elastic_body_destroy(body);
    fixture_mesh_free(&mesh);
  }
}

/* The projected stiffness lanes give the scalar piola__tet_stiffness_blocks's bits in every
 * variant (they fuse no multiply-adds), on stretched, compressed and inverted tets: of two
 * materials (every tet's material part through the public functions), or of one material
 * `model` (blocks with no entry of Fhat below the threshold take the lane loop over the
 * model's parts; at least one does here, and at least one does not). */
static void check_stiffness_lanes(int uniform, piola_material_model model) {
  test_rng rng = test_rng_seeded(78);
  piola_tet_mesh mesh = fixture_grid(3, 0.1);
  piola_material mats[2] = {fixture_material(uniform ? model : PIOLA_MODEL_NEOHOOKEAN),
                            fixture_material(PIOLA_MODEL_STVK)};
  int32_t *which = malloc(sizeof(int32_t) * (size_t)mesh.tet_count);
  for (int32_t t = 0; t < mesh.tet_count; ++t) which[t] = t % 5 == 2;
  piola_elastic_body_def def = piola_default_elastic_body_def();
  def.rest_mesh = &mesh;
  def.materials = mats;
  def.material_count = uniform ? 1 : 2;
  def.tet_materials = uniform ? NULL : which;
  piola_elastic_body *body = NULL;
  assert_int_equal(piola_elastic_body_create(&def, &body), PIOLA_OK);
  const int n = 3 * mesh.vertex_count;
  double *x = malloc(sizeof(double) * (size_t)n), *f = malloc(sizeof(double) * (size_t)n);
  const double noise = uniform ? 0.005 : 0.05;
  for (int i = 0; i < n; ++i)
    x[i] = mesh.positions[i] * 1.1 + test_rng_uniform(&rng, -noise, noise);
  for (int v = 0; v < 6; ++v) x[3 * (5 * v + 3) + 2] += 0.15; /* inverts some tets */
  piola_elastic_stats st;
  assert_int_equal(piola_elastic_body_update(body, x, 0.7, f, &st), PIOLA_OK);
  assert_true(st.inverted_count > 0);
  const int32_t blocks = mesh.tet_count / PIOLA_TET_BLOCK;
  assert_true(blocks > 0);
  if (uniform) { /* both paths of the lanes' material part are taken */
    int32_t unclamped_blocks = 0;
    for (int32_t b = 0; b < blocks; ++b) {
      int unclamped = 1;
      for (int e = 0; e < 3 * PIOLA_TET_BLOCK; ++e)
        unclamped &= body->fhat[3 * (size_t)b * PIOLA_TET_BLOCK + e] >= mats[0].threshold;
      unclamped_blocks += unclamped;
    }
    assert_true(unclamped_blocks > 0 && unclamped_blocks < blocks);
  }
  for (int isa = 0; isa <= VARIANTS; ++isa) {
    if (isa < VARIANTS && (!STIFFNESS[isa] || !runs(isa))) continue;
    for (int32_t b = 0; b < blocks; ++b) {
      double lanes[54][PIOLA_TET_BLOCK], scalar[54];
      if (isa < VARIANTS)
        STIFFNESS[isa](body, b, lanes);
      else
        piola__stiffness_block_lanes(body, b, lanes);
      for (int l = 0; l < PIOLA_TET_BLOCK; ++l) {
        piola__tet_stiffness_blocks(body, b * PIOLA_TET_BLOCK + l, scalar);
        for (int e = 0; e < 54; ++e)
          if (memcmp(&lanes[e][l], &scalar[e], sizeof(double)) != 0)
            fail_msg("%s: tet %d entry %d: lanes %.17g, scalar %.17g",
                     isa < VARIANTS ? piola__isa_name((piola__isa)isa) : "plain name",
                     (int)(b * PIOLA_TET_BLOCK + l), e, lanes[e][l], scalar[e]);
      }
    }
  }
  free(x);
  free(f);
  free(which);
  piola_elastic_body_destroy(body);
  fixture_mesh_free(&mesh);
}

static void stiffness_lanes_give_the_scalar_bits(void **state) {
  (void)state;
  check_stiffness_lanes(0, PIOLA_MODEL_NEOHOOKEAN);
  /* every model, the muscle's and HGO's matrix too (their bodies here have no fibres; a
   * fibre term is added after the lanes, tests/test_element_stiffness.c checks it) */
  for (int model = 0; model < PIOLA_MODEL_COUNT; ++model)
    check_stiffness_lanes(1, (piola_material_model)model);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(chosen_variant_follows_cpu_and_environment),
      cmocka_unit_test(svd_variants_agree),
      cmocka_unit_test(force_damping_and_step_variants_agree),
      cmocka_unit_test(cached_step_bound_variants_agree),
      cmocka_unit_test(stiffness_lanes_give_the_scalar_bits),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
