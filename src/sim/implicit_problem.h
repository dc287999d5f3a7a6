/* The problem of one body's implicit step (implicit_step.c) and its obstacle contacts and
 * friction (implicit_contacts.c): the state the two share, the values a node's hold takes,
 * and the contact passes Newton's method calls between its solves (docs/time-stepping.md,
 * "Implicit integrators", "Friction after the solve"). */
#ifndef PIOLA_SIM_IMPLICIT_PROBLEM_H
#define PIOLA_SIM_IMPLICIT_PROBLEM_H

#include "force/stiffness_incomplete_cholesky.h"
#include "force/stiffness_matrix.h"
#include "force/stiffness_multigrid.h"
#include "sim/world_internal.h"

/* How many times a step with friction is solved again after its first solve with it
 * (piola__newton_next_friction_round): the sliding block of piola__newton_body_may_slide settles in
 * one to three */
#define FRICTION_SLIP_ROUNDS 4

struct implicit_state {
  piola__stiffness_matrix matrix;
  piola__incomplete_cholesky factor; /* a solid's IC(0), when that is the preconditioner */
  int factored;                      /* factor holds the current Newton system's */
  piola__multigrid multigrid; /* a solid's multigrid hierarchy, when that is the preconditioner */
  int multigrid_ready;        /* multigrid serves the current Newton system */
  int multigrid_fresh;        /* the hierarchy was set up in this step (else: set it up) */
  int32_t split_systems;      /* Newton systems of this step solved by the split's solver */
  int after_kept_start;       /* the step before this one kept its start */
  double start_elastic, start_energy; /* J, at the step's start (RECOVERING_DROP) */
  double failed_progress;     /* try_progress of this step's last failed try; -1: none yet */
  int halvings;               /* of the step's try being solved */
  int may_go_deeper;  /* a kept try that would keep only its start is halved on (DEEPER_HALVINGS) */
  int went_deeper;    /* ... and this try was */
  double *prediction; /* 3n: x^n + dt v^n (backward Euler) */
  double *residual;   /* 3n: g, unfiltered */
  double *step;       /* 3n: the Newton direction */
  double *base;       /* 3n: x before the line search */
  double *damping;    /* 3n: D v */
  double *cg[4];      /* 3n each: r, z, p, q */
  double *scratch_v;  /* 3n: velocities handed to the obstacle projection */
  double *surface_v;  /* 3n: velocity of the solid surface a HELD_BY_SOLID node touches */
  double *surface_mu; /* n: a solid's HELD_BY_SOLID node: the pair's friction coefficient */
  double *friction;   /* 3n: the force friction applied to each node in the step, m dv / dt (N) */
  double *friction_free; /* 6n: a converged iterate's positions before friction's
                            moves, then the velocities friction left (newton_iterate) */
  uint8_t *hit;       /* n: nodes the obstacle projection moved */
  double *retry_guess; /* 3n: quasistatics: a failed try's last iterate, the first guess of its
                          retry where the load is the same (newton_body) */
  double retry_guess_t1; /* s: the time that try ended at */
  int has_retry_guess;   /* retry_guess holds one for this step */
};

typedef struct newton_problem {
  piola_world *w;
  world_body *s;
  struct implicit_state *st;
  double t1, dt;
  int quasistatic;
  double beta, alpha; /* viscosities at t1, Pa s */
  int damped;
  double g1[3];        /* gravity at t1 */
  double force_weight; /* dt^2, or 1 in quasistatics */
  double mass_weight;  /* 1, or 0 in quasistatics */
  double total_mass;
  int signed_twist;   /* this Newton system keeps the rotation eigenvalues' sign (the tail) */
  int indefinite;     /* the last CG met non-positive curvature or an indefinite preconditioner */
  int contacts_moved; /* piola__newton_contacts or _release_contacts changed the contact set since
                       * the preconditioner was built */
  int friction_held; /* solved again after friction (piola__newton_friction_moves_deform): the nodes
                      * it stopped are held, the others feel its force, no friction pass */
  int slip_rounds;   /* friction rounds solved since (piola__newton_next_friction_round) */
  int kinetic;       /* the step began its friction with kinetic friction on every contact
                      * (piola__newton_body_may_slide) */
  int resolving;     /* solved again after the collision pass: no halving loop around it, so a
                      * failed try is kept, never handed back to be halved */
} newton_problem;

/* Projects free nodes that are inside an obstacle (or, for a coupled shell, a solid) onto
 * its surface and holds their normal from then on. Returns the number of nodes newly held
 * (at least 1 when any node moved; -1 on error). */
int32_t piola__newton_contacts(newton_problem *pb);
/* Quasistatics, at a step's start: holds the free nodes that rest on an obstacle's surface
 * (on it or just outside), put onto it. Returns how many (0 for backward Euler). */
int32_t piola__newton_resting_contacts(newton_problem *pb);
/* Releases held nodes whose contact force would pull them into the obstacle; on the
 * kinetic-friction path, friction-held nodes only with friction_held_too. Returns how many. */
int32_t piola__newton_release_contacts(newton_problem *pb, int friction_held_too);
/* Coulomb friction node by node with the converged contact forces; returns how many nodes it
 * changed (what it did to each is left in pb->st for a second solve). */
int32_t piola__newton_contact_friction(newton_problem *pb);
/* Whether friction's moves (piola__newton_contact_friction, just run) can flatten or invert
 * the tets (a shell's triangles) they touch. */
int piola__newton_friction_moves_deform(const newton_problem *pb);
/* Whether the body may slide as a whole on its contacts, after a solve without friction. */
int piola__newton_body_may_slide(const newton_problem *pb);
/* Kinetic friction on every obstacle contact, into pb->st->friction; returns how many nodes
 * feel it. */
int32_t piola__newton_kinetic_friction(newton_problem *pb);
/* One more friction round after a converged solve with friction: whether it changed the
 * friction enough that the step is to be solved again. */
int piola__newton_next_friction_round(newton_problem *pb);
/* Whether gravity's step alone would take a free node into an obstacle (1, else 0; -1 on
 * error). */
int piola__newton_gravity_step_enters_obstacle(newton_problem *pb);

#endif
