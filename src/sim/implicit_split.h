/* The Newton systems of a solid split among processes (implicit_split.c): the one call the
 * implicit step makes instead of its own conjugate gradient. */
#ifndef PIOLA_SIM_IMPLICIT_SPLIT_H
#define PIOLA_SIM_IMPLICIT_SPLIT_H

#include "force/stiffness_matrix.h"
#include "piola/work_split.h"
#include "sim/body.h"

/* s's split when its Newton systems go to the split's solver (a solid split over more than
 * one process, with solve_newton), else NULL. */
const piola_work_split *piola__implicit_split_of(const world_body *s);

/* Solves matrix d = -S residual (S the constraint filter) with the split's solver to the
 * relative tolerance; step_system: the system's index in its step (0: the step's first,
 * piola_split_newton_system); rhs is 3n scratch. Returns the iterations, -1 on failure.
 * Collective. */
int32_t piola__implicit_split_solve(const world_body *s, const piola__stiffness_matrix *matrix,
                                    const double *residual, double tolerance,
                                    const piola_world_def *def, int32_t step_system, double *rhs,
                                    double *step);

/* The trace of the assembled matrix's diagonal blocks, over every node (on a split, each
 * process's owned nodes, added in process order). Collective on a split. */
double piola__implicit_matrix_trace(const world_body *s, const piola__stiffness_matrix *matrix);

#endif
