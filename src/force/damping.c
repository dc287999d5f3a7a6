/* Damping forces (paper section 6.2): the robust variant, made to conserve angular momentum.
 *
 * The velocity gradient Fdot = Ds_dot Dm^-1 is rotated into the frame of the last update's
 * diagonalization, Fdot_hat = U^T Fdot V; the damping stress there is the rotated-linear
 * analogue Phat = beta (Fdot_hat + Fdot_hat^T) + alpha tr(Fdot_hat) I, rotated back,
 * P = U Phat V^T, and turned into nodal forces exactly as the elastic stress is. It never
 * divides by Fhat, so it does not vanish (or blow up) on flat, collapsed or inverted tets,
 * which is what keeps those from oscillating.
 *
 * Angular momentum. As the paper notes, this stress has a torque unless Phat Fhat is
 * symmetric, which fails for deformed tets; recovering from a collapse (all tets flat) that
 * torque spins the whole body up, and nothing damps a rigid spin afterwards. So each tet's
 * damping map D_t (12 velocities -> 12 forces) is sandwiched between the projection that
 * removes the tet's infinitesimal rigid rotations about its centroid at the current
 * positions: D'_t = P_t D_t P_t, P_t = I - R (R^T R + eps I)^-1 R^T, R the 12x3 matrix of
 * rotation generators (e_k x r_a), r_a = x_a - centroid. Then:
 *   - the net torque of each tet's forces is zero (R^T P f = 0), and their sum is zero;
 *   - rigid rotations are not damped at any deformation, not only at rest;
 *   - compression and shear rates of flat and inverted tets still are (P only removes the
 *     3 rotation directions of the 12);
 *   - D'_t is symmetric negative semi-definite because D_t is and P_t is symmetric, and
 *     linear in v: with A = Fdot_hat(P v), B = Fdot_hat(P w),
 *     w . f(v) = -sum V0 [beta/2 (A + A^T):(B + B^T) + alpha tr A tr B].
 *     So the implicit step's M - dt/2 D is symmetric positive definite and CG applies.
 * eps = 1e-12 tr(R^T R) regularizes tets collapsed to a line or a point, whose R^T R is
 * singular (for a point R = 0 and P = I: all corners coincide, so there is no torque).
 *
 * Speed. The implicit step applies this operator in every conjugate-gradient iteration, about
 * 20 times per elastic update, so the work is split. Once per update (lazily, on the first
 * damping call after it) each tet's record is prepared: the rotation Q = U V^T (the stress
 * needs only it: U Phat(U^T Fdot V) V^T = beta (Fdot + Q Fdot^T Q) + alpha tr(Q^T Fdot) Q),
 * the corner offsets from the centroid r_1..r_3 (r_0 = -(r_1 + r_2 + r_3)) and sqrt(V0) Dm^-1
 * (V0 split evenly between the two sides keeps the operator symmetric in rounding too). The
 * apply is bound by memory traffic, not arithmetic, so the record is small (144 bytes, see
 * the layout below) and (R^T R + eps I)^-1 is recomputed from r in the apply rather than
 * stored. The apply runs branch-free straight-line code vectorized across blocks of
 * PIOLA_TET_BLOCK tets, then adds each block's forces straight into per-vertex sums: one of
 * PIOLA_DAMPING_CHUNKS partial-sum arrays per fixed range of tets, added in chunk order at
 * the end, so the result is the same for any thread count without the elastic loop's
 * per-tet buffer (writing and re-reading it was half of the traffic). Both projections are
 * written in terms of the edge vectors: R^T y = sum_j r_j x (y_j - y_0), and for forces g
 * with g_0 = -sum g_j, R^T g = sum_j (r_j - r_0) x g_j. A scalar reference of the original
 * per-tet formulation (piola__elastic_body_damping_reference) is kept for the tests. */
#include <math.h>
#include <stdlib.h>

#include "force/elastic_body_internal.h"
#include "force/svd_kernel.h"

#define B PIOLA_TET_BLOCK

