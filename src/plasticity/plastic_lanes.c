/* The blocked plastic update: the return mapping of 8 tets at once on explicit 8-lane
 * vectors (design in plastic_state.h; the scalar path it must agree with is update_tet in
 * plastic_state.c, the per-tet math in return_mapping.h). A kernel, compiled once per
 * instruction set (common/isa.h). */
/* Fused multiply-adds, as in the force loop (see "Fused multiply-adds" in svd_kernel.h). */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("fp-contract=fast")
#endif
#include <math.h>
#include <string.h>

#include "force/effective_dm_inv.h"
#include "force/elastic_body_internal.h"
#include "math/v8_logexp.h"
#include "plasticity/plastic_state.h"

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#define L PIOLA_PLASTIC_LANES
_Static_assert(PIOLA_PLASTIC_LANES == PIOLA_TET_BLOCK, "plastic lanes are the force loop's blocks");

typedef piola_v8d v8;
typedef piola_v8l m8;
#define SEL PIOLA_V8_SELECT

static inline __attribute__((always_inline)) v8 v8_sqrt(v8 x) {
#if defined(__AVX512F__)
  return (v8)_mm512_sqrt_pd((__m512d)x);
#else
  v8 r;
  for (int l = 0; l < L; ++l) r[l] = sqrt(x[l]);
  return r;
#endif
}

/* Bit l set where lane l of the mask is set. */
static inline __attribute__((always_inline)) unsigned lane_bits(m8 m) {
#if defined(__AVX512DQ__)
  return (unsigned)_mm512_movepi64_mask((__m512i)m);
#else
  unsigned bits = 0;
  for (int l = 0; l < L; ++l) bits |= (unsigned)(m[l] != 0) << l;
  return bits;
#endif
}

/* Stores x into the lanes of p whose bit is set in bits; the others keep their bits. */
static inline __attribute__((always_inline)) void store_lanes(double *p, v8 x, m8 mask, unsigned bits) {
#if defined(__AVX512F__)
  (void)mask;
  _mm512_mask_storeu_pd(p, (__mmask8)bits, (__m512d)x);
#else
  (void)bits;
  piola__v8_store(p, SEL(mask, x, piola__v8_load(p)));
#endif
}

/* 1 / sqrt x for positive normal x: the hardware estimate (2^-14) and `newton` Newton steps
 * (1: 4e-9, 2: about an ulp); elsewhere the exact quotient. */
static inline __attribute__((always_inline)) v8 v8_rsqrt(v8 x, int newton) {
#if defined(__AVX512F__)
  v8 y = (v8)_mm512_rsqrt14_pd((__m512d)x);
  for (int i = 0; i < newton; ++i) y = y * (1.5 - 0.5 * x * y * y);
  return y;
#else
  (void)newton;
  return 1.0 / v8_sqrt(x);
#endif
}

/* 1 / x to 2^-28 relative (estimate and one Newton step); elsewhere exact. */
static inline __attribute__((always_inline)) v8 v8_recip_estimate(v8 x) {
#if defined(__AVX512F__)
  v8 y = (v8)_mm512_rcp14_pd((__m512d)x);
  return y * (2.0 - x * y);
#else
  return 1.0 / x;
#endif
}

/* 1 / x to about an ulp, and a / x to about an ulp (x normal, positive or negative). */
static inline __attribute__((always_inline)) v8 v8_div(v8 a, v8 x) {
#if defined(__AVX512F__)
  v8 y = (v8)_mm512_rcp14_pd((__m512d)x); /* relative error below 2^-14 */
  y = y * (2.0 - x * y);                  /* 2^-28 */
  v8 q = a * y;
  return q + y * (a - q * x);             /* one correction of the quotient: ~2^-56 + rounding */
#else
  return a / x;
#endif
}

#define SHUF __builtin_shufflevector

/* Fhat of the block's tets (AoS in the body, 3 per tet: 24 doubles = 3 vectors) as three
 * lane vectors, by two shuffles each. */
