/* piola: splitting an elastic body's per-tet work among cooperating processes.
 *
 * The core knows nothing of MPI: a process that runs with others (libpiola_mpi,
 * docs/mpi.md) hands each elastic body a piola_work_split, which says which blocks of
 * PIOLA_WORK_SPLIT_BLOCK consecutive tets this process computes and which process owns each
 * node, and gives the collective operations the body calls. Every process keeps the whole
 * mesh and the whole node state (positions, velocities, forces); the split divides the work
 * of the force loop and of the damping products, and, in the local mode, the per-tet state.
 *
 * With a split set, piola_elastic_body_update runs the force loop (F, its diagonalization,
 * stress, muscle fibres, nodal forces) on this process's blocks only, then sum_nodes turns
 * each process's partial nodal forces (3 per node, zero away from its tets) into the total on
 * every process, bit-identical on all of them, and the damping products compute the rows of
 * this process's nodes only, then share_nodes gives every process every node's 3 values
 * (written by the node's owner). What happens to the per-tet state (U, V, Fhat, det F) of
 * the force loop depends on the mode:
 *   - replicated (a split without the local operations, or a solid with plasticity, whose
 *     return mapping runs on every tet of every process, or with fracture, whose criteria
 *     read every tet's state on every process): share_blocks gives every process
 *     every block's state, written by the block's process;
 *   - local (share_ghosts, reduce and collect_blocks given, no plasticity or fracture): a
 *     process holds the state of its own blocks and of its ghost blocks, the other processes'
 *     blocks with a tet on one of its nodes (the damping rows of its nodes need their
 *     rotations), which share_ghosts brings (U and V; Fhat too before each Newton assembly);
 *     the step bound and the statistics of piola_elastic_body_update are reduced over the
 *     processes. The state of the other blocks is never written here: its memory stays
 *     untouched (allocated, not resident), and the getters (det F, Fhat, energy density)
 *     hold it only on process 0 after piola_world_split_collect.
 * All processes must make the same calls in the same order (they do: their node states are
 * bit-identical). */
#ifndef PIOLA_WORK_SPLIT_H
#define PIOLA_WORK_SPLIT_H

#include <stdint.h>

#include "piola/elastic_body.h"
#include "piola/export.h"
#include "piola/mesh.h"
#include "piola/scene.h"
#include "piola/status.h"
#include "piola/world.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Tets per block: the force loop's SIMD group, the unit of work a split assigns. */
#define PIOLA_WORK_SPLIT_BLOCK 8

/* Reductions of piola_work_split.reduce. */
typedef enum piola_work_split_reduction {
  PIOLA_WORK_SPLIT_SUM, /* summed in process order, the same bits on every process */
  PIOLA_WORK_SPLIT_MAX,
  PIOLA_WORK_SPLIT_MIN
} piola_work_split_reduction;

/* Writes block `block`'s values (width doubles) to out, or reads them from in. */
typedef void (*piola_work_split_pack)(void *owner, int32_t block, double *out);
typedef void (*piola_work_split_unpack)(void *owner, int32_t block, const double *in);

/* A Newton system of the implicit integrators on a split solid (docs/mpi.md, "Implicit
 * integrators on several processes"): A d = b, A symmetric positive definite with 3x3 blocks
 * on the mesh edges. Each process gives the rows of the nodes it owns (node_part), complete
 * and with the single process's bits; constrained components are projected out (A's
 * filtered rows and columns are those of the identity, b's components zero), so the solution
 * is the one the single process's filtered conjugate gradient converges to. */
typedef struct piola_split_newton_system {
  int32_t node_count;
  const double *positions; /* 3 per node, m: where the nodes are (the rigid body modes) */
  const double *rhs;       /* 3 per node, every node (the same on every process): b */
  int32_t max_row_blocks;  /* the most blocks a row has */
  /* Row `node` (owned here): its columns (node indices, the diagonal first) and its 3x3
   * blocks (9 each, row-major); returns how many. */
  int32_t (*row)(const void *owner, int32_t node, int32_t *columns, double *blocks);
  const void *owner;
  double tolerance;       /* stop at this fraction of the initial residual (preconditioner norm) */
  int32_t max_iterations; /* iterations at most */
  piola_mpi_preconditioner preconditioner;
  /* 0 for the first Newton system of a step (or of a retried step), then 1, 2, ...: a solver
   * may reuse for a later system what it set up for an earlier one of the same step */
  int32_t step_system;
} piola_split_newton_system;

typedef struct piola_work_split {
  int32_t part;              /* this process, 0 .. part_count - 1 */
  int32_t part_count;
  const int32_t *block_part; /* per block (piola_elastic_body_block_count): its process */
  const int32_t *node_part;  /* per node: the process that owns it (computes its rows) */
  void *context;             /* passed to the operations */
  void (*sum_nodes)(void *context, double *values);
  void (*share_nodes)(void *context, double *values);
  void (*share_blocks)(void *context, double *values, int32_t width);
  /* The local mode's operations (all NULL: the replicated mode). share_ghosts: each process
   * packs those of its blocks that have a tet on a node another process owns and sends them
   * there; each receiving process unpacks them (its ghost blocks). reduce: count values
   * combined over the processes, the result on every process. collect_blocks: every block's
   * values on process 0 (packed by the block's process; unpack runs on process 0 only). */
  void (*share_ghosts)(void *context, void *owner, piola_work_split_pack pack,
                       piola_work_split_unpack unpack, int32_t width);
  void (*reduce)(void *context, double *values, int32_t count, piola_work_split_reduction op);
  void (*collect_blocks)(void *context, void *owner, piola_work_split_pack pack,
                         piola_work_split_unpack unpack, int32_t width);
  /* Optional, for the implicit integrators: solves system (collective) and
   * writes every node's 3 values of the solution to solution on every process (the same
   * bits everywhere); returns the iterations, or -1 with the error set. NULL: a world with
   * an implicit integrator refuses the split. */
  int32_t (*solve_newton)(void *context, const piola_split_newton_system *system,
                          double *solution);
} piola_work_split;