/* A block's record: 9 rows of doubles (r_1, r_2, r_3: x, y, z each, centroid-relative
 * corners), then 18 rows of damping_real (Q = U V^T and sqrt(V0) Dm^-1, row-major); each row
 * holds PIOLA_TET_BLOCK lanes. The offsets must stay exact (the projections have to remove
 * the rotations about the true corners to rounding), so they are doubles; Q and Dm^-1 only
 * set the size of the viscous stress, where float's 6e-8 relative rounding is far below
 * anything a viscosity is known to, and halving them cuts the bytes the apply streams per
 * tet from 216 to 144 (the apply is bound by memory traffic, not arithmetic). The operator
 * stays exactly symmetric: both sides use the same stored numbers. Set PIOLA_DAMPING_DOUBLE
 * to 1 to store them as doubles. */
#ifndef PIOLA_DAMPING_DOUBLE
#define PIOLA_DAMPING_DOUBLE 0
#endif
#if PIOLA_DAMPING_DOUBLE
typedef double damping_real;
#else
typedef float damping_real;
#endif
/* PIOLA_DAMPING_GATHER_OFFSETS 1: recompute the offsets in the apply from the update's
 * positions (gathered like the velocities) instead of storing them, 72 fewer bytes streamed
 * per tet (88 with the indices instead of 160). Measured on the torus, one thread: 2.42
 * against 2.30 ms per apply (the 12 extra gathers cost more than the bytes saved here), the
 * preparation 0.6 ms cheaper; so off. Both compute the offsets by the same formula. */
#ifndef PIOLA_DAMPING_GATHER_OFFSETS
#define PIOLA_DAMPING_GATHER_OFFSETS 0
#endif
enum { ROWS_R = PIOLA_DAMPING_GATHER_OFFSETS ? 0 : 9, ROWS_Q = 0, ROWS_DM = 9, ROWS_REAL = 18 };
#define BLOCK_BYTES (ROWS_R * B * sizeof(double) + ROWS_REAL * B * sizeof(damping_real))
_Static_assert(BLOCK_BYTES <= PIOLA_DAMPING_FIELDS * B * sizeof(double), "damping record size");

static inline double *block_offsets(const piola_elastic_body *body, int32_t block) {
  return (double *)((char *)body->damping_data + (size_t)block * BLOCK_BYTES);
}
static inline damping_real *block_reals(const piola_elastic_body *body, int32_t block) {
  return (damping_real *)((char *)body->damping_data + (size_t)block * BLOCK_BYTES + ROWS_R * B * sizeof(double));
}

/* Prepares the records of one block from the last update's U, V and positions. */
PIOLA_WIDE_VECTORS static void prepare_block(piola_elastic_body *body, int32_t block) {
  const int32_t base = block * B;
  const double *x = body->positions;
  const int32_t *i0 = body->tet_vertices[0] + base, *i1 = body->tet_vertices[1] + base;
  const int32_t *i2 = body->tet_vertices[2] + base, *i3 = body->tet_vertices[3] + base;
  double *const *u = body->u, *const *v = body->v, *const *dmi = body->dm_inv;
  const double *volume = body->rest_volume;
  double *ro = block_offsets(body, block);
  damping_real *rq = block_reals(body, block);
#pragma omp simd
  for (int l = 0; l < B; ++l) {
    const int32_t t = base + l;
    const int32_t ia = 3 * i0[l], ib = 3 * i1[l], ic = 3 * i2[l], id = 3 * i3[l];
    double r[4][3]; /* r[0] = -(r[1] + r[2] + r[3]) is recomputed by the apply */
    PIOLA_UNROLL
    for (int k = 0; k < 3; ++k) {
      double c = 0.25 * (x[ia + k] + x[ib + k] + x[ic + k] + x[id + k]);
      r[1][k] = x[ib + k] - c;
      r[2][k] = x[ic + k] - c;
      r[3][k] = x[id + k] - c;
    }
    if (!PIOLA_DAMPING_GATHER_OFFSETS)
      PIOLA_UNROLL
      for (int j = 0; j < 3; ++j)
        PIOLA_UNROLL
        for (int k = 0; k < 3; ++k) ro[(3 * j + k) * B + l] = r[j + 1][k];
    PIOLA_UNROLL
    for (int i = 0; i < 3; ++i)
      PIOLA_UNROLL
      for (int j = 0; j < 3; ++j)
        rq[(ROWS_Q + 3 * i + j) * B + l] = (damping_real)(u[3 * i][t] * v[3 * j][t] + u[3 * i + 1][t] * v[3 * j + 1][t] +
                                                          u[3 * i + 2][t] * v[3 * j + 2][t]);
    double sv = sqrt(volume[t]);
    PIOLA_UNROLL
    for (int k = 0; k < 9; ++k) rq[(ROWS_DM + k) * B + l] = (damping_real)(sv * dmi[k][t]);
  }
}