static inline __attribute__((always_inline)) void load_fhat(const double *fh, v8 f[3]) {
  v8 x0 = piola__v8_load(fh), x1 = piola__v8_load(fh + 8), x2 = piola__v8_load(fh + 16);
  v8 s0 = SHUF(x0, x1, 0, 3, 6, 9, 12, 15, 0, 0);
  v8 s1 = SHUF(x0, x1, 1, 4, 7, 10, 13, 0, 0, 0);
  v8 s2 = SHUF(x0, x1, 2, 5, 8, 11, 14, 0, 0, 0);
  f[0] = SHUF(s0, x2, 0, 1, 2, 3, 4, 5, 10, 13);
  f[1] = SHUF(s1, x2, 0, 1, 2, 3, 4, 8, 11, 14);
  f[2] = SHUF(s2, x2, 0, 1, 2, 3, 4, 9, 12, 15);
}

/* r[k][l] <- r[l][k]: three rounds of interleaving, 24 shuffles. */
static inline __attribute__((always_inline)) void transpose8(v8 r[8]) {
  v8 t[8], u[8];
  for (int i = 0; i < 4; ++i) {
    t[2 * i] = SHUF(r[2 * i], r[2 * i + 1], 0, 8, 2, 10, 4, 12, 6, 14);
    t[2 * i + 1] = SHUF(r[2 * i], r[2 * i + 1], 1, 9, 3, 11, 5, 13, 7, 15);
  }
  for (int h = 0; h < 2; ++h)
    for (int odd = 0; odd < 2; ++odd) {
      v8 a = t[4 * h + odd], b = t[4 * h + 2 + odd];
      u[4 * h + odd] = SHUF(a, b, 0, 1, 8, 9, 4, 5, 12, 13);
      u[4 * h + 2 + odd] = SHUF(a, b, 2, 3, 10, 11, 6, 7, 14, 15);
    }
  for (int k = 0; k < 4; ++k) {
    r[k] = SHUF(u[k], u[4 + k], 0, 1, 2, 3, 8, 9, 10, 11);
    r[4 + k] = SHUF(u[k], u[4 + k], 4, 5, 6, 7, 12, 13, 14, 15);
  }
}

/* The 9-entry matrices of 8 tets (AoS, 72 doubles) as 9 lane vectors: an 8 x 8 transpose
 * of unaligned rows for entries 0..7, entry 8 lane by lane. */
static inline __attribute__((always_inline)) void load_matrices(const double *m, v8 a[9]) {
  for (int l = 0; l < L; ++l) a[l] = piola__v8_load(m + 9 * l);
  transpose8(a);
  for (int l = 0; l < L; ++l) a[8][l] = m[9 * l + 8];
}

static inline __attribute__((always_inline)) void store_matrices(double *m, const v8 a[9]) {
  v8 r[8];
  for (int k = 0; k < 8; ++k) r[k] = a[k];
  transpose8(r);
  for (int l = 0; l < L; ++l) piola__v8_store(m + 9 * l, r[l]);
  for (int l = 0; l < L; ++l) m[9 * l + 8] = a[8][l];
}

/* The exact limit of 8 Fp^-1 at once (lanes of a, rows as in the AoS matrices): the SVD
 * a = W Sigma Q^T by one-sided Jacobi on the rows of a (they are rotated until orthogonal;
 * the rotations accumulate into W, the row norms become Sigma), Sigma clamped to
 * [1/cap, cap] (= log Sigma clamped to [-limit, limit]), and out = W Sigma' W^T, rotation
 * dropped, as piola__plastic_exact_limit does one tet at a time. One-sided Jacobi keeps the
 * small singular values relatively accurate (unlike an eigen-decomposition of a a^T, whose
 * condition is squared). Fixed sweeps, no branches; returns the lanes whose rows ended
 * orthogonal to 1e-14 (the others must take the scalar path) and the largest clamped
 * singular value in *largest. Not inlined: it runs only while tets reach the limit. */
