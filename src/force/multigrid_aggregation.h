/* The coarsening of smoothed aggregation multigrid (force/stiffness_multigrid.h): which
 * nodes form a coarse node (aggregation on the strong couplings of the block matrix) and
 * the tentative prolongator that carries the rigid-body modes of each aggregate.
 *
 * Strength. Block (i, j) couples i and j strongly when its Frobenius norm exceeds
 * theta sqrt(|A_ii| |A_jj|) (Vanek, Mandel and Brezina 1996, on block norms so that a node's
 * three (or six) unknowns stay together). A node without strong couplings (a fixed vertex,
 * whose filtered row is the identity) joins no aggregate: the smoother alone treats it.
 *
 * Aggregation, in row order (reverse Cuthill-McKee on the finest level, so the aggregates
 * are compact): (1) a node whose strong neighbours are all unaggregated starts an aggregate
 * of itself and them; (2) a node left over joins the aggregate of its strongest aggregated
 * neighbour; (3) what is still left starts aggregates of itself and its unaggregated strong
 * neighbours. Sequential and in a fixed order, so the result does not depend on the thread
 * count.
 *
 * Tentative prolongator. The near null space B (rows * b x 6, the rigid-body modes: on the
 * finest level three translations and three rotations about the aggregate's centroid,
 * projected by each vertex's constraint; on a coarser level the R factors of the level
 * below) is split by aggregate and each piece factored B_a = Q_a R_a by modified
 * Gram-Schmidt with a second pass. Q_a becomes the aggregate's block column of the
 * tentative prolongator T (orthonormal columns, T R = B exactly), R_a the coarse node's
 * near null space. A mode that is dependent on the earlier ones within an aggregate (a
 * rotation of a single vertex, the translations of a fixed one) gets a zero column, and the
 * coarse operator then a zero row and column, which the caller replaces by the identity. */
#ifndef PIOLA_FORCE_MULTIGRID_AGGREGATION_H
#define PIOLA_FORCE_MULTIGRID_AGGREGATION_H

#include <stdint.h>

#include "math/block_sparse.h"

#define PIOLA_MULTIGRID_MODES 6

/* aggregate[i] of every node of the square matrix a (-1: none) for strength threshold
 * theta; returns the number of aggregates, -1 when out of memory. */
int32_t piola__multigrid_aggregate(const piola__block_sparse *a, double theta, int32_t *aggregate);

/* The tentative prolongator t (a->rows x aggregates, blocks b x 6) and the coarse near null
 * space coarse_modes (aggregates x 36, row-major 6x6) from the near null space modes
 * (rows * b x 6, row-major; b = a's block size). */
piola_status piola__multigrid_tentative(const piola__block_sparse *a, const int32_t *aggregate,
                                        int32_t aggregates, const double *modes,
                                        piola__block_sparse *t, double *coarse_modes);

#endif
