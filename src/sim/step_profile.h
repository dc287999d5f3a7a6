/* Where a world step's time goes: optional per-phase timers for benchmarks.
 *
 * The speed target of a full step (issue 3) needs to know which part of the step to work
 * on: the elastic update, the two damping solves (and in them the operator applies versus
 * the conjugate gradient's own vector work), collisions. A world keeps one of these; it is
 * off by default, and then the step reads no clock at all (a clock read costs far less than
 * a step of a large body but is not free for the tiny ones). When on, every phase adds its
 * wall time, the calling thread's CPU time (which leaves out time other processes hold the
 * core, so it is steadier on a shared machine) and the process CPU time (all threads). */
#ifndef PIOLA_SIM_STEP_PROFILE_H
#define PIOLA_SIM_STEP_PROFILE_H

#include <stdint.h>

typedef enum step_phase {
  STEP_PHASE_SETUP,     /* copies, right-hand side of solve 1, constrained nodes */
  STEP_PHASE_PREPARE,   /* damping operator set-up from the last elastic update */
  STEP_PHASE_SOLVE1,    /* (M - dt/2 D_n) v~ = ... */
  STEP_PHASE_COLLIDE,   /* x~ and collisions with obstacles */
  STEP_PHASE_RHS2,      /* D_n v' and the right-hand side of solve 2 */
  STEP_PHASE_UPDATE,    /* F, diagonalization, elastic forces (and stats) at x^n+1 */
  STEP_PHASE_SOLVE2,    /* (M - dt/2 D_n+1) v^n+1 = ... */
  STEP_PHASE_FRICTION,  /* A v^n+1 and the friction of the held normal impulse */
  STEP_PHASE_CHECK,     /* finiteness and energy checks */
  STEP_PHASE_WORLD,     /* stable dt, self-collision, plasticity: outside the solids' steps */
  /* the implicit integrators (implicit_step.c); their force evaluations count as update */
  STEP_PHASE_ASSEMBLE,  /* the projected stiffness and the Newton system's preconditioner */
  STEP_PHASE_LINEAR,    /* the Newton system's linear solve */
  STEP_PHASE_COUNT
} step_phase;

typedef struct step_profile {
  int enabled;
  int64_t steps;
  double wall[STEP_PHASE_COUNT], thread_cpu[STEP_PHASE_COUNT], cpu[STEP_PHASE_COUNT]; /* s */
  /* inside the two solves: the damping operator applies (one per CG iteration and one per
   * solve for the initial residual) */
  int64_t applies;
  double apply_wall, apply_thread_cpu, apply_cpu; /* s */
  /* the clocks at the last mark and at the start of the current apply */
  double last_wall, last_thread_cpu, last_cpu;
  double apply_start_wall, apply_start_thread_cpu, apply_start_cpu;
} step_profile;

/* Short names of the phases for tables, STEP_PHASE_COUNT of them. */
extern const char *const piola__step_phase_names[STEP_PHASE_COUNT];

/* Clears the sums and switches the profile on (enabled != 0) or off. */
void piola__step_profile_reset(step_profile *p, int enabled);
/* Starts timing: the next mark measures from here. No-op when off. */
void piola__step_profile_start(step_profile *p);
/* Adds the time since the last start or mark to phase and restarts. No-op when off. */
void piola__step_profile_mark(step_profile *p, step_phase phase);
/* Brackets one damping operator apply inside a solve (begin != 0 before it, 0 after it).
 * No-op when off. */
void piola__step_profile_apply(step_profile *p, int begin);

#endif
