/* The world's state, shared by the files of src/sim.
 *
 * How the world is laid out, for a newcomer:
 *  - the bodies (body.h): one table, bodies[0 .. body_count), of every deformable thing the
 *    step advances, each with a kind tag (solid, shell). The table is ordered by kind
 *    (solids first, then shells, each in the order added), which fixes the order in which
 *    bodies step and enter the collision surface. body_table.c keeps it (insertion, the
 *    slots behind the public ids, lookups by kind and index); body.c dispatches the
 *    operations that depend on the kind; world_solids.c and world_shells.c hold each kind's
 *    own code (creation, forces, step bound, stats);
 *  - the obstacles (obstacle.c, obstacles/): rigid, keyframed shapes the bodies collide with
 *    inside the step;
 *  - the contact between bodies (world_contact.c): one collision surface over every body
 *    with self-collision, processed after the step;
 *  - the step (integrator.c): the Newmark scheme, one loop over the bodies, then contact,
 *    then plasticity. */
#ifndef PIOLA_SIM_WORLD_INTERNAL_H
#define PIOLA_SIM_WORLD_INTERNAL_H

#include <stdint.h>

#include "piola/work_split.h"
#include "piola/world.h"
#include "piola/world_bodies.h"
#include "piola/world_shells.h"
#include "sim/body.h"
#include "sim/step_profile.h"

/* One slot per id ever handed out (body_table.c): the position of its body in the table,
 * or -1 once the body is gone, and the generation ids of this slot carry. */
typedef struct body_slot {
  int32_t position;
  uint32_t generation;
} body_slot;

/* How many steps' bounds an explicit step looks back over (docs/time-stepping.md, "The
 * recent bounds"): at least one period of the fastest element's oscillation at the
 * default cfl (about 2 pi / (cfl sqrt 3) steps, 7 at cfl 0.5), twice that to be safe. */
enum { STEP_BOUND_WINDOW = 16 };

struct piola_world {
  piola_world_def def;
  double time;
  world_body *bodies;         /* ordered by kind, then by insertion (body_table.c) */
  int32_t body_count, body_capacity;
  int32_t kind_count[PIOLA_BODY_KIND_COUNT]; /* bodies of each kind */
  body_slot *slots;
  int32_t slot_count, slot_capacity;
  uint64_t bodies_version;    /* changes whenever a body is added or changes its nodes */
  piola_obstacle **obstacles;
  int32_t obstacle_count, obstacle_capacity;
  struct world_contact *contact; /* self-collision of boundary surfaces (world_contact.c) */
  /* what the implicit solve under way knows of the other solids (solid_contacts.c), and
   * that solve's number: every solve (a try of a body's step, or its solve after the
   * collision pass) takes the next one, piola__solid_contacts_solve_begins */
  struct piola__solid_solve *solid_solve;
  int64_t implicit_solve;
  /* the CFL bounds (min(max_dt, every body's bound)) of the start states of the last
   * STEP_BOUND_WINDOW Newmark steps, oldest overwritten first: a step is never longer than
   * their minimum (docs/time-stepping.md, "The recent bounds") */
  double recent_bounds[STEP_BOUND_WINDOW];
  int32_t recent_bound_count; /* how many of them hold a bound, up to STEP_BOUND_WINDOW */
  int32_t recent_bound_next;  /* where the next one goes */
  double collision_deadline;  /* advance_to's target, which closes a collision interval too;
                                 NAN outside advance_to */
  /* implicit steps that advance_to may still halve past the last try's length in this call
   * (implicit_step.c, DEEPER_HALVINGS): IMPLICIT_DEEPER_STEPS at its start, so a frame ends
   * in a bounded number of steps; -1 (no limit: one step) outside advance_to */
  int32_t deeper_steps_left;
  step_profile profile;       /* per-phase step timers, off unless a benchmark turns them on */
  char *warnings[PIOLA_WARNING_KIND_COUNT]; /* first message of each kind, or NULL */
  piola_warning_handler *warning_handler;   /* told of each as it is raised (or NULL) */
  void *warning_context;
  int start_checked;  /* the first step's checks of the start ran (world_warnings.c) */
  int tangle_checked; /* the first collision pass's check of tangled solids ran (world_contact.c) */
  piola_work_split_planner split_planner; /* splits of solids added (plan NULL: none) */
  piola_work_split_planner split_replanner; /* splits of split solids a cut rebuilt */
  int split_replans_deferred; /* a rebuilt split solid stays whole, marked split_pending */
};

/* How many steps of one advance_to may be halved past the last try's length (above). */
#define IMPLICIT_DEEPER_STEPS 8

/* Warnings (world_warnings.c). warn records the message of kind unless one is recorded
 * already (printf format). check_slivers raises PIOLA_WARNING_SLIVER for solid s when its
 * worst tets force a rest step far below the typical tet's. warnings_free frees them. */
