/* piola: splitting an elastic body's per-tet work among cooperating processes.
 *
 * The core knows nothing of MPI: a process that runs with others (libpiola_mpi,
 * docs/mpi.md) hands each elastic body a piola_work_split, which says which blocks of
 * PIOLA_WORK_SPLIT_BLOCK consecutive tets this process computes and which process owns each
 * node, and gives the three collective operations the body calls. Every process keeps the
 * whole body (positions, velocities, per-tet state): the split divides the work of the
 * force loop and of the damping products, not the memory.
 *
 * With a split set, piola_elastic_body_update runs the force loop (F, its diagonalization,
 * stress, muscle fibres, nodal forces) on this process's blocks only, then
 *   - sum_nodes turns each process's partial nodal forces (3 per node, zero away from its
 *     tets) into the total on every process, bit-identical on all of them;
 *   - share_blocks gives every process every block's per-tet state (width doubles per block,
 *     written by the block's process);
 * and the damping products compute the rows of this process's nodes only, then
 *   - share_nodes gives every process every node's 3 values (written by the node's owner).
 * All processes must make the same calls in the same order (they do: their states are
 * bit-identical). */
#ifndef PIOLA_WORK_SPLIT_H
#define PIOLA_WORK_SPLIT_H

#include <stdint.h>

#include "piola/elastic_body.h"
#include "piola/export.h"
#include "piola/status.h"
#include "piola/world.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Tets per block: the force loop's SIMD group, the unit of work a split assigns. */
#define PIOLA_WORK_SPLIT_BLOCK 8

typedef struct piola_work_split {
  int32_t part;              /* this process, 0 .. part_count - 1 */
  int32_t part_count;
  const int32_t *block_part; /* per block (piola_elastic_body_block_count): its process */
  const int32_t *node_part;  /* per node: the process that owns it (computes its rows) */
  void *context;             /* passed to the operations */
  void (*sum_nodes)(void *context, double *values);
  void (*share_nodes)(void *context, double *values);
  void (*share_blocks)(void *context, double *values, int32_t width);
} piola_work_split;

/* Number of blocks of PIOLA_WORK_SPLIT_BLOCK tets (the last one padded). */
PIOLA_API int32_t piola_elastic_body_block_count(const piola_elastic_body *body);

/* Sets (or with NULL clears) the body's split. The split and its arrays are not copied and
 * must outlive the body or the next call. A split with part_count 1 changes no bit. */
PIOLA_API piola_status piola_elastic_body_set_work_split(piola_elastic_body *body,
                                                         const piola_work_split *split);

/* NULL when every solid of world can be split, else why not (shells, self-collision and the
 * implicit integrators run on one process only). */
PIOLA_API const char *piola_world_split_unsupported(const piola_world *world);

/* The same for solid `solid` of a world (its index among the solids). */
PIOLA_API piola_status piola_world_solid_set_work_split(piola_world *world, int32_t solid,
                                                        const piola_work_split *split);

#ifdef __cplusplus
}
#endif

#endif