enum { LIMIT_SWEEPS = 4 };
__attribute__((noinline)) PIOLA_WIDE_VECTORS static m8 limit_lanes(const v8 a[9], double cap, v8 out[9],
                                                                  v8 *largest) {
  v8 x[3][3], w[3][3];
  for (int i = 0; i < 3; ++i)
    for (int c = 0; c < 3; ++c) {
      x[i][c] = a[3 * i + c];
      w[i][c] = piola__v8_splat(i == c ? 1.0 : 0.0);
    }
  static const int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
  for (int sweep = 0; sweep < LIMIT_SWEEPS; ++sweep)
    for (int r = 0; r < 3; ++r) {
      const int pi = pairs[r][0], qi = pairs[r][1];
      v8 alpha = x[pi][0] * x[pi][0] + x[pi][1] * x[pi][1] + x[pi][2] * x[pi][2];
      v8 beta = x[qi][0] * x[qi][0] + x[qi][1] * x[qi][1] + x[qi][2] * x[qi][2];
      v8 gamma = x[pi][0] * x[qi][0] + x[pi][1] * x[qi][1] + x[pi][2] * x[qi][2];
      /* rows p' = c p - s q, q' = s p + c q are orthogonal for t = s / c the smaller root of
       * gamma t^2 + 2 tau t - gamma = 0, tau = (beta - alpha) / 2:
       * t = sign(tau) gamma / (|tau| + sqrt(tau^2 + gamma^2)); gamma = 0 gives t = 0 */
      v8 tau = 0.5 * (beta - alpha);
      v8 abs_tau = (v8)((m8)tau & INT64_C(0x7fffffffffffffff));
      v8 signed_gamma = (v8)((m8)gamma ^ ((m8)tau & INT64_MIN));
      /* the angle only has to be close (a later rotation corrects it, and convergence is
       * checked at the end): square root and division from the hardware estimates; the
       * normalization of (c, s) to an ulp, so every rotation is orthogonal */
      v8 q = tau * tau + gamma * gamma + 1e-300;
      v8 t = signed_gamma * v8_recip_estimate(abs_tau + q * v8_rsqrt(q, 1));
      v8 c = v8_rsqrt(1.0 + t * t, 2), sn = c * t;
      for (int k = 0; k < 3; ++k) {
        v8 xp = x[pi][k], xq = x[qi][k];
        x[pi][k] = c * xp - sn * xq;
        x[qi][k] = sn * xp + c * xq;
        v8 wp = w[pi][k], wq = w[qi][k];
        w[pi][k] = c * wp - sn * wq;
        w[qi][k] = sn * wp + c * wq;
      }
    }
  m8 ok = (m8)(piola__v8_splat(0.0) == piola__v8_splat(0.0));
  v8 norm2[3];
  for (int i = 0; i < 3; ++i) norm2[i] = x[i][0] * x[i][0] + x[i][1] * x[i][1] + x[i][2] * x[i][2];
  for (int r = 0; r < 3; ++r) {
    const int pi = pairs[r][0], qi = pairs[r][1];
    v8 gamma = x[pi][0] * x[qi][0] + x[pi][1] * x[qi][1] + x[pi][2] * x[qi][2];
    ok &= (m8)(gamma * gamma <= 1e-28 * (norm2[pi] * norm2[qi]));
  }
  v8 d[3], lo = piola__v8_splat(1.0 / cap), hi = piola__v8_splat(cap);
  for (int k = 0; k < 3; ++k) {
    v8 sigma = v8_sqrt(norm2[k]);
    sigma = SEL((m8)(sigma < lo), lo, sigma);
    d[k] = SEL((m8)(sigma > hi), hi, sigma);
  }
  /* w[k] is column k of W (the rotations act on it as on the rows of a) */
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      out[3 * i + j] = d[0] * w[0][i] * w[0][j] + d[1] * w[1][i] * w[1][j] + d[2] * w[2][i] * w[2][j];
  v8 m = SEL((m8)(d[0] > d[1]), d[0], d[1]);
  *largest = SEL((m8)(d[2] > m), d[2], m);
  return ok;
}

/* What phase 1 hands phase 2 for one block: the yielding lanes, the exponents -delta of
 * exp(-delta) and the plastic strain increments. */
typedef struct block_flow {
  v8 minus_delta[3];
  v8 dl;
  unsigned bits; /* bit l: lane l yields */
} block_flow;