/* Adds the damping forces of one block of tets to forces, tet by tet in order. */
PIOLA_WIDE_VECTORS static void apply_block(const piola_elastic_body *body, const double *vel, double beta,
                                           double alpha, int32_t block, double *forces) {
  const int32_t base = block * B;
  const int32_t *i0 = body->tet_vertices[0] + base, *i1 = body->tet_vertices[1] + base;
  const int32_t *i2 = body->tet_vertices[2] + base, *i3 = body->tet_vertices[3] + base;
#if PIOLA_DAMPING_GATHER_OFFSETS
  /* the corner offsets from the update's positions, as prepare_block would compute them */
  double ro[9 * B];
  const double *x = body->positions;
#pragma omp simd
  for (int l = 0; l < B; ++l) {
    const int32_t ia = 3 * i0[l], ib = 3 * i1[l], ic = 3 * i2[l], id = 3 * i3[l];
    PIOLA_UNROLL
    for (int k = 0; k < 3; ++k) {
      double c = 0.25 * (x[ia + k] + x[ib + k] + x[ic + k] + x[id + k]);
      ro[k * B + l] = x[ib + k] - c;
      ro[(3 + k) * B + l] = x[ic + k] - c;
      ro[(6 + k) * B + l] = x[id + k] - c;
    }
  }
#else
  const double *ro = block_offsets(body, block);
#endif
  const damping_real *rq = block_reals(body, block);
  double tf[12 * B];
  /* the gathers in a loop of their own: GCC vectorizes loops with int32-indexed gathers at
   * 256 bits, the arithmetic below runs at 512 */
  double dv[9][B];
#pragma omp simd
  for (int l = 0; l < B; ++l) {
    /* index arithmetic, not pointers or loops, so GCC emits vector gathers */
    const int32_t ia = 3 * i0[l], ib = 3 * i1[l], ic = 3 * i2[l], id = 3 * i3[l];
    dv[0][l] = vel[ib] - vel[ia], dv[1][l] = vel[ib + 1] - vel[ia + 1], dv[2][l] = vel[ib + 2] - vel[ia + 2];
    dv[3][l] = vel[ic] - vel[ia], dv[4][l] = vel[ic + 1] - vel[ia + 1], dv[5][l] = vel[ic + 2] - vel[ia + 2];
    dv[6][l] = vel[id] - vel[ia], dv[7][l] = vel[id + 1] - vel[ia + 1], dv[8][l] = vel[id + 2] - vel[ia + 2];
  }
  /* widened in a loop of their own too, so the one below is all doubles (512 bits) */
  double qd[ROWS_REAL][B];
  PIOLA_UNROLL
  for (int k = 0; k < ROWS_REAL; ++k)
#pragma omp simd
    for (int l = 0; l < B; ++l) qd[k][l] = rq[k * B + l];
#pragma omp simd
  for (int l = 0; l < B; ++l) {
    /* edge velocities d[j] = v_{j+1} - v_0 and corner offsets */
    double d[3][3], r[4][3], e[3][3];
    PIOLA_UNROLL
    for (int k = 0; k < 9; ++k) d[k / 3][k % 3] = dv[k][l];
    PIOLA_UNROLL
    for (int j = 0; j < 3; ++j)
      PIOLA_UNROLL
      for (int k = 0; k < 3; ++k) r[j + 1][k] = ro[(3 * j + k) * B + l];
    PIOLA_UNROLL
    for (int k = 0; k < 3; ++k) r[0][k] = -(r[1][k] + r[2][k] + r[3][k]);
    PIOLA_UNROLL
    for (int j = 0; j < 3; ++j)
      PIOLA_UNROLL
      for (int k = 0; k < 3; ++k) e[j][k] = r[j + 1][k] - r[0][k]; /* edge x_{j+1} - x_0 */
    /* Minv = (R^T R + eps I)^-1, recomputed here from r: ~70 flops cost less than streaming
     * 6 more doubles per tet. R^T R = sum_a |r_a|^2 I - r_a r_a^T */
    double mxx = 0, mxy = 0, mxz = 0, myy = 0, myz = 0, mzz = 0;
    PIOLA_UNROLL
    for (int c = 0; c < 4; ++c) {
      double rx = r[c][0], ry = r[c][1], rz = r[c][2];
      mxx += ry * ry + rz * rz;
      myy += rx * rx + rz * rz;
      mzz += rx * rx + ry * ry;
      mxy -= rx * ry;
      mxz -= rx * rz;
      myz -= ry * rz;
    }
    {
      double eps = 1e-12 * (mxx + myy + mzz);
      mxx += eps;
      myy += eps;
      mzz += eps;
      double cxx = myy * mzz - myz * myz, cxy = mxz * myz - mxy * mzz, cxz = mxy * myz - myy * mxz;
      double cyy = mxx * mzz - mxz * mxz, cyz = mxy * mxz - mxx * myz, czz = mxx * myy - mxy * mxy;
      double det = mxx * cxx + mxy * cxy + mxz * cxz;
      /* all corners at one point (or a padding tet): no rotation to remove */
      double inv = eps > 0 ? 1.0 / (eps > 0 ? det : 1.0) : 0.0;
      mxx = cxx * inv, mxy = cxy * inv, mxz = cxz * inv;
      myy = cyy * inv, myz = cyz * inv, mzz = czz * inv;
    }

    /* remove the rigid rotation: tau = R^T v = sum_j r_j x d_j, omega = Minv tau,
     * d_j -= omega x e_j */
    double tx = 0, ty = 0, tz = 0;
    PIOLA_UNROLL
    for (int j = 0; j < 3; ++j) {
      tx += r[j + 1][1] * d[j][2] - r[j + 1][2] * d[j][1];
      ty += r[j + 1][2] * d[j][0] - r[j + 1][0] * d[j][2];
      tz += r[j + 1][0] * d[j][1] - r[j + 1][1] * d[j][0];
    }
    double wx = mxx * tx + mxy * ty + mxz * tz;
    double wy = mxy * tx + myy * ty + myz * tz;
    double wz = mxz * tx + myz * ty + mzz * tz;
    PIOLA_UNROLL
    for (int j = 0; j < 3; ++j) {
      d[j][0] -= wy * e[j][2] - wz * e[j][1];
      d[j][1] -= wz * e[j][0] - wx * e[j][2];
      d[j][2] -= wx * e[j][1] - wy * e[j][0];
    }

    /* Fdot (times sqrt V0) = Ds_dot Dm^-1: fd[i][k] = sum_j d[j][i] dm[j][k] */
    double dm[3][3], q[3][3], fd[3][3];
    PIOLA_UNROLL
    for (int k = 0; k < 9; ++k) {
      dm[k / 3][k % 3] = qd[ROWS_DM + k][l];
      q[k / 3][k % 3] = qd[ROWS_Q + k][l];
    }
    PIOLA_UNROLL
    for (int i = 0; i < 3; ++i)
      PIOLA_UNROLL
      for (int k = 0; k < 3; ++k) fd[i][k] = d[0][i] * dm[0][k] + d[1][i] * dm[1][k] + d[2][i] * dm[2][k];
    /* A = Q^T Fdot; S = beta (A + A^T) + alpha tr(A) I; P = Q S */
    double a[3][3];
    PIOLA_UNROLL
    for (int i = 0; i < 3; ++i)
      PIOLA_UNROLL
      for (int k = 0; k < 3; ++k) a[i][k] = q[0][i] * fd[0][k] + q[1][i] * fd[1][k] + q[2][i] * fd[2][k];
    double tr = alpha * (a[0][0] + a[1][1] + a[2][2]);
    double s00 = 2 * beta * a[0][0] + tr, s11 = 2 * beta * a[1][1] + tr, s22 = 2 * beta * a[2][2] + tr;
    double s01 = beta * (a[0][1] + a[1][0]), s02 = beta * (a[0][2] + a[2][0]), s12 = beta * (a[1][2] + a[2][1]);
    double p[3][3];
    PIOLA_UNROLL
    for (int i = 0; i < 3; ++i) {
      p[i][0] = q[i][0] * s00 + q[i][1] * s01 + q[i][2] * s02;
      p[i][1] = q[i][0] * s01 + q[i][1] * s11 + q[i][2] * s12;
      p[i][2] = q[i][0] * s02 + q[i][1] * s12 + q[i][2] * s22;
    }
    /* forces on corners j + 1: g_j = -P (sqrt V0 Dm^-T) column j; corner 0 balances */
    double g[4][3];
    PIOLA_UNROLL
    for (int j = 0; j < 3; ++j)
      PIOLA_UNROLL
      for (int i = 0; i < 3; ++i) g[j + 1][i] = -(p[i][0] * dm[j][0] + p[i][1] * dm[j][1] + p[i][2] * dm[j][2]);
    PIOLA_UNROLL
    for (int i = 0; i < 3; ++i) g[0][i] = -(g[1][i] + g[2][i] + g[3][i]);

    /* remove the torque: tau = R^T g = sum_j e_j x g_j, omega = Minv tau, g_a -= omega x r_a */
    tx = ty = tz = 0;
    PIOLA_UNROLL
    for (int j = 0; j < 3; ++j) {
      tx += e[j][1] * g[j + 1][2] - e[j][2] * g[j + 1][1];
      ty += e[j][2] * g[j + 1][0] - e[j][0] * g[j + 1][2];
      tz += e[j][0] * g[j + 1][1] - e[j][1] * g[j + 1][0];
    }
    wx = mxx * tx + mxy * ty + mxz * tz;
    wy = mxy * tx + myy * ty + myz * tz;
    wz = mxz * tx + myz * ty + mzz * tz;
    PIOLA_UNROLL
    for (int c = 0; c < 4; ++c) {
      tf[(3 * c + 0) * B + l] = g[c][0] - (wy * r[c][2] - wz * r[c][1]);
      tf[(3 * c + 1) * B + l] = g[c][1] - (wz * r[c][0] - wx * r[c][2]);
      tf[(3 * c + 2) * B + l] = g[c][2] - (wx * r[c][1] - wy * r[c][0]);
    }
  }
  /* scalar scatter in tet order (lanes may share vertices); padding tets add nothing */
  const int32_t lanes = body->tet_count - base < B ? body->tet_count - base : B;
  for (int l = 0; l < lanes; ++l) {
    const int32_t corner[4] = {i0[l], i1[l], i2[l], i3[l]};
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 3; ++k) forces[3 * corner[c] + k] += tf[(3 * c + k) * B + l];
  }
}

