/* Assembly of the damping matrix (damping_matrix.h) from the body's last update.
 *
 * Per tet, with Q = U V^T the rotation of the update's diagonalization, m_j the rows of
 * sqrt(V0) Dm^-1 and d_j = v_{j+1} - v_0 the edge velocities, the damping stress of damping.c
 * comes from A = Q^T Fdot = sum_j (Q^T d_j) m_j^T, through its symmetric part and trace:
 *   v . D_t v = -[2 beta |sym A|^2 + alpha (tr A)^2]   (V0 is inside m).
 * So D_t = -S^T W S with S the 6 x 12 map from corner velocities to the components of sym A
 * (off-diagonal ones times sqrt 2, so that |sym A|^2 is their plain sum of squares) and
 * W = 2 beta I + alpha on the three diagonal components' sum. The rigid-rotation projection
 * P of damping.c becomes S <- S P, column by column: corner a's 6 x 3 block loses
 * (Y_s x r_a), Y_s = (R^T R + eps I)^-1 (sum_j e_j x S_s,j+1). The 6 off-diagonal corner
 * blocks D_ab = -S_a^T W S_b then go to the tet's 6 edges, transposed where the edge's
 * stored orientation is the other way round. The diagonal blocks are never formed: rows of D
 * sum to zero, and the product works in edge differences.
 *
 * Cost: about 1100 flops per tet, vectorized across a SIMD block of tets, then 54 scalar
 * additions into the edge blocks. Fixed tet ranges run in parallel, edges they share
 * through private slots (damping_matrix.h), so each block is summed in a fixed order for
 * any thread count.
 *
 * A kernel, compiled once per instruction set (common/isa.h). */
#include <math.h>

#include "force/damping_matrix.h"
#include "force/elastic_body_internal.h"
#include "force/svd_kernel.h"

#define B PIOLA_TET_BLOCK
#define PREFETCH_BLOCKS 4

/* Corner pairs, as in damping_pattern.c. */
static const int PAIR_A[6] = {0, 0, 0, 1, 1, 2}, PAIR_B[6] = {1, 2, 3, 2, 3, 3};

/* The 6 corner-pair blocks D_ab of each tet of a SIMD block: out[(9 p + 3 c + d) B + l] is
 * entry (c, d) of pair p of lane l. */