/* Phase 1 of a block: quick test and radial return. */
static inline __attribute__((always_inline)) void return_map_block(const piola_plastic_state *s, int32_t block,
                                                                   const double *fhat_all, block_flow *out) {
  const int32_t base = block * L;
  const int32_t valid_count = s->tet_count - base < L ? s->tet_count - base : L;
  const plastic_params *p = &s->params;
  out->bits = 0;
  m8 valid;
  for (int l = 0; l < L; ++l) valid[l] = l < valid_count ? -1 : 0;
  v8 fh[3];
  load_fhat(fhat_all + 3 * (size_t)base, fh);
  /* quick test: every entry inside [exp(-gamma/sqrt3), exp(gamma/sqrt3)] cannot yield
   * (without hardening gamma is the same for all: the strain is not even read) */
  v8 gamma, lo, hi;
  if (p->hardening == 0) {
    gamma = piola__v8_splat(p->yield);
    lo = piola__v8_splat(s->quick_lo0), hi = piola__v8_splat(s->quick_hi0);
  } else {
    gamma = p->yield + p->hardening * piola__v8_load(s->alpha + base);
    v8 r = gamma * (1.0 / 1.7320508075688772);
    lo = piola__v8_exp(-r), hi = piola__v8_exp(r);
  }
  m8 outside = (fh[0] < lo) | (fh[0] > hi) | (fh[1] < lo) | (fh[1] > hi) | (fh[2] < lo) | (fh[2] > hi);
  /* NaN entries compare false both ways: they go to the full path like the scalar one */
  outside |= (fh[0] != fh[0]) | (fh[1] != fh[1]) | (fh[2] != fh[2]);
  if (!lane_bits(outside & valid)) return;

  /* radial return (return_mapping.h) */
  const v8 floor = piola__v8_splat(PIOLA_PLASTIC_FLAT_FLOOR);
  v8 e[3];
  for (int i = 0; i < 3; ++i) e[i] = piola__v8_log(SEL((m8)(fh[i] > floor), fh[i], floor));
  v8 mean = p->volume_preserving ? (e[0] + e[1] + e[2]) * (1.0 / 3.0) : piola__v8_splat(0.0);
  v8 d[3] = {e[0] - mean, e[1] - mean, e[2] - mean};
  v8 norm = v8_sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  m8 yielded = (m8)(norm > gamma) & valid;
  const unsigned ybits = lane_bits(yielded);
  if (!ybits) return;
  v8 dl = SEL(yielded, (norm - gamma) * (1.0 / (1.0 + p->hardening)), piola__v8_splat(0.0));
  v8 scale = SEL(yielded, v8_div(dl, SEL(yielded, norm, piola__v8_splat(1.0))), piola__v8_splat(0.0));

  for (int i = 0; i < 3; ++i) out->minus_delta[i] = -scale * d[i];
  out->dl = dl;
  out->bits = ybits;
}

/* Phase 2 of a block that has yielding lanes: new Fp^-1, bounds, effective Dm^-1. Returns
 * the number of yielded tets and adds the limited ones to *limited. */
