/* The implicit integrators' system matrix (stiffness_matrix.h): per-tet projected stiffness
 * blocks, their assembly on the damping matrix's edge pattern, and the product. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "force/elastic_body_internal.h"
#include "force/element_stiffness.h"
#include "force/stiffness_lanes.h"
#include "force/stiffness_matrix.h"
#include "material/hgo_kernels.h"
#include "math/mat3.h"

static const int PAIR_A[6] = {0, 0, 0, 1, 1, 2}, PAIR_B[6] = {1, 2, 3, 2, 3, 3};

piola_status piola__stiffness_matrix_init(piola__stiffness_matrix *m,
                                          const piola_elastic_body *body) {
  memset(m, 0, sizeof *m);
  const piola__damping_matrix *d = &body->damping;
  m->vertex_count = body->vertex_count;
  m->slot_count = d->shared_count > 0 ? d->shared_slot_start[d->shared_count] : d->edge_count;
  size_t nv = (size_t)(body->vertex_count > 0 ? body->vertex_count : 1);
  /* zeroed: on a split in the local mode the slots of the tets this process does not hold
   * are never written (see assemble_part) */
  m->blocks = calloc(9 * (size_t)(m->slot_count > 0 ? m->slot_count : 1), sizeof(double));
  m->diagonal = malloc(sizeof(double) * 9 * nv);
  m->inverse_diagonal = malloc(sizeof(double) * 9 * nv);
  if (!m->blocks || !m->diagonal || !m->inverse_diagonal) {
    piola__stiffness_matrix_free(m);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "stiffness matrix: out of memory");
  }
  return PIOLA_OK;
}

void piola__stiffness_matrix_free(piola__stiffness_matrix *m) {
  free(m->blocks);
  free(m->diagonal);
  free(m->inverse_diagonal);
  memset(m, 0, sizeof *m);
}

int piola__stiffness_projection(const piola_elastic_body *body) {
  return body->signed_twist ? PIOLA_STIFFNESS_SIGNED_TWIST : PIOLA_STIFFNESS_PROJECTED;
}

void piola__tet_diagonal_stiffness(const piola_elastic_body *body, int32_t t,
                                   piola__diagonal_stiffness *k) {
  const piola_material *material = &body->materials[body->tet_material[t]];
  const double *fhat = body->fhat + 3 * (size_t)t;
  double phat[3];
  piola__material_stress_and_derivative(material, fhat, phat, k->block);
  piola__diagonal_stiffness_from(fhat, phat, piola__stiffness_projection(body), k);
}

/* The rows g_a of tet t's Dm^-1 (g_0 = -(g_1 + g_2 + g_3)) and its U and V. */
static void tet_frame(const piola_elastic_body *body, int32_t t, double g[4][3], double u[3][3],
                      double v[3][3]) {
  double dm[3][3];
  for (int k = 0; k < 9; ++k) {
    u[k / 3][k % 3] = body->u[k][t];
    v[k / 3][k % 3] = body->v[k][t];
    dm[k / 3][k % 3] = body->dm_inv[k][t];
  }
  for (int j = 0; j < 3; ++j) {
    g[0][j] = -(dm[0][j] + dm[1][j] + dm[2][j]);
    for (int a = 1; a < 4; ++a) g[a][j] = dm[a - 1][j];
  }
}

/* Adds tet t's fibre term (a muscle's or HGO's, when the body has fibres; nothing otherwise)
 * to its six corner-pair blocks out[stride (9 p + e)], scaled as the material's part. Kept
 * apart from that part so that the assembly takes the material's part through the lane
 * kernel (stiffness_lanes.h) for bodies with fibres too. */