PIOLA_WIDE_VECTORS static void tet_blocks(const piola_elastic_body *body, int32_t block,
                                          double beta, double alpha, double *out) {
  const int32_t base = block * B;
  const int32_t *i0 = body->tet_vertices[0] + base, *i1 = body->tet_vertices[1] + base;
  const int32_t *i2 = body->tet_vertices[2] + base, *i3 = body->tet_vertices[3] + base;
  const double *x = body->positions, *volume = body->rest_volume + base;
  /* the tet state comes in 32 streams (U, V, Dm^-1 entry by entry, V0, the corners), more
   * than the hardware prefetcher follows: ask for a later block's lines now (~3% of the
   * assembly, in interleaved runs) */
  const int32_t ahead = base + PREFETCH_BLOCKS * B;
  if (ahead < body->padded_tet_count) {
    for (int k = 0; k < 9; ++k) {
      __builtin_prefetch(body->u[k] + ahead);
      __builtin_prefetch(body->v[k] + ahead);
      __builtin_prefetch(body->dm_inv[k] + ahead);
    }
    __builtin_prefetch(body->rest_volume + ahead);
    for (int c = 0; c < 4; ++c) __builtin_prefetch(body->tet_vertices[c] + ahead);
  }
  double q9[9][B], m9[9][B];
  /* Q = U V^T and sqrt(V0) Dm^-1, in loops of their own so the one below stays in registers
   * as far as it can */
#pragma omp simd
  for (int l = 0; l < B; ++l) {
    const int32_t t = base + l;
    PIOLA_UNROLL
    for (int i = 0; i < 3; ++i)
      PIOLA_UNROLL
      for (int j = 0; j < 3; ++j)
        q9[3 * i + j][l] = body->u[3 * i][t] * body->v[3 * j][t] +
                           body->u[3 * i + 1][t] * body->v[3 * j + 1][t] +
                           body->u[3 * i + 2][t] * body->v[3 * j + 2][t];
    double sv = sqrt(volume[l]);
    PIOLA_UNROLL
    for (int k = 0; k < 9; ++k) m9[k][l] = sv * body->dm_inv[k][t];
  }
  double r9[9][B];
#pragma omp simd
  for (int l = 0; l < B; ++l) {
    const int32_t ia = 3 * i0[l], ib = 3 * i1[l], ic = 3 * i2[l], id = 3 * i3[l];
    PIOLA_UNROLL
    for (int k = 0; k < 3; ++k) {
      double c = 0.25 * (x[ia + k] + x[ib + k] + x[ic + k] + x[id + k]);
      r9[k][l] = x[ib + k] - c;
      r9[3 + k][l] = x[ic + k] - c;
      r9[6 + k][l] = x[id + k] - c;
    }
  }
  const double half_root2 = 0.70710678118654752440;
#pragma omp simd
  for (int l = 0; l < B; ++l) {
    double r[4][3], e[3][3], s[6][4][3];
    PIOLA_UNROLL
    for (int j = 0; j < 3; ++j)
      PIOLA_UNROLL
      for (int k = 0; k < 3; ++k) r[j + 1][k] = r9[3 * j + k][l];
    PIOLA_UNROLL
    for (int k = 0; k < 3; ++k) r[0][k] = -(r[1][k] + r[2][k] + r[3][k]);
    PIOLA_UNROLL
    for (int j = 0; j < 3; ++j)
      PIOLA_UNROLL
      for (int k = 0; k < 3; ++k) e[j][k] = r[j + 1][k] - r[0][k];

    /* Minv = (R^T R + eps I)^-1, R^T R = sum_a |r_a|^2 I - r_a r_a^T (as in damping.c) */
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

    /* S before the projection: corner j + 1, direction c gives A = q_c m_j^T (q_c row c of Q) */
    PIOLA_UNROLL
    for (int j = 0; j < 3; ++j)
      PIOLA_UNROLL
      for (int c = 0; c < 3; ++c) {
        double g0 = q9[3 * c][l], g1 = q9[3 * c + 1][l], g2 = q9[3 * c + 2][l];
        double m0 = m9[3 * j][l], m1 = m9[3 * j + 1][l], m2 = m9[3 * j + 2][l];
        s[0][j + 1][c] = g0 * m0;
        s[1][j + 1][c] = g1 * m1;
        s[2][j + 1][c] = g2 * m2;
        s[3][j + 1][c] = half_root2 * (g0 * m1 + g1 * m0);
        s[4][j + 1][c] = half_root2 * (g0 * m2 + g2 * m0);
        s[5][j + 1][c] = half_root2 * (g1 * m2 + g2 * m1);
      }
    /* S <- S P: each row loses its rigid-rotation part; corner 0 balances the other three */
    PIOLA_UNROLL
    for (int k = 0; k < 6; ++k) {
      double tx = 0, ty = 0, tz = 0;
      PIOLA_UNROLL
      for (int j = 0; j < 3; ++j) {
        tx += e[j][1] * s[k][j + 1][2] - e[j][2] * s[k][j + 1][1];
        ty += e[j][2] * s[k][j + 1][0] - e[j][0] * s[k][j + 1][2];
        tz += e[j][0] * s[k][j + 1][1] - e[j][1] * s[k][j + 1][0];
      }
      double wx = mxx * tx + mxy * ty + mxz * tz;
      double wy = mxy * tx + myy * ty + myz * tz;
      double wz = mxz * tx + myz * ty + mzz * tz;
      PIOLA_UNROLL
      for (int a = 1; a < 4; ++a) {
        s[k][a][0] -= wy * r[a][2] - wz * r[a][1];
        s[k][a][1] -= wz * r[a][0] - wx * r[a][2];
        s[k][a][2] -= wx * r[a][1] - wy * r[a][0];
      }
      PIOLA_UNROLL
      for (int c = 0; c < 3; ++c) s[k][0][c] = -(s[k][1][c] + s[k][2][c] + s[k][3][c]);
    }
    /* traces: the bulk term's row */
    double tr[4][3];
    PIOLA_UNROLL
    for (int a = 0; a < 4; ++a)
      PIOLA_UNROLL
      for (int c = 0; c < 3; ++c) tr[a][c] = s[0][a][c] + s[1][a][c] + s[2][a][c];

    const double two_beta = 2.0 * beta;
    PIOLA_UNROLL
    for (int p = 0; p < 6; ++p) {
      const int a = PAIR_A[p], b = PAIR_B[p];
      PIOLA_UNROLL
      for (int c = 0; c < 3; ++c)
        PIOLA_UNROLL
        for (int d = 0; d < 3; ++d) {
          double sum = 0;
          PIOLA_UNROLL
          for (int n = 0; n < 6; ++n) sum += s[n][a][c] * s[n][b][d];
          out[(9 * p + 3 * c + d) * B + l] = -(two_beta * sum + alpha * tr[a][c] * tr[b][d]);
        }
    }
  }
}