static inline __attribute__((always_inline)) int32_t flow_block(piola_plastic_state *s, int32_t block,
                                                                double *const dm_inv[9], const double *const vk[9],
                                                                const block_flow *in, int32_t *limited) {
  const int32_t base = block * L;
  const plastic_params *p = &s->params;
  const unsigned ybits = in->bits;
  m8 yielded;
  for (int l = 0; l < L; ++l) yielded[l] = (ybits >> l & 1) ? -1 : 0;
  /* M = V exp(-delta) V^T, so Fp^-1 <- Fp^-1 M. With columns v0, v1, v2 of the rotation V
   * (v0 v0^T + v1 v1^T + v2 v2^T = I) and G = exp(-delta):
   *   M = G2 I + (G0 - G2) v0 v0^T + (G1 - G2) v1 v1^T,
   * so the third column of V is never read (a third less V traffic, fewer products), and
   * a lane with delta = 0 (G = 1) gets M = I exactly */
  v8 G[3];
  for (int i = 0; i < 3; ++i) G[i] = piola__v8_exp(in->minus_delta[i]);
  v8 c0 = G[0] - G[2], c1 = G[1] - G[2];
  v8 a0 = piola__v8_load(vk[0] + base), a1 = piola__v8_load(vk[3] + base), a2 = piola__v8_load(vk[6] + base);
  v8 b0 = piola__v8_load(vk[1] + base), b1 = piola__v8_load(vk[4] + base), b2 = piola__v8_load(vk[7] + base);
  v8 ca0 = c0 * a0, ca1 = c0 * a1, ca2 = c0 * a2, cb0 = c1 * b0, cb1 = c1 * b1, cb2 = c1 * b2;
  v8 m00 = G[2] + ca0 * a0 + cb0 * b0;
  v8 m11 = G[2] + ca1 * a1 + cb1 * b1;
  v8 m22 = G[2] + ca2 * a2 + cb2 * b2;
  v8 m01 = ca0 * a1 + cb0 * b1;
  v8 m02 = ca0 * a2 + cb0 * b2;
  v8 m12 = ca1 * a2 + cb1 * b2;
  v8 m[9] = {m00, m01, m02, m01, m11, m12, m02, m12, m22};

  /* Fp^-1 of the block's tets, AoS -> lanes */
  double *fp = s->fp_inv + 9 * (size_t)base;
  v8 a[9];
  load_matrices(fp, a); /* fp_inv is padded to whole blocks (identity) */
  v8 an[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      an[3 * i + j] = a[3 * i] * m[j] + a[3 * i + 1] * m[3 + j] + a[3 * i + 2] * m[6 + j];

  /* cheap bounds on the singular values of the new Fp^-1 from B = A A^T (see
   * singular_bounds in plastic_state.c, here compared squared) */
  v8 b00 = an[0] * an[0] + an[1] * an[1] + an[2] * an[2];
  v8 b11 = an[3] * an[3] + an[4] * an[4] + an[5] * an[5];
  v8 b22 = an[6] * an[6] + an[7] * an[7] + an[8] * an[8];
  v8 b01 = an[0] * an[3] + an[1] * an[4] + an[2] * an[5];
  v8 b02 = an[0] * an[6] + an[1] * an[7] + an[2] * an[8];
  v8 b12 = an[3] * an[6] + an[4] * an[7] + an[5] * an[8];
  v8 mb = (b00 + b11 + b22) * (1.0 / 3.0);
  v8 dev = v8_sqrt((b00 - mb) * (b00 - mb) + (b11 - mb) * (b11 - mb) + (b22 - mb) * (b22 - mb) +
                   2.0 * (b01 * b01 + b02 * b02 + b12 * b12));
  v8 bhi = mb + 0.816496580927726 * dev; /* sqrt(2/3) */
  v8 det = an[0] * (an[4] * an[8] - an[5] * an[7]) - an[1] * (an[3] * an[8] - an[5] * an[6]) +
           an[2] * (an[3] * an[7] - an[4] * an[6]);
  /* lambda_min >= max(blo1, det^2 / bhi^2) >= 1 / cap^2, without the division */
  v8 blo1 = mb - 0.816496580927726 * dev;
  const double cap = s->limit_cap, inv_cap2 = 1.0 / (cap * cap);
  m8 inside = (m8)(bhi <= cap * cap) & ((m8)(blo1 >= inv_cap2) | (m8)(det * det >= inv_cap2 * (bhi * bhi)));
  m8 exact = yielded & ~inside;
  v8 upper = v8_sqrt(bhi);
  const unsigned ebits = lane_bits(exact);
  /* tets past the limit: the vector exact limit (not with volume preservation, whose clamp
   * keeps the sum of the log-stretches by bisection: scalar) */
  m8 vlim = {0, 0, 0, 0, 0, 0, 0, 0};
  unsigned vbits = 0;
  if (ebits && !p->volume_preserving) {
    v8 alim[9], largest;
    vlim = limit_lanes(an, s->limit_cap, alim, &largest) & exact;
    vbits = lane_bits(vlim);
    for (int k = 0; k < 9; ++k) an[k] = SEL(vlim, alim[k], an[k]);
    upper = SEL(vlim, largest, upper);
  }

  /* the new effective Dm^-1 = Dm^-1,rest Fp^-1 M = (old effective Dm^-1) M into the body's
   * lanes (others keep theirs). From the old one rather than from the rest Dm^-1: the
   * body's lanes are read and written anyway (a store pulls the cache line in), so the rest
   * data is read for one block in PIOLA_PLASTIC_REFRESH only; the two products differ by
   * rounding (the tests bound it) */
  v8 e[9], r[9];
  for (int k = 0; k < 9; ++k) e[k] = piola__v8_load(dm_inv[k] + base);
  if (vbits) /* limited lanes: Dm^-1,rest times their new Fp^-1 */
    for (int k = 0; k < 9; ++k) r[k] = piola__v8_load(s->rest_lanes + (size_t)block * 9 * L + (size_t)k * L);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      v8 eff = e[3 * i] * m[j] + e[3 * i + 1] * m[3 + j] + e[3 * i + 2] * m[6 + j];
      if (vbits) eff = SEL(vlim, r[3 * i] * an[j] + r[3 * i + 1] * an[3 + j] + r[3 * i + 2] * an[6 + j], eff);
      store_lanes(dm_inv[3 * i + j] + base, eff, yielded, ybits);
    }
  piola__v8_store(s->alpha + base, piola__v8_load(s->alpha + base) + in->dl);
  v8 old_bound = piola__v8_load(s->stretch_bound + base);
  piola__v8_store(s->stretch_bound + base, SEL(yielded, upper, old_bound));

  /* lanes -> AoS (tets that did not yield keep their bits); the exact limit where the
   * bounds leave it */
  for (int k = 0; k < 9; ++k) an[k] = SEL(yielded, an[k], a[k]);
  store_matrices(fp, an);
  const int32_t count = __builtin_popcount(ybits);
  *limited += __builtin_popcount(ebits);
  for (unsigned sbits = ebits & ~vbits; sbits; sbits &= sbits - 1) {
    int l = __builtin_ctz(sbits);
    s->stretch_bound[base + l] = piola__plastic_exact_limit(fp + 9 * l, p);
    piola__plastic_commit_tet(s, base + l);
  }
  double bmax = 1.0;
  for (int l = 0; l < L; ++l) bmax = fmax(bmax, s->stretch_bound[base + l]); /* padding lanes hold 1 */
  s->block_bound[block] = bmax;
  return count;
}

