/* `piola run` on several MPI processes (docs/mpi.md): started by mpirun, every process loads
 * the scene and steps the whole world, the solids' per-tet work split among them
 * (libpiola_mpi); process 0 alone writes the output. In a build without PIOLA_MPI, or not
 * started by mpirun, the run is the single process it always was and MPI is never touched. */
#ifndef PIOLA_CLI_RUN_MPI_H
#define PIOLA_CLI_RUN_MPI_H

#include <stdbool.h>

#include "piola/scene.h"
#include "piola/world.h"

typedef struct run_mpi {
  int rank, size;  /* 0 and 1 for a single process */
  bool started;    /* MPI_Init ran */
  void *split;     /* piola_mpi_split of the world, or NULL */
} run_mpi;

/* Starts MPI when the process was launched by mpirun; false (message printed) on failure. */
bool run_mpi_start(run_mpi *m);
/* Loads the scene at path (piola_scene_load); with more than one process each solid is
 * partitioned as it is added, and each process builds only its own and ghost blocks' per-tet
 * state (piola_mpi_split_planner). Collective. */
piola_status run_mpi_load(run_mpi *m, const char *path, piola_scene **out);
/* Splits world's solids among the processes (size > 1 only; those run_mpi_load planned are
 * split already); false with a message on stderr when the world has something that runs on
 * one process only. Collective. */
bool run_mpi_split(run_mpi *m, piola_world *world);
/* Before process 0 reads the solids' per-tet state (a frame, statistics, a failure report):
 * brings every process's share of it to process 0 (collective; nothing without a split). */
void run_mpi_collect(run_mpi *m, piola_world *world);
/* Prints each process's share and exchange figures (process 0), at the end of a run. */
void run_mpi_report(run_mpi *m);
/* Whether every process says ok (collective; ok itself for a single process). */
bool run_mpi_all(run_mpi *m, bool ok);
/* The largest value over the processes (collective; value itself for a single process). */
int run_mpi_max(run_mpi *m, int value);
/* Process 0's value on every process (collective; value itself for a single process). */
int run_mpi_from_lead(run_mpi *m, int value);
/* Takes the split off world and ends MPI. */
void run_mpi_finish(run_mpi *m, piola_world *world);

#endif
