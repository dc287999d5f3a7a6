/* The damping operator as an assembled sparse matrix (see damping.c for the physics).
 *
 * The damping force is linear in the velocities, f = D v, and D changes only when the body is
 * updated, while the implicit step applies it in every conjugate-gradient iteration. So D is
 * assembled once per update and each apply is a sparse product. D is symmetric and its rows
 * sum to zero (a uniform velocity is not damped), so only the off-diagonal 3x3 blocks are
 * stored, one per mesh edge (i, j), holding D_ij with i ranked first (D_ji is its
 * transpose), and the product is written in edge differences:
 *   f_i = sum over edges (i, j) of D_ij (v_j - v_i).
 * That keeps a rigid translation undamped exactly and needs no diagonal blocks.
 *
 * Layout. Rows are the vertices in reverse Cuthill-McKee order (order[r] is the vertex of
 * row r, rank[i] the row of vertex i), so a vertex's edges sit near those of the vertices
 * around it whatever the mesh file's numbering. Edges are numbered row by row: row r holds
 * the edges from vertex i = order[r] to the vertices ranked after it, col[k] for k in
 * [row_start[r], row_start[r + 1]) (vertex indices, increasing), and block k,
 * blocks[9 k .. 9 k + 8] (row-major), is D_{i, col[k]}. Row r's other edges, those to
 * vertices ranked before it, are listed in lower_edge/lower_col [lower_start[r],
 * lower_start[r + 1]); their blocks are used transposed. The product gathers both lists per
 * row, so every row is summed by one thread in a fixed order: bit-identical results for any
 * thread count, and the blocks of a row's earlier edges come from cache.
 *
 * Assembly. Each tet adds its 6 corner-pair blocks to its 6 edges (pair p in the order
 * 01 02 03 12 13 23; bit p of tet_flags[t] says the pair is stored transposed). The tets are
 * split into PIOLA_DAMPING_PARTS fixed ranges assembled in parallel. An edge only one range
 * touches is written in place; an edge several ranges touch (the ranges' borders, or most
 * edges of a mesh whose tet order has no locality) gets a private slot per range, after the
 * blocks in `blocks`, and a last pass adds those slots up in range order. tet_slot[6 t + p]
 * is where tet t writes pair p, and bit 6 + p of tet_flags[t] says it writes there first,
 * so nothing needs clearing. Every block is summed in the same order for any thread
 * count. */
#ifndef PIOLA_FORCE_DAMPING_MATRIX_H
#define PIOLA_FORCE_DAMPING_MATRIX_H

#include <stdint.h>

#include "common/isa.h"
#include "piola/elastic_body.h"

typedef struct piola__damping_matrix {
  int32_t vertex_count;
  int32_t edge_count;
  int32_t *order;       /* vertex_count: the vertex of each row */
  int32_t *rank;        /* vertex_count: the row of each vertex */
  int32_t *row_start;   /* vertex_count + 1 */
  int32_t *col;         /* edge_count */
  int32_t *lower_start; /* vertex_count + 1 */
  int32_t *lower_edge;  /* edge_count */
  int32_t *lower_col;   /* edge_count */
  int32_t *tet_slot;    /* 6 per tet (tet_count): where each pair goes in blocks */
  uint16_t *tet_flags;  /* per tet: transposed pairs (bits 0-5), first writers (bits 6-11) */
  int32_t shared_count; /* edges touched by more than one tet range */
  int32_t *shared_edge; /* shared_count edges, increasing */
  int32_t *shared_slot_start; /* shared_count + 1: the private slots of shared_edge[k] */
  double *blocks;       /* 9 per slot: D_ij of each edge (N s/m, force per velocity), then
                           the private slots of shared edges */
  double shear_viscosity, bulk_viscosity; /* what blocks were assembled with, Pa s */
  int ready;            /* blocks match the body's last update and these viscosities */
  uint64_t generation;  /* counts assemblies: a product taken at another one is stale */
} piola__damping_matrix;

/* Tet ranges assembled in parallel; fixed, so results do not depend on the thread count. */
#define PIOLA_DAMPING_PARTS 8