void piola__elastic_body_damping_prepare(piola_elastic_body *body) {
  if (body->damping_ready) return;
  const int32_t blocks = body->padded_tet_count / B;
#pragma omp parallel for schedule(static) num_threads(piola__thread_count()) \
    if (blocks >= PIOLA_PARALLEL_MIN_BLOCKS)
  for (int32_t b = 0; b < blocks; ++b) prepare_block(body, b);
  body->damping_ready = 1;
}

/* forces = D v, or with mass given, out = M v - h D v (the implicit step's operator: its
 * last pass, which sums the chunks, forms it instead of a separate pass over the result). */
static void damping_pass(const piola_elastic_body *body, const double *v, double shear_viscosity,
                         double bulk_viscosity, const double *mass, double h, double *forces) {
  const int32_t blocks = body->padded_tet_count / B;
  const int64_t n = 3 * (int64_t)body->vertex_count;
  /* the records and partial sums are prepared in place, like the lazy energy: concurrent
   * calls on one body are not allowed */
  piola__elastic_body_damping_prepare((piola_elastic_body *)body);
  if (blocks < PIOLA_PARALLEL_MIN_BLOCKS || !body->damping_chunk_forces) {
    for (int64_t i = 0; i < n; ++i) forces[i] = 0.0;
    for (int32_t b = 0; b < blocks; ++b) apply_block(body, v, shear_viscosity, bulk_viscosity, b, forces);
    if (mass)
      for (int64_t i = 0; i < n; ++i) forces[i] = mass[i / 3] * v[i] - h * forces[i];
    return;
  }
  /* Determinism without a per-tet buffer: PIOLA_DAMPING_CHUNKS fixed ranges of blocks, each
   * summed in tet order into its own array, and the arrays added in chunk order. Which
   * thread runs a chunk changes nothing. */
  double *partial = body->damping_chunk_forces;
#pragma omp parallel num_threads(piola__thread_count())
  {
#pragma omp for schedule(static)
    for (int k = 0; k < PIOLA_DAMPING_CHUNKS; ++k) {
      double *fk = partial + (size_t)k * (size_t)n;
      for (int64_t i = 0; i < n; ++i) fk[i] = 0.0;
      int32_t b0 = (int32_t)((int64_t)blocks * k / PIOLA_DAMPING_CHUNKS);
      int32_t b1 = (int32_t)((int64_t)blocks * (k + 1) / PIOLA_DAMPING_CHUNKS);
      for (int32_t b = b0; b < b1; ++b) apply_block(body, v, shear_viscosity, bulk_viscosity, b, fk);
    }
#pragma omp for schedule(static)
    for (int64_t i = 0; i < n; ++i) {
      double sum = partial[i];
      for (int k = 1; k < PIOLA_DAMPING_CHUNKS; ++k) sum += partial[(size_t)k * (size_t)n + i];
      forces[i] = mass ? mass[i / 3] * v[i] - h * sum : sum;
    }
  }
}

