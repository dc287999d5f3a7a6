/* Checkpoints of `mpirun -np N piola run` (run_split_checkpoints.c, docs/mpi.md): one file
 * per process, DIR/checkpoint_NNNN_pK.bin, committed by process 0's
 * DIR/checkpoint_NNNN.manifest (the process count, the scene key and the partition); they
 * resume on the same number of processes only. */
#ifndef PIOLA_CLI_RUN_SPLIT_CHECKPOINTS_H
#define PIOLA_CLI_RUN_SPLIT_CHECKPOINTS_H

#include <stdint.h>

#include "cli/run_mpi.h"
#include "piola/world.h"

/* Every process writes its file of frame, then process 0 the manifest; then all but the
 * newest two sets are removed. Collective; 1 when every process succeeded (failures are
 * printed where they happened). */
int run_split_checkpoint_save(run_mpi *m, const char *dir, const piola_world *world, uint64_t key,
                              int32_t frame);

/* Loads the newest checkpoint set of dir that fits this run and that every process reads
 * intact (a cut state included: its solids are partitioned again once every process has
 * read its file, docs/mpi.md "Checkpoints"). Collective. Returns 0 with *frame set; 1 when
 * dir holds no checkpoint at all; 2 (message printed) when refused: another process count
 * (the message names the one to use), scene or partition, a single process's checkpoints,
 * or none intact. */
int run_split_checkpoint_resume(run_mpi *m, const char *dir, piola_world *world, uint64_t key,
                                int32_t *frame);

/* The process count of dir's newest manifest: 0 when dir holds none, -1 when unreadable. */
int run_split_checkpoint_processes(const char *dir);

#endif
