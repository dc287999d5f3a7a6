/* The world's state, shared by world.c (setup, accessors), constraints.c and integrator.c.
 *
 * Each solid keeps its hot per-node arrays (positions, velocities, inverse masses, the
 * elastic force at the current positions) as flat xyz arrays so the step loop and the
 * conjugate gradient are plain loops over doubles. The elastic force and the diagonalization
 * inside the body always belong to the current positions: they are computed once per step,
 * after collisions, and reused by the next step's first solve. */
#ifndef PIOLA_SIM_WORLD_INTERNAL_H
#define PIOLA_SIM_WORLD_INTERNAL_H

#include <stdint.h>

#include "piola/world.h"
#include "piola/world_shells.h"
#include "sim/step_profile.h"

enum { SOLID_FREE = 0, SOLID_FIXED = 1, SOLID_DRIVEN = 2 };

typedef struct world_solid {
  char *name;
  piola_elastic_body *body;  /* a tetrahedral solid, or NULL for a shell */
  piola_shell_body *shell;   /* a shell (world_shells.c), or NULL */
  piola_shell_stats shell_stats; /* of the last update, shells only */
  int collide_with_solids;   /* shells: one-way coupling to the solids' surfaces */
  double solid_friction;     /* shells: Coulomb mu against solids */
  piola_tri_mesh *boundary;  /* solids: boundary surface, built when a shell first needs it */
  double boundary_reach;     /* solids: longest boundary edge, m */
  int32_t n;                 /* vertex count */
  double *x, *v;             /* 3n current state */
  double *mass;              /* n lumped masses, kg */
  double *inverse_mass;      /* n, 0 for massless (isolated) vertices, which are held fixed */
  double *force;             /* 3n elastic force at x, N */
  double *start;             /* 3n positions of constrained nodes at t = 0 */
  uint8_t *flags;            /* n: SOLID_FREE / FIXED / DRIVEN */
  int32_t *motion_of;        /* n: index into motions for driven nodes, else -1 */
  piola_rigid_motion_def *motions;
  int32_t motion_count;
  piola_track stiffness_scale, shear_viscosity, bulk_viscosity;
  piola_track activation;       /* muscle fibres' activation, set before every force update */
  piola_elastic_stats elastic;  /* of the last update, once refreshed (world.c) */
  int elastic_stale;            /* elastic does not match the last update yet */
  piola_plastic_state *plastic; /* NULL for an elastic solid (world_plasticity.c) */
  piola_plastic_stats plastic_stats; /* of the last plastic update */
  piola_self_collision_def self_collision;
  /* scratch for the step */
  double *x_old, *v_old, *force_old, *rhs, *work, *tmp;
  /* the final solve's A v (3n) and the v it was taken at (3n), with its h and the damping
   * assembly it used: the next step's first solve starts from it (integrator.c) */
  double *av_product, *v_product;
  double product_h;
  uint64_t product_generation;
  int product_valid;
  uint8_t *colliding;
  double *normals;
  struct implicit_state *implicit; /* the implicit integrators' matrix and vectors, made on
                                      their first step (implicit_step.c) */
} world_solid;

struct piola_world {
  piola_world_def def;
  double time;
  world_solid *solids;
  int32_t solid_count, solid_capacity;
  world_solid *shells;        /* shells step like solids, with a shell body (world_shells.c) */
  int32_t shell_count, shell_capacity;
  piola_obstacle **obstacles;
  int32_t obstacle_count, obstacle_capacity;
  struct world_contact *contact; /* self-collision of boundary surfaces (world_contact.c) */
  double collision_deadline;  /* advance_to's target, which closes a collision interval too;
                                 NAN outside advance_to */
  step_profile profile;       /* per-phase step timers, off unless a benchmark turns them on */
};

/* Marks constrained nodes of s from its constraint defs (rest positions rest, 3n). */
/* Shared by add_solid and add_shell (world.c). new_slot appends a zeroed entry to a
 * world_solid array (NULL when out of memory); allocate sizes the per-node state and
 * scratch for n nodes, names the body (kind and id when name is NULL) and copies its rest
 * positions and lumped masses; finish_masses sets inverse masses once constraints are in
 * and fixes massless vertices. */