void piola_elastic_body_damping_forces(const piola_elastic_body *body, const double *v,
                                       double shear_viscosity, double bulk_viscosity,
                                       double *forces) {
  if (!body || !v || !forces) return;
  damping_pass(body, v, shear_viscosity, bulk_viscosity, NULL, 0.0, forces);
}

void piola__elastic_body_damping_operator(const piola_elastic_body *body, const double *v,
                                          double shear_viscosity, double bulk_viscosity,
                                          const double *mass, double h, double *out) {
  damping_pass(body, v, shear_viscosity, bulk_viscosity, mass, h, out);
}

static int vertex_moves(const double *v, int32_t i) {
  return v[3 * i] != 0 || v[3 * i + 1] != 0 || v[3 * i + 2] != 0;
}

void piola__elastic_body_damping_forces_add_sparse(const piola_elastic_body *body, const double *v,
                                                   double shear_viscosity, double bulk_viscosity,
                                                   double *forces) {
  piola__elastic_body_damping_prepare((piola_elastic_body *)body);
  const int32_t blocks = body->padded_tet_count / B;
  /* a byte per vertex (in cache, unlike v) for the scan over the tets */
  uint8_t *moves = malloc((size_t)body->vertex_count + 1);
  if (moves)
    for (int32_t i = 0; i < body->vertex_count; ++i) moves[i] = (uint8_t)vertex_moves(v, i);
  for (int32_t b = 0; b < blocks; ++b) {
    const int32_t base = b * B;
    const int32_t lanes = body->tet_count - base < B ? body->tet_count - base : B;
    int touched = 0;
    for (int l = 0; l < lanes; ++l)
      for (int c = 0; c < 4; ++c) {
        int32_t i = body->tet_vertices[c][base + l];
        touched |= moves ? moves[i] : vertex_moves(v, i);
      }
    /* a tet whose corners are all at rest gets exactly zero force: skipping it is exact */
    if (touched) apply_block(body, v, shear_viscosity, bulk_viscosity, b, forces);
  }
  free(moves);
}

