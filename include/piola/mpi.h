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
} piola_mpi_split_stats;

/* Splits every solid of world among the processes of MPI_COMM_WORLD (MPI initialized).
 * Worlds with shells, self-collision or an implicit integrator are refused
 * (PIOLA_ERROR_UNSUPPORTED, naming what). Collective: every process calls it. */
PIOLA_API piola_status piola_mpi_split_world(piola_world *world, piola_mpi_split **out);
PIOLA_API piola_mpi_split_stats piola_mpi_split_stats_of(const piola_mpi_split *split);
/* Takes the splits off the world's solids (world may be NULL if already destroyed). */
PIOLA_API void piola_mpi_split_destroy(piola_mpi_split *split, piola_world *world);

#ifdef __cplusplus
}
#endif

#endif