world_solid *piola__world_new_slot(world_solid **items, int32_t count, int32_t *capacity);
piola_status piola__solid_allocate(world_solid *s, int32_t n, const char *name, const char *kind,
                                   int32_t id, const double *rest, const double *mass);
void piola__solid_finish_masses(world_solid *s);

/* True when rest position p (3 doubles, m) lies in a box or sphere selector (index lists
 * select by index, not by position: false). Shared by constraints and bone attachments. */
int piola__selector_contains(const piola_selector *sel, const double *p);
piola_status piola__solid_apply_constraints(world_solid *s, const double *rest,
                                            const piola_constraint_def *constraints,
                                            int32_t count);
/* Prescribed position (m) and velocity (m/s) of constrained node i at time t. */
void piola__solid_constrained_state(const world_solid *s, int32_t i, double t, double x[3],
                                    double v[3]);
/* Recomputes the elastic force of s at its positions x and time t (stiffness scale). */
piola_status piola__solid_update_forces(world_solid *s, double t);
/* Frees everything s owns (world.c). */
void piola__solid_free(world_solid *s);

/* Shells (world_shells.c): the body-kind dispatch the step loop needs. */
/* Damping force at velocities v of a solid or a shell (out overwritten, N). */
void piola__solid_damping_forces(const world_solid *s, const double *v, double beta,
                                 double alpha, double *out);
/* True when s has no damping at all (its damping solve is a diagonal one). */
int piola__solid_undamped(const world_solid *s, double beta, double alpha);
/* Elastic force update of a shell (called by piola__solid_update_forces). */
piola_status piola__shell_update_forces(world_solid *s, double t);
/* One-way coupling (world_shells.c): pushes the free nodes of shell s out of the solids'
 * current boundary surfaces at t1 after a step of dt, as obstacle collisions do; flags and
 * normals are set for the final solve. Returns the number of nodes it moved. */
int32_t piola__shell_collide_with_solids(piola_world *w, world_solid *s, double t1, double dt);
/* The step bound of a shell (in-plane CFL and bending time scale), s. */
double piola__shell_stable_dt(const piola_world *w, const world_solid *s, double scale);

/* Plasticity of a solid (world_plasticity.c). Creation binds a plastic state to s->body
 * when def asks for one; the update runs once per step, after the whole step succeeded,
 * from the diagonalization of the step's force evaluation; the stiffening factor (>= 1)
 * divides the CFL step. */
piola_status piola__solid_plastic_create(world_solid *s, const piola_solid_def *def);
void piola__solid_plastic_update(world_solid *s, double dt);
double piola__solid_plastic_stiffening(const world_solid *s);
/* Self-collision (world_contact.c), once per collision interval (piola_world_def.
 * collision_interval; 0: every step).
 * collision_open runs before a step: it builds the collision surface on first use or when
 * bodies were added, opens an interval when none is open (keeping the positions at its
 * start) and gives the time left to the interval's end (s; INFINITY when collisions run
 * after every step or no body has self-collision); the step that reaches it ends the
 * interval.
 * self_collide runs after a step of length dt (s) that every body has taken from x_old to x
 * and that ends at t1: when collisions run every step, or when closes != 0 (the step ends
 * the interval), it changes x and v of bodies with self-collision enabled from the average
 * velocity over the step or interval (and recomputes their forces at time t1) and adds to
 * stats; otherwise it does nothing. collision_reset drops the open interval (the state was
 * set from outside). */
piola_status piola__world_collision_open(piola_world *w, double *left);
piola_status piola__world_self_collide(piola_world *w, double dt, double t1, int closes,
                                       piola_step_stats *stats);
void piola__world_collision_reset(piola_world *w);
void piola__world_contact_free(piola_world *w);

/* The implicit integrators (implicit_step.c): piola_world_step and the step size for
 * PIOLA_INTEGRATOR_BACKWARD_EULER and PIOLA_INTEGRATOR_QUASISTATIC; implicit_state_free
 * frees a solid's implicit state (NULL is fine). */
piola_status piola__implicit_world_step(piola_world *w, double dt_limit, piola_step_stats *stats);
void piola__implicit_state_free(struct implicit_state *state);

/* 1 (default): the step's second right-hand side takes D_n v' from the first solve's
 * initial product plus a correction on the nodes collisions and constraints moved
 * (integrator.c); 0: a full damping pass. For tests comparing the two. */
extern int piola__step_reuse_first_product;

#endif
