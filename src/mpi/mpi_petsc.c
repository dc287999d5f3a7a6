/* The Newton systems of a split solid on PETSc (mpi_petsc.h, docs/mpi.md, "Implicit
 * integrators on several processes").
 *
 * Numbering. PETSc's rows are contiguous per process, the nodes a process owns are not: the
 * node of PETSc block row k is node_order[k] (the nodes sorted by owner, increasing within
 * each), so process p owns block rows node_start[p] .. node_start[p + 1] - 1.
 *
 * The matrix is a MATMPIAIJ with block size 3 (Debian 12's PETSc 3.18 has no GAMG on
 * MATMPIBAIJ: "No method creategraph for Mat of type mpibaij"), filled by 3x3 blocks
 * (MatSetValuesBlocked), preallocated once from the mesh edges of the
 * owned rows (row(), which the core fills from the rows it assembled complete: no entry
 * belongs to another process) and refilled in place for every system: every system writes
 * every entry of the pattern (row() gives every edge block, zero or not), so no
 * MatZeroEntries, and no assembly message (MAT_NO_OFF_PROC_ENTRIES). KSPCG runs to the
 * system's relative tolerance in the preconditioned norm (the single process's criterion),
 * from zero, preconditioned by GAMG told the six rigid body modes of the current positions
 * (MatNullSpaceCreateRigidBody), or by block Jacobi with one block per process, each an
 * IC(0). The solution goes to every process (VecScatterCreateToAll) and back to node order.
 *
 * Reuse. GAMG is set up for the first system of a step only; the later systems of the
 * step (the next Newton iterations, whose matrix moved a little) are solved with it as it
 * is (KSPSetReusePreconditioner). Should CG fail with the reused one (any diverged reason,
 * running out of iterations included), the system is solved again from zero with GAMG set
 * up for it, which the next systems then reuse. Measured in BENCHMARKS.md, "MPI: implicit
 * Newton systems on PETSc": GAMG's setup, redone for every system, cost more than the
 * iterations it saved. Block Jacobi + IC(0) is factored for every system (cheap; a stale
 * factor only added iterations). */
#include "mpi/mpi_petsc.h"

#include <petscksp.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"

#ifndef PETSC_SUCCESS /* before PETSc 3.19 (Debian 12 has 3.18) */
#define PETSC_SUCCESS 0
#endif

struct piola__petsc_solver {
  int32_t node_count;
  PetscInt first, owned;   /* this process's block rows */
  const int32_t *order;    /* the node of each block row */
  int32_t *row_of_node;    /* the block row of each node */
  Mat matrix;
  Vec solution, rhs, coordinates, everything;
  VecScatter to_all;
  KSP ksp;
  int32_t *columns;        /* scratch of a row */
  PetscInt *block_columns;
  double *blocks;
  PetscScalar *values;     /* the row's blocks as 3 rows of 3 x count values */
  int32_t widest;
  int prepared; /* the preconditioner was set up for a system of the current step */
};

/* Did this library start PETSc (so it ends it)? */
static int petsc_started;