/* Adds (or, for a slot's first writer, stores) a SIMD block's tet blocks into their slots,
 * transposed where the edge is stored the other way round (D_ij = D_ba^T). */
static void scatter_tets(piola__damping_matrix *m, int32_t block, int32_t tet_count,
                         const double *out) {
  static const int TRANSPOSE[2][9] = {{0, 1, 2, 3, 4, 5, 6, 7, 8}, {0, 3, 6, 1, 4, 7, 2, 5, 8}};
  const int32_t base = block * B;
  const int32_t lanes = tet_count - base < B ? tet_count - base : B;
  for (int l = 0; l < lanes; ++l) {
    const int32_t *slots = m->tet_slot + 6 * (size_t)(base + l);
    const unsigned flags = m->tet_flags[base + l];
    for (int p = 0; p < 6; ++p) {
      double *dst = m->blocks + 9 * (size_t)slots[p];
      const double *src = out + 9 * p * B + l;
      const int *order = TRANSPOSE[(flags >> p) & 1];
      if ((flags >> (6 + p)) & 1)
        for (int k = 0; k < 9; ++k) dst[k] = src[order[k] * B];
      else
        for (int k = 0; k < 9; ++k) dst[k] += src[order[k] * B];
    }
  }
}

/* Range k of the tets: its SIMD blocks in order. */
static void assemble_part(piola__damping_matrix *m, const piola_elastic_body *body, int k,
                          double beta, double alpha) {
  const int32_t blocks = body->padded_tet_count / B;
  const int32_t b0 = piola__damping_part_start(blocks, k), b1 = piola__damping_part_start(blocks, k + 1);
  double out[54 * B];
  for (int32_t b = b0; b < b1; ++b) {
    tet_blocks(body, b, beta, alpha, out);
    scatter_tets(m, b, body->tet_count, out);
  }
}

void PIOLA_ISA_NAME(piola__damping_matrix_assemble)(piola__damping_matrix *m, const piola_elastic_body *body,
                                    double shear_viscosity, double bulk_viscosity) {
  const int32_t blocks = body->padded_tet_count / B;
#pragma omp parallel num_threads(piola_thread_count()) if (blocks >= PIOLA_PARALLEL_MIN_BLOCKS)
  {
#pragma omp for schedule(static)
    for (int k = 0; k < PIOLA_DAMPING_PARTS; ++k)
      assemble_part(m, body, k, shear_viscosity, bulk_viscosity);
#pragma omp for schedule(static)
    for (int32_t k = 0; k < m->shared_count; ++k) piola__edge_reduce_shared(m, m->blocks, k);
  }
  m->shear_viscosity = shear_viscosity;
  m->bulk_viscosity = bulk_viscosity;
  m->ready = 1;
  m->generation++;
}