/* The first SIMD block of range k (k = PIOLA_DAMPING_PARTS: the end) of blocks blocks. */
static inline int32_t piola__damping_part_start(int32_t blocks, int k) {
  return (int32_t)((int64_t)blocks * k / PIOLA_DAMPING_PARTS);
}

/* Builds the sparsity pattern, the tets' slots and the private slots of body's mesh
 * (damping_pattern.c); allocates the blocks. Needs the body's tets and vertex count. */
piola_status piola__damping_matrix_init(piola__damping_matrix *matrix,
                                        const piola_elastic_body *body);

void piola__damping_matrix_free(piola__damping_matrix *matrix);

/* Assembles the blocks from the body's last update (damping_assembly.c, a kernel built once
 * per instruction set, common/isa.h; the plain name runs the chosen variant). */
#define PIOLA_DAMPING_MATRIX_ASSEMBLE_PARAMS                                                \
  (piola__damping_matrix * matrix, const piola_elastic_body *body, double shear_viscosity, \
   double bulk_viscosity)
PIOLA_ISA_DECLARE(void, piola__damping_matrix_assemble, PIOLA_DAMPING_MATRIX_ASSEMBLE_PARAMS);
void piola__damping_matrix_assemble PIOLA_DAMPING_MATRIX_ASSEMBLE_PARAMS;

/* The pattern serves every edge-block matrix of the body (this damping operator, the
 * implicit step's stiffness matrix): `blocks` below is such a matrix's block array, laid
 * out as the pattern says. */

/* f = the sum over row r's edges (i, j), i = order[r], of A_ij (v_j - v_i): the row's upper
 * edges, then its lower ones (A_ji transposed), in the pattern's fixed order. */
static inline void piola__edge_row_product(const piola__damping_matrix *pattern,
                                           const double *blocks, const double *v, int32_t r,
                                           double f[3]) {
  const int32_t i = pattern->order[r];
  const double v0 = v[3 * i], v1 = v[3 * i + 1], v2 = v[3 * i + 2];
  double f0 = 0, f1 = 0, f2 = 0;
  for (int32_t k = pattern->row_start[r]; k < pattern->row_start[r + 1]; ++k) {
    const double *a = blocks + 9 * (size_t)k, *vj = v + 3 * (size_t)pattern->col[k];
    double d0 = vj[0] - v0, d1 = vj[1] - v1, d2 = vj[2] - v2;
    f0 += a[0] * d0 + a[1] * d1 + a[2] * d2;
    f1 += a[3] * d0 + a[4] * d1 + a[5] * d2;
    f2 += a[6] * d0 + a[7] * d1 + a[8] * d2;
  }
  for (int32_t k = pattern->lower_start[r]; k < pattern->lower_start[r + 1]; ++k) {
    const double *a = blocks + 9 * (size_t)pattern->lower_edge[k];
    const double *vj = v + 3 * (size_t)pattern->lower_col[k];
    double d0 = vj[0] - v0, d1 = vj[1] - v1, d2 = vj[2] - v2;
    f0 += a[0] * d0 + a[3] * d1 + a[6] * d2;
    f1 += a[1] * d0 + a[4] * d1 + a[7] * d2;
    f2 += a[2] * d0 + a[5] * d1 + a[8] * d2;
  }
  f[0] = f0, f[1] = f1, f[2] = f2;
}

/* The block of edge shared_edge[k] = the sum of its private slots, in range order. */
static inline void piola__edge_reduce_shared(const piola__damping_matrix *pattern,
                                             double *blocks, int32_t k) {
  double *dst = blocks + 9 * (size_t)pattern->shared_edge[k];
  int32_t s0 = pattern->shared_slot_start[k], s1 = pattern->shared_slot_start[k + 1];
  for (int i = 0; i < 9; ++i) {
    double sum = blocks[9 * (size_t)s0 + i];
    for (int32_t s = s0 + 1; s < s1; ++s) sum += blocks[9 * (size_t)s + i];
    dst[i] = sum;
  }
}

#endif
