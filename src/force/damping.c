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
 * Speed. The implicit step applies this operator in every conjugate-gradient iteration, a
 * dozen or more times per elastic update, so it is assembled once per update into a sparse
 * matrix with one 3x3 block per mesh edge (damping_matrix.h, damping_assembly.c) and each
 * apply is a product with it: about 80 bytes and 40 flops per edge instead of recomputing
 * the projections and the stress of every tet (that per-tet apply streamed 160 bytes and
 * spent ~400 flops per tet). The matrix depends on the viscosities, so a call with other
 * viscosities than the last assembly assembles again. A scalar reference of the original
 * per-tet formulation is kept for the tests (tests/support/elastic_referees.c). */
#include <stdlib.h>

#include "force/damping_matrix.h"
#include "force/elastic_body_internal.h"

void piola__elastic_body_damping_prepare(piola_elastic_body *body, double shear_viscosity,
                                         double bulk_viscosity) {
  piola__damping_matrix *m = &body->damping;
  if (m->ready && m->shear_viscosity == shear_viscosity && m->bulk_viscosity == bulk_viscosity)
    return;
  piola__damping_matrix_assemble(m, body, shear_viscosity, bulk_viscosity);
}

/* Rows r0 .. r1 - 1 of f = D v, or with mass given of out = M v - h D v. Each row gathers
 * its edges to vertices ranked after it (blocks D_ij) and before it (D_ji^T), in a fixed
 * order. */
static void product_rows(const piola__damping_matrix *m, const double *v, const double *mass,
                         double h, int32_t r0, int32_t r1, const piola_work_split *split,
                         double *out) {
  for (int32_t r = r0; r < r1; ++r) {
    const int32_t i = m->order[r];
    if (split && split->node_part[i] != split->part) continue; /* another process's row */
    const double v0 = v[3 * i], v1 = v[3 * i + 1], v2 = v[3 * i + 2];
    double f[3];
    piola__edge_row_product(m, m->blocks, v, r, f);
    if (mass) {
      out[3 * i] = mass[i] * v0 - h * f[0];
      out[3 * i + 1] = mass[i] * v1 - h * f[1];
      out[3 * i + 2] = mass[i] * v2 - h * f[2];
    } else {
      out[3 * i] = f[0];
      out[3 * i + 1] = f[1];
      out[3 * i + 2] = f[2];
    }
  }
}

/* forces = D v, or with mass given, out = M v - h D v (the implicit step's operator). With a
 * work split each process computes its own nodes' rows, the same bits as the whole
 * product's, and the split shares them. */
static void damping_pass(const piola_elastic_body *body, const double *v, double shear_viscosity,
                         double bulk_viscosity, const double *mass, double h, double *out) {
  /* the matrix is assembled in place, like the lazy energy: concurrent calls on one body are
   * not allowed */
  piola__elastic_body_damping_prepare((piola_elastic_body *)body, shear_viscosity, bulk_viscosity);
  const piola__damping_matrix *m = &body->damping;
  const int32_t nv = body->vertex_count;
  const piola_work_split *split = body->split && body->split->part_count > 1 ? body->split : NULL;
  /* fixed row ranges; each row is summed alone, so the split does not change any bit */
  enum { RANGES = 16 };
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) \
    if (nv >= PIOLA_PARALLEL_MIN_VERTICES)
  for (int r = 0; r < RANGES; ++r)
    product_rows(m, v, mass, h, (int32_t)((int64_t)nv * r / RANGES),
                 (int32_t)((int64_t)nv * (r + 1) / RANGES), split, out);
  if (split) split->share_nodes(split->context, out);
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
                                                   double scale, double *forces) {
  piola__elastic_body_damping_prepare((piola_elastic_body *)body, shear_viscosity, bulk_viscosity);
  const piola__damping_matrix *m = &body->damping;
  /* every edge with a moving end, once: from its first-ranked end if that one moves, else
   * from the other. An edge whose ends are both at rest adds exactly zero. */
  for (int32_t j = 0; j < body->vertex_count; ++j) {
    if (!vertex_moves(v, j)) continue;
    const int32_t r = m->rank[j];
    for (int32_t k = m->row_start[r]; k < m->row_start[r + 1]; ++k) {
      int32_t i = m->col[k];
      const double *a = m->blocks + 9 * (size_t)k;
      double d[3] = {scale * (v[3 * i] - v[3 * j]), scale * (v[3 * i + 1] - v[3 * j + 1]),
                     scale * (v[3 * i + 2] - v[3 * j + 2])};
      for (int c = 0; c < 3; ++c) {
        forces[3 * j + c] += a[3 * c] * d[0] + a[3 * c + 1] * d[1] + a[3 * c + 2] * d[2];
        forces[3 * i + c] -= a[c] * d[0] + a[3 + c] * d[1] + a[6 + c] * d[2];
      }
    }
    for (int32_t k = m->lower_start[r]; k < m->lower_start[r + 1]; ++k) {
      int32_t i = m->lower_col[k];
      if (vertex_moves(v, i)) continue; /* done from i */
      const double *a = m->blocks + 9 * (size_t)m->lower_edge[k];
      double d[3] = {scale * (v[3 * j] - v[3 * i]), scale * (v[3 * j + 1] - v[3 * i + 1]),
                     scale * (v[3 * j + 2] - v[3 * i + 2])};
      for (int c = 0; c < 3; ++c) {
        forces[3 * i + c] += a[3 * c] * d[0] + a[3 * c + 1] * d[1] + a[3 * c + 2] * d[2];
        forces[3 * j + c] -= a[c] * d[0] + a[3 + c] * d[1] + a[6 + c] * d[2];
      }
    }
  }
}