static void add_fiber_blocks(const piola_elastic_body *body, int32_t t, double *out,
                             size_t stride) {
  if (!body->fiber[0]) return;
  const piola_material *material = &body->materials[body->tet_material[t]];
  const int muscle = material->model == PIOLA_MODEL_MUSCLE,
            hgo = material->model == PIOLA_MODEL_HGO;
  if (!muscle && !hgo) return;
  double g[4][3], u[3][3], v[3][3];
  tet_frame(body, t, g, u, v);
  const double *fhat = body->fhat + 3 * (size_t)t;
  const double scale = -body->rest_volume[t] * body->last_stiffness_scale;
  /* the muscle's: w = F a = U (fhat * (V^T a)) */
  double fs = 0, fc = 0, fa[3] = {0, 0, 0}, w[3] = {0, 0, 0};
  if (muscle) {
    for (int i = 0; i < 3; ++i) fa[i] = body->fiber[i][t];
    double ah[3];
    for (int p = 0; p < 3; ++p) ah[p] = v[0][p] * fa[0] + v[1][p] * fa[1] + v[2][p] * fa[2];
    for (int i = 0; i < 3; ++i)
      w[i] = u[i][0] * fhat[0] * ah[0] + u[i][1] * fhat[1] * ah[1] + u[i][2] * fhat[2] * ah[2];
    piola__fiber_stiffness_terms(material, sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]),
                                 body->activation, PIOLA_STIFFNESS_PROJECTED, &fs, &fc);
    if (fs == 0 && fc == 0) return;
  }
  /* HGO's, dP_f/dF at F = U Fhat V^T, positive semi-definite as it is (material.h), in the
   * factored form of hgo_family_derivative: pair (a, b)'s block, the sum over j and l of
   * g_a[j] dP_ij/dF_kl g_b[l], is per family
   *   c4 (G g_a)(G g_b)^T + s2 (kappa g_a . g_b + (1 - 3 kappa) (g_a . n)(g_b . n)) I,
   * a fifth of the products of contracting the 81 numbers of dP_f/dF with g_a and g_b */
  double hgo_blocks[6][9] = {{0}};
  if (hgo) {
    const piola_hgo_def *h = &material->hgo;
    double fm[9], fam[6];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        fm[3 * i + j] = u[i][0] * fhat[0] * v[j][0] + u[i][1] * fhat[1] * v[j][1] + u[i][2] * fhat[2] * v[j][2];
    const double m[3] = {body->fiber[0][t], body->fiber[1][t], body->fiber[2][t]};
    (void)piola_material_hgo_families(material, m, fam); /* checked when the body was built */
    for (int a = 0; a < 2; ++a) {
      const double *n = fam + 3 * a;
      double gm[9], c4, s2, gg[4][3], gn[4];
      hgo_family_derivative(h, fm, n, gm, &c4, &s2);
      for (int c = 0; c < 4; ++c) {
        gn[c] = g[c][0] * n[0] + g[c][1] * n[1] + g[c][2] * n[2];
        for (int i = 0; i < 3; ++i)
          gg[c][i] = gm[3 * i] * g[c][0] + gm[3 * i + 1] * g[c][1] + gm[3 * i + 2] * g[c][2];
      }
      for (int p = 0; p < 6; ++p) {
        const int ca = PAIR_A[p], cb = PAIR_B[p];
        const double dot = g[ca][0] * g[cb][0] + g[ca][1] * g[cb][1] + g[ca][2] * g[cb][2];
        const double diagonal = s2 * (h->kappa * dot + (1.0 - 3.0 * h->kappa) * gn[ca] * gn[cb]);
        for (int i = 0; i < 3; ++i) {
          for (int k = 0; k < 3; ++k) hgo_blocks[p][3 * i + k] += c4 * gg[ca][i] * gg[cb][k];
          hgo_blocks[p][4 * i] += diagonal;
        }
      }
    }
  }
  for (int n = 0; n < 6; ++n) {
    const double *pa = g[PAIR_A[n]], *pb = g[PAIR_B[n]];
    const double fiber_weight = muscle ? (pa[0] * fa[0] + pa[1] * fa[1] + pa[2] * fa[2]) *
                                             (pb[0] * fa[0] + pb[1] * fa[1] + pb[2] * fa[2])
                                       : 0.0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const double kij =
            fiber_weight * ((i == j ? fs : 0.0) + fc * w[i] * w[j]) + hgo_blocks[n][3 * i + j];
        out[stride * (size_t)(9 * n + 3 * i + j)] += scale * kij;
      }
  }
}

void piola__tet_stiffness_blocks(const piola_elastic_body *body, int32_t t, double out[54]) {
  double g[4][3], u[3][3], v[3][3];
  tet_frame(body, t, g, u, v);
  piola__diagonal_stiffness k;
  piola__tet_diagonal_stiffness(body, t, &k);
  /* the rows g_a of Dm^-1 in the diagonal frame: gh_a = V^T g_a */
  double gh[4][3];
  for (int a = 0; a < 4; ++a)
    for (int p = 0; p < 3; ++p)
      gh[a][p] = v[0][p] * g[a][0] + v[1][p] * g[a][1] + v[2][p] * g[a][2];
  /* pair (p, q) of the diagonal frame: index of its 2x2 block */
  static const int PAIR_OF[3][3] = {{-1, 0, 1}, {0, -1, 2}, {1, 2, -1}};
  const double scale = -body->rest_volume[t] * body->last_stiffness_scale;
  for (int n = 0; n < 6; ++n) {
    const double *ga = gh[PAIR_A[n]], *gb = gh[PAIR_B[n]];
    double mm[3][3];
    for (int p = 0; p < 3; ++p) {
      double diag = ga[p] * gb[p] * k.block[p][p];
      for (int q = 0; q < 3; ++q)
        if (q != p) {
          const int pr = PAIR_OF[p][q];
          diag += ga[q] * gb[q] * k.pair_a[pr];
          mm[p][q] = ga[p] * gb[q] * k.block[p][q] + ga[q] * gb[p] * k.pair_b[pr];
        }
      mm[p][p] = diag;
    }
    /* U M U^T */
    double um[3][3];
    for (int i = 0; i < 3; ++i)
      for (int q = 0; q < 3; ++q)
        um[i][q] = u[i][0] * mm[0][q] + u[i][1] * mm[1][q] + u[i][2] * mm[2][q];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        out[9 * n + 3 * i + j] =
            scale * (um[i][0] * u[j][0] + um[i][1] * u[j][1] + um[i][2] * u[j][2]);
  }
  add_fiber_blocks(body, t, out, 1);
}

