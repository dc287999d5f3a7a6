/* piola: running a world on several MPI processes (libpiola_mpi, docs/mpi.md).
 *
 * Built only where OpenMPI and METIS are found (CMake option PIOLA_MPI). The caller
 * initializes MPI; piola_mpi_split_world then splits the per-tet work of every solid of
 * `world` among the processes of MPI_COMM_WORLD: METIS partitions each solid's blocks of
 * PIOLA_WORK_SPLIT_BLOCK tets (their dual graph, weighted by real tets), and each process
 * computes the force loop of its blocks and the damping rows of its nodes; solids without
 * plasticity keep only their own and ghost blocks' per-tet state (the local mode,
 * piola/work_split.h). Every process must build the same world and call this, and then
 * step it in the same way: the node states stay bit-identical on all of them. Before
 * process 0 reads per-tet state (frames, statistics), every process calls
 * piola_world_split_collect.
 *
 *   MPI_Init(&argc, &argv);
 *   piola_mpi_split *split;
 *   if (piola_mpi_split_world(world, &split) != PIOLA_OK) puts(piola_last_error());
 *   ... piola_world_advance_to(world, t, NULL) on every process ...
 *   piola_mpi_split_destroy(split);  // before the world
 *   MPI_Finalize(); */
#ifndef PIOLA_MPI_H
#define PIOLA_MPI_H

#include <stdint.h>

#include "piola/export.h"
#include "piola/status.h"
#include "piola/work_split.h"
#include "piola/world.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct piola_mpi_split piola_mpi_split;

typedef struct piola_mpi_split_stats {
  int32_t rank, size;      /* this process in MPI_COMM_WORLD */
  int64_t tets;            /* real tets whose force loop this process runs, all solids */
  int64_t owned_nodes;     /* nodes whose damping rows this process computes */
  int64_t shared_nodes;    /* nodes of this process's tets that other processes' tets touch */
  int64_t halo_bytes;      /* bytes this process sent in halo messages (node sums and ghost
                              blocks) so far */
  int64_t gather_bytes;    /* bytes this process received in the gathers (nodes, blocks) so far */
  double halo_seconds;     /* s spent in halo exchanges (pack, wait, sum) so far */
  double gather_seconds;   /* s spent in the gathers so far */
  double exchange_cpu_seconds; /* s of CPU time of the calling thread in all the exchanges
                                  (halo, ghosts, gathers, reductions) so far: the rest of a
                                  step's CPU time is its own work */
  int64_t replans;         /* partitions made again for a solid a cut changed, so far */
  double replan_seconds;   /* s spent in them (METIS on process 0, the broadcast, the plan) */
} piola_mpi_split_stats;

/* Splits every solid of world among the processes of MPI_COMM_WORLD (MPI initialized).
 * Worlds with shells or an implicit integrator (without PETSc) are refused
 * (PIOLA_ERROR_UNSUPPORTED, naming what). Collective: every process calls it. Each process
 * has built the whole world first; to build only each process's part, use the planner
 * below instead. */
PIOLA_API piola_status piola_mpi_split_world(piola_world *world, piola_mpi_split **out);

/* The same in three steps, so that no process builds the whole world:
 *
 *   piola_mpi_split *split;
 *   piola_mpi_split_create(&split);
 *   piola_work_split_planner planner = piola_mpi_split_planner(split);
 *   piola_world_set_work_split_planner(world, &planner);  // or piola_scene_build_split
 *   ... piola_world_add_solid ...  // each solid partitioned (METIS) before its body is built
 *   piola_mpi_split_finish(split, world);
 *
 * piola_mpi_split_create makes an empty split; the planner partitions each solid as it is
 * added (piola/work_split.h: those that can run in the local mode); piola_mpi_split_finish
 * takes the planner off the world, refuses what piola_mpi_split_world refuses, and splits
 * the solids the planner left whole (with plasticity: the replicated mode). Every process
 * makes the same calls. On failure, piola_mpi_split_destroy still frees the split. */
PIOLA_API piola_status piola_mpi_split_create(piola_mpi_split **out);
PIOLA_API piola_work_split_planner piola_mpi_split_planner(piola_mpi_split *split);
PIOLA_API piola_status piola_mpi_split_finish(piola_mpi_split *split, piola_world *world);
PIOLA_API piola_mpi_split_stats piola_mpi_split_stats_of(const piola_mpi_split *split);
/* Takes the splits off the world's solids (world may be NULL if already destroyed). */
PIOLA_API void piola_mpi_split_destroy(piola_mpi_split *split, piola_world *world);

#ifdef __cplusplus
}
#endif

#endif
