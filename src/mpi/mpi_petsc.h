/* The Newton systems of a split solid solved by PETSc (mpi_petsc.c, docs/mpi.md, "Implicit
 * integrators on several processes"): libpiola_mpi's solve_newton (piola/work_split.h),
 * built where PETSc is (PIOLA_PETSC). */
#ifndef PIOLA_MPI_PETSC_H
#define PIOLA_MPI_PETSC_H

#include <stdint.h>

#include "piola/work_split.h"

typedef struct piola__petsc_solver piola__petsc_solver;

/* A solver for a solid whose node of PETSc block row k is node_order[k], process p owning
 * rows node_start[p] .. node_start[p + 1] - 1 (the arrays must outlive it). Starts PETSc
 * on first use (after MPI). Collective. */
piola_status piola__petsc_solver_create(int rank, int32_t node_count, const int32_t *node_order,
                                        const int32_t *node_start, piola__petsc_solver **out);
void piola__petsc_solver_free(piola__petsc_solver *solver);

/* solve_newton: collective; every process gets the whole solution. Returns the CG
 * iterations (aborts all processes if PETSc fails). */
int32_t piola__petsc_solve(piola__petsc_solver *solver, const piola_split_newton_system *system,
                           double *solution);

/* Ends PETSc if this library started it (after every solver is freed, before MPI ends). */
void piola__petsc_finish(void);

#endif