/* Removes from the 4 corner vectors y (12) their rigid-rotation part about the centroid
 * of positions p (12). */
static void reference_remove_rotation(const double p[12], double y[12]) {
  double c[3] = {0, 0, 0};
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) c[i] += 0.25 * p[3 * a + i];
  double r[4][3], m[3][3] = {{0}}, tau[3] = {0, 0, 0};
  for (int a = 0; a < 4; ++a) {
    for (int i = 0; i < 3; ++i) r[a][i] = p[3 * a + i] - c[i];
    double rr = r[a][0] * r[a][0] + r[a][1] * r[a][1] + r[a][2] * r[a][2];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) m[i][j] += (i == j ? rr : 0.0) - r[a][i] * r[a][j];
    const double *ya = y + 3 * a;
    tau[0] += r[a][1] * ya[2] - r[a][2] * ya[1];
    tau[1] += r[a][2] * ya[0] - r[a][0] * ya[2];
    tau[2] += r[a][0] * ya[1] - r[a][1] * ya[0];
  }
  double eps = 1e-12 * (m[0][0] + m[1][1] + m[2][2]);
  if (!(eps > 0)) return; /* all corners at one point: no rotation to remove */
  for (int i = 0; i < 3; ++i) m[i][i] += eps;
  double cof[3][3] = {
      {m[1][1] * m[2][2] - m[1][2] * m[2][1], m[1][2] * m[2][0] - m[1][0] * m[2][2], m[1][0] * m[2][1] - m[1][1] * m[2][0]},
      {m[0][2] * m[2][1] - m[0][1] * m[2][2], m[0][0] * m[2][2] - m[0][2] * m[2][0], m[0][1] * m[2][0] - m[0][0] * m[2][1]},
      {m[0][1] * m[1][2] - m[0][2] * m[1][1], m[0][2] * m[1][0] - m[0][0] * m[1][2], m[0][0] * m[1][1] - m[0][1] * m[1][0]}};
  double det = m[0][0] * cof[0][0] + m[0][1] * cof[0][1] + m[0][2] * cof[0][2];
  /* omega = (R^T R + eps)^-1 R^T y; m is symmetric so its inverse is cof / det */
  double omega[3];
  for (int i = 0; i < 3; ++i) omega[i] = (cof[i][0] * tau[0] + cof[i][1] * tau[1] + cof[i][2] * tau[2]) / det;
  for (int a = 0; a < 4; ++a) {
    y[3 * a] -= omega[1] * r[a][2] - omega[2] * r[a][1];
    y[3 * a + 1] -= omega[2] * r[a][0] - omega[0] * r[a][2];
    y[3 * a + 2] -= omega[0] * r[a][1] - omega[1] * r[a][0];
  }
}