/* Two phases over a chunk of blocks rather than one pass per block: each phase's loop body
 * is half as long, so the processor overlaps consecutive blocks (the work of one block is
 * a long chain of dependent operations: log, norm, exp, products). */
enum { CHUNK_BLOCKS = 16 };

PIOLA_WIDE_VECTORS int32_t PIOLA_ISA_NAME(piola__plastic_update_blocks)(piola_plastic_state *s, int32_t first,
                                                                      int32_t end, int32_t *limited,
                                                                      double *bound) {
  double *dm_inv[9];
  const double *vk[9];
  int32_t padded;
  piola__elastic_body_plastic_lanes(s->body, dm_inv, vk, &padded);
  (void)padded;
  const double *fhat = piola_elastic_body_fhat(s->body);
  block_flow flow[CHUNK_BLOCKS];
  int32_t yielded = 0;
  double bmax = 1.0;
  for (int32_t b0 = first; b0 < end; b0 += CHUNK_BLOCKS) {
    int32_t n = end - b0 < CHUNK_BLOCKS ? end - b0 : CHUNK_BLOCKS;
    for (int32_t i = 0; i < n; ++i) return_map_block(s, b0 + i, fhat, &flow[i]);
    for (int32_t i = 0; i < n; ++i)
      if (flow[i].bits) {
        yielded += flow_block(s, b0 + i, dm_inv, vk, &flow[i], limited);
        /* this update's share of blocks: effective Dm^-1 recomputed from the rest data, so
         * rounding cannot pile up over more than PIOLA_PLASTIC_REFRESH updates */
        if (((b0 + i) & (PIOLA_PLASTIC_REFRESH - 1)) == s->refresh_phase)
          for (int32_t t = (b0 + i) * L; t < (b0 + i + 1) * L && t < s->tet_count; ++t)
            piola__plastic_commit_tet(s, t);
      }
    for (int32_t i = 0; i < n; ++i) bmax = fmax(bmax, s->block_bound[b0 + i]);
  }
  *bound = bmax;
  return yielded;
}