void piola__world_warn(piola_world *w, piola_warning_kind kind, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
void piola__world_check_slivers(piola_world *w, const world_body *s);
/* Sets whether solid s waits to untangle before it joins self-collision (world_contact.c,
 * "A tangled start"; checkpoints restore it), rebuilding the collision surface if it changed. */
void piola__world_set_collision_waits(piola_world *w, world_body *s, int waits);
/* Before the world's first step from t = 0: warns (PIOLA_WARNING_STARTS_INSIDE) when free nodes of
 * a body start inside an obstacle deeper than a percent of the body's size, and
 * (PIOLA_WARNING_UNDAMPED_TANGLE) when an undamped elastic solid starts tangled under the
 * explicit integrator. Once per world. */
void piola__world_check_start(piola_world *w);

/* Diagonal (m) of the bounding box of n points x (3 n numbers); 0 for none. */
double piola__bounding_diagonal(int32_t n, const double *x);
/* The first tet of solid s at positions x whose det F (against the rest mesh) is at most
 * limit, its value in *det; -1 for none (world_contact.c). */
int32_t piola__solid_flat_or_inverted_tet(const world_body *s, const double *x, double *det,
                                          double limit);
void piola__world_warnings_free(piola_world *w);

/* ---- the body table (body_table.c) */

/* A new zeroed body of kind at the end of its kind's range (later kinds move one place on),
 * with a slot of its own; index receives its index among its kind. NULL when out of memory.
 * Pointers to bodies are invalid after an insertion or a drop. The caller fills it, or
 * takes it out again with piola__world_drop_body when that fails. */
world_body *piola__world_insert_body(piola_world *w, piola_body_kind kind, int32_t *index);
/* Frees b (a body of w's table) and removes it; later bodies move one place back. */
void piola__world_drop_body(piola_world *w, world_body *b);
/* Body number index of kind (NULL when out of range), and the body an id names (NULL when
 * it names none). */
world_body *piola__world_body_of(const piola_world *w, piola_body_kind kind, int32_t index);
world_body *piola__world_body(const piola_world *w, piola_body_id id);
/* Position in the table of the first body of kind. */
int32_t piola__world_kind_start(const piola_world *w, piola_body_kind kind);
/* Frees every body and the table. */
void piola__world_free_bodies(piola_world *w);

/* True when every value of track t is finite and >= lo (world.c). */
int piola__track_ok(const piola_track *t, double lo);
/* PIOLA_OK when both viscosity tracks of body id (kind "solid" or "shell") are finite and
 * >= 0, else an error naming the one that is not. */
piola_status piola__check_viscosities(const char *kind, int32_t id, const piola_track *shear,
                                      const piola_track *bulk);

/* True when rest position p (3 doubles, m) lies in a box or sphere selector (index lists
 * select by index, not by position: false). Shared by constraints and bone attachments. */
int piola__selector_contains(const piola_selector *sel, const double *p);
/* Marks the constrained nodes of b (rest positions rest, 3n) from its constraint defs. */
piola_status piola__body_apply_constraints(world_body *b, const double *rest,
                                           const piola_constraint_def *constraints,
                                           int32_t count);
/* Raises PIOLA_WARNING_EMPTY_SELECTION for the first of body b's constraints (index: b's
 * number among the bodies of its kind) whose selector picks no node, naming it as the scene
 * keys do: fixed[k] and driven[k] count the non-driven and the driven constraints apart. */
void piola__world_check_selections(piola_world *w, const world_body *b, const double *rest,
                                   const piola_constraint_def *constraints, int32_t count,
                                   int32_t index);
/* Prescribed position (m) and velocity (m/s) of constrained node i at time t. */
void piola__body_constrained_state(const world_body *b, int32_t i, double t, double x[3],
                                   double v[3]);

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

/* What self-collision carries from one step to the next (for checkpoints): whether the
 * collision surface is built for the current bodies (a surface built anew starts without
 * history, contact/surface_history.h), and the open interval (collision_interval > 0): its
 * start time (s) and the positions then (3 * vertex_count, m). */
typedef struct piola__contact_state {
  int built;
  int *open;
  double *t_start;
  double *x0;
  int32_t vertex_count;
  struct piola_collision_surface *surface;
} piola__contact_state;
/* The state of w's contact, pointing into it ({0} when no surface is built for the current
 * bodies). */
piola__contact_state piola__world_contact_state(const piola_world *w);
/* built != 0: builds the surface when it is not built for the current bodies (as the first
 * step that needs it would); 0: drops it (the next step that needs it builds it). */
piola_status piola__world_contact_prepare(piola_world *w, int built);

/* 1 (default): the step's second right-hand side takes D_n v' from the first solve's
 * initial product plus a correction on the nodes collisions and constraints moved
 * (integrator.c); 0: a full damping pass. For tests comparing the two. */
extern int piola__step_reuse_first_product;
/* 1 (default): Newmark steps that fail the energy check are redone (integrator.c); tests set
 * 0 to see what the check prevents. */
extern int piola__step_energy_check;

/* The end of an accepted step of any integrator (integrator.c): plasticity after the step,
 * the profile, the clock advanced by dt, and local (one substep of dt) handed to stats. */
piola_status piola__world_finish_step(piola_world *w, double dt, piola_step_stats *local,
                                      piola_step_stats *stats);

/* The implicit integrators (implicit_step.c): piola_world_step for
 * PIOLA_INTEGRATOR_BACKWARD_EULER and PIOLA_INTEGRATOR_QUASISTATIC; implicit_state_free frees
 * a body's implicit state (NULL is fine). */
piola_status piola__implicit_world_step(piola_world *w, double dt_limit, piola_step_stats *stats);
void piola__implicit_state_free(struct implicit_state *state);

/* Applies the scripted cuts due at the world's time to every solid with fracture state
 * (fracture.c); called before each step. */
piola_status piola__world_fracture_step(piola_world *w);

#endif