/* Adds (or, for a slot's first writer, stores) weight times tet t's six blocks out[9 p + e]
 * (entry e of pair p, at stride `stride` in out) into their slots, transposed where the edge
 * is stored the other way round. Inlined, with the four cases written out and constant
 * indices, so each call site gets straight-line code for its stride (the same operations
 * on every entry as a table-driven loop: the same bits). */
static inline __attribute__((always_inline)) void scatter_tet(piola__stiffness_matrix *m,
                                                              const piola__damping_matrix *d,
                                                              int32_t t, const double *out,
                                                              size_t stride, double weight) {
  const int32_t *slots = d->tet_slot + 6 * (size_t)t;
  const unsigned flags = d->tet_flags[t];
  for (int p = 0; p < 6; ++p) {
    double *dst = m->blocks + 9 * (size_t)slots[p];
    const double *src = out + stride * (size_t)(9 * p);
    const int transposed = (flags >> p) & 1, first = (flags >> (6 + p)) & 1;
    if (first && !transposed)
      for (int e = 0; e < 9; ++e) dst[e] = weight * src[stride * (size_t)e];
    else if (first)
      for (int e = 0; e < 9; ++e) dst[e] = weight * src[stride * (size_t)(3 * (e % 3) + e / 3)];
    else if (!transposed)
      for (int e = 0; e < 9; ++e) dst[e] += weight * src[stride * (size_t)e];
    else
      for (int e = 0; e < 9; ++e) dst[e] += weight * src[stride * (size_t)(3 * (e % 3) + e / 3)];
  }
}

/* Range k of the tets (the damping assembly's ranges), in tet order. Whole blocks go through
 * the lane kernel (stiffness_lanes.h, the same bits), their fibre terms added tet by tet,
 * the rest tet by tet. */
static void assemble_part(piola__stiffness_matrix *m, const piola_elastic_body *body, int k,
                          double weight) {
  const piola__damping_matrix *d = &body->damping;
  const int32_t blocks = body->padded_tet_count / PIOLA_TET_BLOCK;
  const int32_t t0 = piola__damping_part_start(blocks, k) * PIOLA_TET_BLOCK;
  int32_t t1 = piola__damping_part_start(blocks, k + 1) * PIOLA_TET_BLOCK;
  if (t1 > body->tet_count) t1 = body->tet_count;

  /* a split in the local mode assembles the blocks it holds, as the damping assembly does:
   * every tet on one of its nodes, so its nodes' rows are complete, in the same order */
  const uint8_t *held = piola__local_split(body) ? body->split_held : NULL;
  double out[54], lane_out[54][PIOLA_TET_BLOCK];
  for (int32_t t = t0; t < t1;) {
    if (held && !held[t / PIOLA_TET_BLOCK]) {
      t = (t / PIOLA_TET_BLOCK + 1) * PIOLA_TET_BLOCK;
      continue;
    }
    if (t + PIOLA_TET_BLOCK <= t1) {
      piola__stiffness_block_lanes(body, t / PIOLA_TET_BLOCK, lane_out);
      for (int l = 0; l < PIOLA_TET_BLOCK; ++l) {
        add_fiber_blocks(body, t + l, &lane_out[0][l], PIOLA_TET_BLOCK);
        scatter_tet(m, d, t + l, &lane_out[0][l], PIOLA_TET_BLOCK, weight);
      }
      t += PIOLA_TET_BLOCK;
    } else {
      piola__tet_stiffness_blocks(body, t, out);
      scatter_tet(m, d, t, out, 1, weight);
      ++t;
    }
  }
}

/* What a pass over the matrix's rows reads and writes. */
typedef struct row_pass {
  int32_t rows;                     /* the body's vertex count */
  const double *blocks;             /* the edge blocks */
  piola__stiffness_matrix *diagonal; /* gets the diagonal blocks (NULL for the product) */
  const piola__damping_matrix *d;
  const double *mass;
  double mass_weight;
  const double *p; /* the product's operand */
  double *out;     /* the product */
} row_pass;