static PetscErrorCode start_petsc(void) {
  PetscFunctionBeginUser;
  if (!PetscInitializeCalled) {
    /* piola's own error reports and signals: PETSc's handlers stay out */
    PetscCall(PetscInitializeNoArguments());
    PetscCall(PetscPopSignalHandler());
    petsc_started = 1;
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

void piola__petsc_finish(void) {
  if (petsc_started && !PetscFinalizeCalled) (void)PetscFinalize();
  petsc_started = 0;
}

void piola__petsc_solver_free(piola__petsc_solver *s) {
  if (!s) return;
  if (PetscInitializeCalled && !PetscFinalizeCalled) {
    (void)MatDestroy(&s->matrix);
    (void)VecDestroy(&s->solution), (void)VecDestroy(&s->rhs);
    (void)VecDestroy(&s->coordinates), (void)VecDestroy(&s->everything);
    (void)VecScatterDestroy(&s->to_all);
    (void)KSPDestroy(&s->ksp);
  }
  free(s->row_of_node), free(s->columns), free(s->block_columns), free(s->blocks);
  free(s->values);
  free(s);
}

/* The matrix, vectors and solver for the system's pattern (first solve only). */
static PetscErrorCode create(piola__petsc_solver *s, const piola_split_newton_system *system) {
  PetscFunctionBeginUser;
  const PetscInt bs = 3;
  PetscInt *d_nnz, *o_nnz;
  PetscCall(PetscMalloc2(bs * s->owned, &d_nnz, bs * s->owned, &o_nnz));
  for (PetscInt k = 0; k < s->owned; ++k) {
    const int32_t count = system->row(system->owner, s->order[s->first + k], s->columns, s->blocks);
    PetscInt diagonal = 0, off = 0;
    for (int32_t c = 0; c < count; ++c) {
      const int32_t col = s->row_of_node[s->columns[c]];
      if (col >= s->first && col < s->first + s->owned) diagonal += bs;
      else off += bs;
    }
    for (PetscInt a = 0; a < bs; ++a) d_nnz[bs * k + a] = diagonal, o_nnz[bs * k + a] = off;
  }
  PetscCall(MatCreateAIJ(PETSC_COMM_WORLD, bs * s->owned, bs * s->owned, PETSC_DETERMINE,
                         PETSC_DETERMINE, 0, d_nnz, 0, o_nnz, &s->matrix));
  PetscCall(MatSetBlockSize(s->matrix, bs));
  PetscCall(PetscFree2(d_nnz, o_nnz));
  PetscCall(MatSetOption(s->matrix, MAT_SYMMETRIC, PETSC_TRUE));
  PetscCall(MatSetOption(s->matrix, MAT_NO_OFF_PROC_ENTRIES, PETSC_TRUE)); /* own rows only */
  PetscCall(MatCreateVecs(s->matrix, &s->solution, &s->rhs));
  PetscCall(VecDuplicate(s->rhs, &s->coordinates));
  PetscCall(VecSetBlockSize(s->coordinates, bs));
  PetscCall(VecScatterCreateToAll(s->solution, &s->to_all, &s->everything));
  PetscCall(KSPCreate(PETSC_COMM_WORLD, &s->ksp));
  PetscCall(KSPSetType(s->ksp, KSPCG));
  PetscCall(KSPSetNormType(s->ksp, KSP_NORM_PRECONDITIONED));
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode fill(piola__petsc_solver *s, const piola_split_newton_system *system) {
  PetscFunctionBeginUser;
  PetscScalar *b, *x;
  PetscCall(VecGetArray(s->rhs, &b));
  PetscCall(VecGetArray(s->coordinates, &x));
  for (PetscInt k = 0; k < s->owned; ++k) {
    const int32_t node = s->order[s->first + k];
    const PetscInt row = s->first + k;
    const int32_t count = system->row(system->owner, node, s->columns, s->blocks);
    /* MatSetValuesBlocked reads the 3 x 3 count rows, row-major */
    for (int32_t c = 0; c < count; ++c) {
      s->block_columns[c] = s->row_of_node[s->columns[c]];
      for (int a = 0; a < 3; ++a)
        for (int e = 0; e < 3; ++e)
          s->values[(size_t)a * 3 * (size_t)count + 3 * (size_t)c + e] = s->blocks[9 * (size_t)c + 3 * a + e];
    }
    PetscCall(MatSetValuesBlocked(s->matrix, 1, &row, count, s->block_columns, s->values,
                                  INSERT_VALUES));
    for (int a = 0; a < 3; ++a) {
      b[3 * k + a] = system->rhs[3 * (size_t)node + a];
      x[3 * k + a] = system->positions[3 * (size_t)node + a];
    }
  }
  PetscCall(VecRestoreArray(s->rhs, &b));
  PetscCall(VecRestoreArray(s->coordinates, &x));
  PetscCall(MatAssemblyBegin(s->matrix, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(s->matrix, MAT_FINAL_ASSEMBLY));
  /* the first fill made the pattern; later ones only overwrite it */
  PetscCall(MatSetOption(s->matrix, MAT_NEW_NONZERO_LOCATION_ERR, PETSC_TRUE));
  PetscFunctionReturn(PETSC_SUCCESS);
}

/* The solver for the system just filled: its preconditioner set up for it (fresh), or the
 * one of an earlier system as it is. */
static PetscErrorCode set_preconditioner(piola__petsc_solver *s,
                                         const piola_split_newton_system *system, int fresh) {
  PetscFunctionBeginUser;
  PC pc;
  PetscCall(KSPGetPC(s->ksp, &pc));
  PetscCall(KSPSetReusePreconditioner(s->ksp, fresh ? PETSC_FALSE : PETSC_TRUE));
  const int gamg = system->preconditioner == PIOLA_MPI_PRECONDITIONER_GAMG;
  if (fresh && gamg) {
    MatNullSpace rigid;
    PetscCall(MatNullSpaceCreateRigidBody(s->coordinates, &rigid));
    PetscCall(MatSetNearNullSpace(s->matrix, rigid));
    PetscCall(MatNullSpaceDestroy(&rigid));
  }
  PetscCall(PCSetType(pc, gamg ? PCGAMG : PCBJACOBI));
  PetscCall(KSPSetOperators(s->ksp, s->matrix, s->matrix));
  PetscCall(KSPSetTolerances(s->ksp, system->tolerance, 0.0, PETSC_DEFAULT,
                             system->max_iterations));
  PetscCall(KSPSetUp(s->ksp));
  if (fresh && !gamg) {
    KSP *local;
    PetscInt count;
    PetscCall(PCBJacobiGetSubKSP(pc, &count, NULL, &local));
    for (PetscInt k = 0; k < count; ++k) {
      PC sub;
      PetscCall(KSPGetPC(local[k], &sub));
      PetscCall(PCSetType(sub, PCICC));
    }
  }
  PetscFunctionReturn(PETSC_SUCCESS);
}

static PetscErrorCode solve(piola__petsc_solver *s, const piola_split_newton_system *system,
                            double *solution, PetscInt *iterations, KSPConvergedReason *why) {
  PetscFunctionBeginUser;
  if (!s->matrix) PetscCall(create(s, system));
  PetscCall(fill(s, system));
  /* GAMG only: IC(0)'s factorization costs little, and a stale one added CG iterations */
  const int gamg = system->preconditioner == PIOLA_MPI_PRECONDITIONER_GAMG;
  const int reuse = s->prepared && system->step_system > 0 && gamg;
  if (s->prepared && gamg && !reuse) {
    /* a step's GAMG starts from a new solver, as a resumed run's first one does: set up again
     * in the last step's, it kept state a checkpoint does not hold (PCReset alone did not
     * clear it), and a split run resumed from a checkpoint differed from the run that never
     * stopped by about 1e-11 from its first step */
    PetscCall(KSPDestroy(&s->ksp));
    PetscCall(KSPCreate(PETSC_COMM_WORLD, &s->ksp));
    PetscCall(KSPSetType(s->ksp, KSPCG));
    PetscCall(KSPSetNormType(s->ksp, KSP_NORM_PRECONDITIONED));
  }
  PetscCall(set_preconditioner(s, system, !reuse));
  PetscCall(KSPSolve(s->ksp, s->rhs, s->solution));
  PetscCall(KSPGetIterationNumber(s->ksp, iterations));
  PetscCall(KSPGetConvergedReason(s->ksp, why));
  if (reuse && *why < 0) { /* the earlier system's preconditioner does not serve this one */
    PetscInt more = 0;
    PC pc; /* forgotten: PCSetUp would skip a matrix whose state it has seen */
    PetscCall(KSPGetPC(s->ksp, &pc));
    PetscCall(PCReset(pc));
    PetscCall(set_preconditioner(s, system, 1));
    PetscCall(KSPSolve(s->ksp, s->rhs, s->solution));
    PetscCall(KSPGetIterationNumber(s->ksp, &more));
    PetscCall(KSPGetConvergedReason(s->ksp, why));
    *iterations += more;
  }
  s->prepared = 1;
  PetscCall(VecScatterBegin(s->to_all, s->solution, s->everything, INSERT_VALUES, SCATTER_FORWARD));
  PetscCall(VecScatterEnd(s->to_all, s->solution, s->everything, INSERT_VALUES, SCATTER_FORWARD));
  const PetscScalar *all;
  PetscCall(VecGetArrayRead(s->everything, &all));
  for (int32_t k = 0; k < s->node_count; ++k)
    for (int a = 0; a < 3; ++a) solution[3 * (size_t)s->order[k] + a] = all[3 * (size_t)k + a];
  PetscCall(VecRestoreArrayRead(s->everything, &all));
  PetscFunctionReturn(PETSC_SUCCESS);
}

piola_status piola__petsc_solver_create(int rank, int32_t node_count, const int32_t *node_order,
                                        const int32_t *node_start, piola__petsc_solver **out) {
  *out = NULL;
  if (start_petsc() != PETSC_SUCCESS)
    return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED, "implicit step on MPI: PETSc did not start");
  piola__petsc_solver *s = calloc(1, sizeof *s);
  if (!s) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "PETSc solver: out of memory");
  s->node_count = node_count;
  s->order = node_order;
  s->first = node_start[rank];
  s->owned = node_start[rank + 1] - node_start[rank];
  s->row_of_node = malloc(sizeof(int32_t) * (size_t)(node_count > 0 ? node_count : 1));
  if (!s->row_of_node) {
    piola__petsc_solver_free(s);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "PETSc solver: out of memory");
  }
  for (int32_t k = 0; k < node_count; ++k) s->row_of_node[node_order[k]] = k;
  *out = s;
  return PIOLA_OK;
}

int32_t piola__petsc_solve(piola__petsc_solver *s, const piola_split_newton_system *system,
                           double *solution) {
  if (system->max_row_blocks > s->widest) {
    free(s->columns), free(s->block_columns), free(s->blocks), free(s->values);
    s->widest = system->max_row_blocks;
    s->columns = malloc(sizeof(int32_t) * (size_t)s->widest);
    s->block_columns = malloc(sizeof(PetscInt) * (size_t)s->widest);
    s->blocks = malloc(sizeof(double) * 9 * (size_t)s->widest);
    s->values = malloc(sizeof(PetscScalar) * 9 * (size_t)s->widest);
    if (!s->columns || !s->block_columns || !s->blocks || !s->values)
      MPI_Abort(MPI_COMM_WORLD, 1); /* the processes cannot go on apart */
  }
  PetscInt iterations = 0;
  KSPConvergedReason why = KSP_CONVERGED_ITERATING;
  if (solve(s, system, solution, &iterations, &why) != PETSC_SUCCESS)
    MPI_Abort(MPI_COMM_WORLD, 1); /* PETSc has reported it; the processes cannot go on apart */
  /* running out of iterations leaves the best iterate, as the single process's CG does; the
   * line search judges it */
  return (int32_t)iterations;
}