/* The damping forces of tet t at corner velocities vt (12, already projected). */
static void reference_tet_damping(const piola_elastic_body *body, int32_t t, const double vt[12], double beta,
                        double alpha, double out[12]) {
  double *const *dmi = body->dm_inv;
  double d[3][3], fd[3][3], fv[3][3], a[3][3], ph[3][3], p[3][3], u[3][3], v[3][3], dm[3][3];
  for (int k = 0; k < 9; ++k) {
    u[k / 3][k % 3] = body->u[k][t];
    v[k / 3][k % 3] = body->v[k][t];
    dm[k / 3][k % 3] = dmi[k][t];
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) d[i][j] = vt[3 * (j + 1) + i] - vt[i];
  /* Fdot = Ds_dot Dm^-1 */
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) fd[i][j] = d[i][0] * dm[0][j] + d[i][1] * dm[1][j] + d[i][2] * dm[2][j];
  /* Fdot_hat = U^T Fdot V */
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) fv[i][j] = fd[i][0] * v[0][j] + fd[i][1] * v[1][j] + fd[i][2] * v[2][j];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) a[i][j] = u[0][i] * fv[0][j] + u[1][i] * fv[1][j] + u[2][i] * fv[2][j];
  double tr = alpha * (a[0][0] + a[1][1] + a[2][2]);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) ph[i][j] = beta * (a[i][j] + a[j][i]) + (i == j ? tr : 0.0);
  /* P = U Phat V^T */
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) fv[i][j] = u[i][0] * ph[0][j] + u[i][1] * ph[1][j] + u[i][2] * ph[2][j];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) p[i][j] = fv[i][0] * v[j][0] + fv[i][1] * v[j][1] + fv[i][2] * v[j][2];
  /* G = -V0 P Dm^-T: column j is the force on corner j + 1 */
  double w = -body->rest_volume[t];
  for (int i = 0; i < 3; ++i) out[i] = 0.0;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      double g = w * (p[i][0] * dm[j][0] + p[i][1] * dm[j][1] + p[i][2] * dm[j][2]);
      out[3 * (j + 1) + i] = g;
      out[i] -= g;
    }
}

void piola__elastic_body_damping_reference(const piola_elastic_body *body, const double *v,
                                           double shear_viscosity, double bulk_viscosity,
                                           double *forces) {
  for (int32_t i = 0; i < 3 * body->vertex_count; ++i) forces[i] = 0.0;
  for (int32_t t = 0; t < body->tet_count; ++t) {
    double pt[12], vt[12], out[12];
    for (int c = 0; c < 4; ++c) {
      int32_t i = body->tet_vertices[c][t];
      for (int k = 0; k < 3; ++k) {
        pt[3 * c + k] = body->positions[3 * i + k];
        vt[3 * c + k] = v[3 * i + k];
      }
    }
    reference_remove_rotation(pt, vt);
    reference_tet_damping(body, t, vt, shear_viscosity, bulk_viscosity, out);
    reference_remove_rotation(pt, out);
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 3; ++k) forces[3 * body->tet_vertices[c][t] + k] += out[3 * c + k];
  }
}