/* rows(c, r0, r1) over 16 fixed ranges of the rows, in parallel for large bodies; each row
 * is computed by one thread, so results do not depend on the thread count. */
static void over_row_ranges(const row_pass *c, void (*rows)(const row_pass *, int32_t, int32_t)) {
  const int32_t nv = c->rows;
  enum { RANGES = 16 };
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) \
    if (nv >= PIOLA_PARALLEL_MIN_VERTICES)
  for (int r = 0; r < RANGES; ++r)
    rows(c, (int32_t)((int64_t)nv * r / RANGES), (int32_t)((int64_t)nv * (r + 1) / RANGES));
}

/* Diagonal blocks of rows r0 .. r1 - 1: m_w m_i I + sum over the row's edges of S_ij. */
static void diagonal_rows(const row_pass *pass, int32_t r0, int32_t r1) {
  piola__stiffness_matrix *m = pass->diagonal;
  const piola__damping_matrix *d = pass->d;
  const double *mass = pass->mass;
  const double mass_weight = pass->mass_weight;
  for (int32_t r = r0; r < r1; ++r) {
    const int32_t i = d->order[r];
    double a[9] = {0};
    for (int32_t k = d->row_start[r]; k < d->row_start[r + 1]; ++k)
      for (int e = 0; e < 9; ++e) a[e] += m->blocks[9 * (size_t)k + e];
    for (int32_t k = d->lower_start[r]; k < d->lower_start[r + 1]; ++k) {
      const double *b = m->blocks + 9 * (size_t)d->lower_edge[k];
      for (int c = 0; c < 3; ++c)
        for (int e = 0; e < 3; ++e) a[3 * c + e] += b[3 * e + c];
    }
    for (int c = 0; c < 3; ++c) a[4 * c] += mass_weight * mass[i];
    memcpy(m->diagonal + 9 * (size_t)i, a, sizeof a);
    piola__invert3_or_diagonal(a, m->inverse_diagonal + 9 * (size_t)i);
  }
}

void piola__stiffness_matrix_assemble(piola__stiffness_matrix *m, const piola_elastic_body *body,
                                      double stiffness_weight, double damping_weight,
                                      const double *mass, double mass_weight) {
  const piola__damping_matrix *d = &body->damping;
  const int32_t blocks = body->padded_tet_count / PIOLA_TET_BLOCK;
#pragma omp parallel num_threads(piola_thread_count()) if (blocks >= PIOLA_PARALLEL_MIN_BLOCKS)
  {
#pragma omp for schedule(static)
    for (int k = 0; k < PIOLA_DAMPING_PARTS; ++k) assemble_part(m, body, k, stiffness_weight);
#pragma omp for schedule(static)
    for (int32_t k = 0; k < d->shared_count; ++k) piola__edge_reduce_shared(d, m->blocks, k);
#pragma omp for schedule(static)
    for (int32_t e = 0; e < d->edge_count; ++e) {
      if (damping_weight != 0)
        for (int c = 0; c < 9; ++c) m->blocks[9 * (size_t)e + c] += damping_weight * d->blocks[9 * (size_t)e + c];
    }
  }
  piola__stiffness_matrix_set_mass_weight(m, body, mass, mass_weight);
}

void piola__stiffness_matrix_set_mass_weight(piola__stiffness_matrix *m,
                                             const piola_elastic_body *body, const double *mass,
                                             double mass_weight) {
  const row_pass c = {body->vertex_count, m->blocks, m, &body->damping, mass, mass_weight,
                      NULL, NULL};
  over_row_ranges(&c, diagonal_rows);
}

/* Rows r0 .. r1 - 1 of out = A p: each row gathers its edges in a fixed order, so results
 * do not depend on the thread count. */
static void product_rows(const row_pass *c, int32_t r0, int32_t r1) {
  const piola__damping_matrix *d = c->d;
  const double *p = c->p, *mass = c->mass;
  double *out = c->out;
  for (int32_t r = r0; r < r1; ++r) {
    const int32_t i = d->order[r];
    const double p0 = p[3 * i], p1 = p[3 * i + 1], p2 = p[3 * i + 2];
    double f[3];
    piola__edge_row_product(d, c->blocks, p, r, f);
    const double mi = c->mass_weight * mass[i];
    out[3 * i] = mi * p0 - f[0];
    out[3 * i + 1] = mi * p1 - f[1];
    out[3 * i + 2] = mi * p2 - f[2];
  }
}

void piola__stiffness_matrix_apply(const piola__stiffness_matrix *m, const piola_elastic_body *body,
                                   const double *mass, double mass_weight, const double *p,
                                   double *out) {
  const row_pass c = {body->vertex_count, m->blocks, NULL, &body->damping, mass, mass_weight,
                      p, out};
  over_row_ranges(&c, product_rows);
}