/* Number of blocks of PIOLA_WORK_SPLIT_BLOCK tets (the last one padded). */
PIOLA_API int32_t piola_elastic_body_block_count(const piola_elastic_body *body);

/* Sets (or with NULL clears) the body's split. The split and its arrays are not copied and
 * must outlive the body or the next call. A split with part_count 1 changes no bit. */
PIOLA_API piola_status piola_elastic_body_set_work_split(piola_elastic_body *body,
                                                         const piola_work_split *split);

/* The body's split (as set), or NULL when it has none. */
PIOLA_API const piola_work_split *piola_elastic_body_work_split(const piola_elastic_body *body);

/* Whether body runs its split in the local mode (above). */
PIOLA_API int piola_elastic_body_split_is_local(const piola_elastic_body *body);

/* Collective, for the frames: makes the per-tet state (Fhat, det F, energy density) of every
 * tet whole on process 0 for every solid split in the local mode (nothing to do otherwise).
 * Every process calls it; process 0 may then read the getters and the solid statistics. */
PIOLA_API piola_status piola_world_split_collect(piola_world *world);

/* A split planned from a solid's rest mesh before its body is built (libpiola_mpi's
 * piola_mpi_split_planner): a world with a planner asks it for the split of each solid it
 * adds whose per-tet state can be local (no plasticity, the Newmark integrator), sets the split before the solid's first update, and writes the per-tet state
 * (U, V, Fhat, det F, Dm^-1, the damping matrix's tet slots) of this process's own and ghost
 * blocks only: no process ever holds every tet's state, not even while the world is built
 * (docs/mpi.md, "Memory"). plan gets the solid's index among the solids and its mesh as
 * given to piola_world_add_solid (blocks are its tets in order, PIOLA_WORK_SPLIT_BLOCK at a
 * time); it sets *out to the split, which must outlive the body, or to NULL to leave the
 * solid whole (split later, or never). Collective: every process adds the same solids in
 * the same order, and plan fails on all of them or on none. */
typedef struct piola_work_split_planner {
  piola_status (*plan)(void *context, int32_t solid, const piola_tet_mesh *mesh,
                       const piola_work_split **out);
  void *context;
} piola_work_split_planner;

/* Sets (or with NULL clears) the planner of the solids added to world from now on. The
 * planner is copied. */
PIOLA_API void piola_world_set_work_split_planner(piola_world *world,
                                                  const piola_work_split_planner *planner);

/* Sets (or with NULL clears) the planner of the split solids whose mesh changes (a cut:
 * world_fracture.h): after such a solid's body is rebuilt for its new mesh, the world asks
 * it (plan, with the solid's index and its new mesh: the tets of the new body, rest
 * positions) for the new body's split, and sets it in the replicated mode (a solid that can
 * break holds every tet's state on every process, so every process takes the same fracture
 * decisions). The split the solid had before may be freed by plan: no body refers to it any
 * more. NULL from plan, or no replanner: the rebuilt body is whole on every process
 * (correct, every process computing everything). Collective like the cut itself: every
 * process cuts the same tets at the same step. The planner is copied. */
PIOLA_API void piola_world_set_work_split_replanner(piola_world *world,
                                                    const piola_work_split_planner *planner);

/* While defer is on, a split solid whose mesh changes (a checkpoint read giving a solid a
 * cut state: docs/mpi.md, "Checkpoints") is left whole on this process and marked pending
 * instead of asking the replanner, so that the change takes no collective step and a
 * process whose read fails cannot leave the others waiting. Turning it off keeps the marks:
 * once every process has read its state, piola_world_solid_replan_work_split splits each
 * solid pending on any of them. */
PIOLA_API void piola_world_defer_work_split_replans(piola_world *world, int defer);

/* Whether solid `solid` (its index among the solids) is pending as above. */
PIOLA_API int piola_world_solid_split_pending(const piola_world *world, int32_t solid);

/* Asks the replanner for the split of solid `solid`'s current mesh and sets it in the
 * replicated mode, whether the solid is whole (pending) or split (the old split is taken
 * off first: the replanner may free it), and clears the mark. It changes no state but the
 * split's own (the damping operator and the next solve's start are made afresh, as after a
 * cut: read the state again afterwards to restore them). Collective: every process replans
 * the same solids in the same order. */
PIOLA_API piola_status piola_world_solid_replan_work_split(piola_world *world, int32_t solid);

/* piola_scene_build with planner set on the scene's world before its solids are added. */
PIOLA_API piola_status piola_scene_build_split(const piola_scene_desc *desc,
                                               const piola_work_split_planner *planner,
                                               piola_scene **out);

/* NULL when every solid of world can be split by splits without solve_newton, else why not
 * (shells and, without solve_newton, the implicit integrators run on one process only). */
PIOLA_API const char *piola_world_split_unsupported(const piola_world *world);

/* The same for splits with solve_newton: the implicit integrators can be split. */
PIOLA_API const char *piola_world_split_unsupported_solving(const piola_world *world);

/* The same for solid `solid` of a world (its index among the solids). */
PIOLA_API piola_status piola_world_solid_set_work_split(piola_world *world, int32_t solid,
                                                        const piola_work_split *split);

#ifdef __cplusplus
}
#endif

#endif
