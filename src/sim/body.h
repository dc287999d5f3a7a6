/* A body of the world: one deformable thing the step loop advances, whatever its kind.
 *
 * Why it looks like this. The Newmark step (integrator.c) does the same things to every
 * body: copy the old state, two damping solves, move, collide with the obstacles, hold the
 * constrained nodes, check the result. Only a few operations depend on what the body is
 * made of: its elastic force, its damping force (and the damping solve's fast paths), its
 * step bound, its plasticity, its share of the collision surface and its statistics. So a
 * body is one struct, world_body, with
 *  - the per-node state every kind has, as flat xyz arrays (positions, velocities, masses,
 *    forces, constraint flags, the step's scratch), which the step loop and the conjugate
 *    gradient read as plain loops over doubles;
 *  - a kind tag (piola_body_kind) and the kind's own object (a piola_elastic_body for a
 *    solid, a piola_shell_body for a shell) with the few fields only that kind uses;
 *  - the kind-dependent operations, declared below and dispatched in body.c by a switch on
 *    the tag (a tagged struct and a switch, no function-pointer tables). With -Wswitch a new
 *    kind (rods, rigid bodies, fractured pieces) that misses one case does not compile, and
 *    body.c is the one file that lists what a kind must provide. The kinds' own code lives
 *    in world_solids.c and world_shells.c.
 *
 * The world keeps its bodies in one array (body_table.c), ordered by kind: every solid
 * before every shell, each kind in the order it was added. That is the order bodies step
 * and join the collision surface in, so results do not depend on the order of the add
 * calls. Public ids (piola/world_bodies.h) go through a slot table, so they survive the
 * moves that insertion in the middle causes.
 *
 * The elastic force held by a body always belongs to its current positions: it is computed
 * once per step, after collisions, and reused by the next step's first solve. */
#ifndef PIOLA_SIM_BODY_H
#define PIOLA_SIM_BODY_H

#include <math.h>
#include <stdint.h>

#include "piola/world.h"
#include "piola/world_bodies.h"
#include "piola/world_shells.h"

struct piola__stiffness_matrix; /* force/stiffness_matrix.h */

/* Node flags (world_body.flags). */
enum { NODE_FREE = 0, NODE_FIXED = 1, NODE_DRIVEN = 2 };

/* Values of world_body.colliding: a node held along its normal by an obstacle, along the push
 * of the self-collision pass (implicit steps: self_collide_and_resolve), or by a solid's
 * surface (a shell's one-way coupling, collide_with_solids); or (implicit steps) held in all
 * three directions where friction stopped it (newton_iterate's friction pass). */
enum { HELD_BY_OBSTACLE = 1, HELD_BY_COLLISION = 2, HELD_BY_SOLID = 3, HELD_BY_FRICTION = 4 };

typedef struct world_body {
  piola_body_kind kind;
  uint32_t slot;             /* its entry in the world's id slots (body_table.c) */
  char *name;
  /* the kind's own object and fields */
  piola_elastic_body *solid; /* PIOLA_BODY_SOLID: the tetrahedral elastic body */
  piola_plastic_state *plastic;      /* solids: NULL when elastic (world_plasticity.c) */
  piola_plastic_stats plastic_stats; /* solids: of the last plastic update */
  piola_elastic_stats elastic;       /* solids: of the last update, once refreshed */
  int elastic_stale;                 /* solids: elastic does not match the last update yet */
  piola_track activation;            /* solids: muscle fibres' activation */
  piola_tri_mesh *boundary;  /* solids: boundary surface, built when a shell first needs it */
  double boundary_reach;     /* solids: longest boundary edge, m */
  struct piola__bvh
      *boundary_tree; /* solids: over boundary's triangles (piola__solid_boundary_tree) */
  struct piola__box *boundary_boxes; /* solids: those triangles' boxes at its last fit */
  piola_shell_body *shell;   /* PIOLA_BODY_SHELL: the shell body */
  piola_shell_stats shell_stats; /* shells: of the last update */
  int collide_with_solids;   /* shells: one-way coupling to the solids' surfaces */
  double solid_friction;     /* shells: Coulomb mu against solids */
  /* every kind: per-node state */
  int32_t n;                 /* node count */
  double *x, *v;             /* 3n current state */
  double *mass;              /* n lumped masses, kg */
  double *inverse_mass;      /* n, 0 for massless (isolated) nodes, which are held fixed */
  double *force;             /* 3n elastic force at x, N */
  double *start;             /* 3n positions of constrained nodes at t = 0 */
  uint8_t *flags;            /* n: NODE_FREE / FIXED / DRIVEN */
  int32_t *motion_of;        /* n: index into motions for driven nodes, else -1 */
  piola_rigid_motion_def *motions;
  int32_t motion_count;
  piola_track stiffness_scale, shear_viscosity, bulk_viscosity;
  piola_self_collision_def self_collision;
  /* solids: self-collision waits for this solid to untangle, so it is not in the collision
   * surface (world_contact.c, "A tangled start"); checkpointed */
  int collision_waits;
  /* solids, in an implicit step: holds between this solid and another's surface, of either's
   * nodes (solid_contacts.c), counted since the step's try began */
  int32_t solid_contacts;
  /* scratch for the step */
  double *x_old, *v_old, *force_old, *rhs, *work, *tmp;
  /* the final solve's A v (3n) and the v it was taken at (3n), with its h and the damping
   * assembly it used: the next step's first solve starts from it (integrator.c) */
  double *av_product, *v_product;
  double product_h;
  uint64_t product_generation;
  int product_valid;
  uint8_t *colliding; /* n: HELD_BY_* this step, 0 for a node nothing holds */
  double *normals;
  /* n: the normal impulse per unit mass (m/s) whose friction the explicit step's collision
   * processing applied to each obstacle contact's motion (or a shell's coupling to a solid,
   * to its velocity), NAN for the other nodes; the friction after the final solve makes up
   * the rest of the step's (integrator.c) */
  double *friction_spent;
  /* shells with collide_with_solids: 3n, the velocity of the solid surface point that holds
   * each node the explicit step's coupling moved (mark SOLID_HELD in colliding), for the
   * friction after the final solve (integrator.c); NULL for other bodies */
  double *solid_surface_v;
  /* the state-aware step bound of the last update, a cache of a function of the update's
   * per-element state, valid until the next update. Solids (stable_step.h, world_solids.c):
   * max over tets of k_e / (rho h_e^2), 1/s^2, and the tet that attains it. Shells
   * (shell_stable_step.h, world_shells.c): the membrane's term and its triangle, and the
   * bending term in state_bending_rate2 */
  double state_rate2, state_bending_rate2;
  int32_t state_worst_tet;
  int state_rate_valid;
  uint32_t split_pending; /* solids: split before a rebuild whose replan is deferred
                             (work_split.h, piola_world_defer_work_split_replans), whole on
                             this process until piola_world_solid_replan_work_split: the
                             split's process count << 16 | process; 0: not pending */
  struct solid_fracture *fracture; /* solids: the virtual node state, NULL until the solid
                                      is first cut or given a fracture def (fracture.c) */
  struct implicit_state *implicit; /* the implicit integrators' matrix and vectors, made on
                                      their first step of a solid (implicit_step.c) */
  double quasistatic_mu; /* the implicit integrators' regularization carried from step to
                            step, 1/s^2 (0: not chosen yet; implicit_step.c); checkpointed */
  int kept_start;        /* solids: backward Euler's last step kept its start's positions
                            (a tangle froze it; implicit_step.c, RECOVERING_DROP);
                            checkpointed */
} world_body;

/* ---- the kind-dependent operations (body.c) */

/* "solid", "shell": for names and messages. */
const char *piola__body_kind_name(piola_body_kind kind);
/* Elements: tets of a solid, triangles of a shell. */
int32_t piola__body_element_count(const world_body *b);
/* Recomputes the elastic force of b at its positions x and time t (stiffness scale). */
piola_status piola__body_update_forces(world_body *b, double t);
/* Damping force at velocities v (out overwritten, N), viscosities beta, alpha in Pa s. */
void piola__body_damping_forces(const world_body *b, const double *v, double beta, double alpha,
                                double *out);
/* True when b has no damping at all (its damping solve is a diagonal one). */
int piola__body_undamped(const world_body *b, double beta, double alpha);
/* out = M p - h D p (the damping solve's operator); scratch holds 3n doubles. */
void piola__body_damping_apply(const world_body *b, const double *p, double beta, double alpha,
                               double h, double *scratch, double *out);
/* Whether the kind's damping is an assembled operator the step can reuse between solves
 * (prepare, generation and add_sparse below); the others are no-ops for a kind without. */
int piola__body_damping_reusable(const world_body *b);
/* Assembles the damping operator for these viscosities from the last update, if needed. */
void piola__body_damping_prepare(world_body *b, double beta, double alpha);
/* Changes whenever the assembled damping operator does. */
uint64_t piola__body_damping_generation(const world_body *b);
/* out += scale * D e, evaluated only on the elements touching nodes where e != 0. */
void piola__body_damping_add_sparse(const world_body *b, const double *e, double beta,
                                    double alpha, double scale, double *out);
/* The largest stable step of b (s) with stiffness scale `scale`, before max_dt. */
double piola__body_stable_dt(const piola_world *w, const world_body *b, double scale);
/* The rest state's fastest wave speed of b (m/s): a solid's dilatational, a shell's
 * membrane's; 0 for no body. */
double piola__body_max_wave_speed(const world_body *b);
/* Plasticity inside the step, right after the force update at the step's end (shells). */
void piola__body_plastic_in_step(world_body *b, double dt);
/* Plasticity once every body has stepped and contact is done (solids). */
void piola__body_plastic_after_step(world_body *b, double dt);
/* Collisions with other bodies inside the step, after the obstacles' (the shells' one-way
 * coupling to solids): moves nodes, flags them colliding (with the value mark) with their
 * normals, and when surface_velocity (3n) is not NULL stores there the velocity of the
 * surface each moved node touches; returns how many newly collide. */
int32_t piola__body_collide_in_step(piola_world *w, world_body *b, double t1, double dt,
                                    uint8_t mark, double *surface_velocity);
/* The implicit integrators' system matrix (force/stiffness_matrix.h for solids,
 * shell/shell_stiffness.h for shells): init sizes it for b; assemble forms
 * stiffness_weight K + damping_weight D (D at viscosities beta, alpha in Pa s; a solid's
 * damping matrix must have been prepared for them) with mass_weight M on the diagonal from
 * b's last update; apply gives out = A p. */
piola_status piola__body_stiffness_init(world_body *b, struct piola__stiffness_matrix *matrix);
void piola__body_stiffness_assemble(const world_body *b, struct piola__stiffness_matrix *matrix,
                                    double stiffness_weight, double damping_weight, double beta,
                                    double alpha, double mass_weight);
/* The matrix as last assembled with its mass term changed to mass_weight M (the other weights
 * as that assembly had them): a solid recomputes only its diagonal blocks, a shell assembles
 * again. */
void piola__body_stiffness_set_mass_weight(const world_body *b,
                                           struct piola__stiffness_matrix *matrix,
                                           double stiffness_weight, double damping_weight,
                                           double beta, double alpha, double mass_weight);
void piola__body_stiffness_apply(const world_body *b, const struct piola__stiffness_matrix *matrix,
                                 double mass_weight, const double *p, double *out);
/* The body's triangles in the world's collision surface, over its own node numbering.
 * *owned says whether out must be freed with piola_tri_mesh_free (else it is borrowed). */
piola_status piola__body_collision_triangles(const world_body *b, piola_tri_mesh *out, int *owned);
/* Energies, momentum and inverted elements at the current state. */
piola_body_stats piola__body_stats(world_body *b);
/* Frees the kind's own object and fields. */
void piola__body_free_kind(world_body *b);

/* ---- every kind (body.c) */

/* Sizes the per-node state and scratch for n nodes, names the body (kind and index when
 * name is NULL) and copies its rest positions (the constrained nodes' start) and lumped
 * masses. */
piola_status piola__body_allocate(world_body *b, int32_t n, const char *name, int32_t index,
                                  const double *rest, const double *mass);
/* Sets inverse masses once constraints are in, fixing massless nodes. */
void piola__body_finish_masses(world_body *b);
/* Puts x, v and the force back to the step's start (x_old, v_old, force_old) and updates
 * the forces there at time t: a step that is undone, to be retried or abandoned. */
void piola__body_restore_step(world_body *b, double t);
/* Frees everything b owns and zeroes it. */
void piola__body_free(world_body *b);

/* ---- bodies that change (body_rebuild.c) */

/* A new mesh for a body, between steps (fracture, refinement). The parents say where each
 * new node and element comes from in the old mesh. */
typedef struct body_change {
  const piola_tet_mesh *solid_rest; /* a solid's new rest mesh (m), copied */
  const double *x, *v;          /* 3 per new node: positions (m) and velocities (m/s); a
                                   constrained node's are replaced by its prescribed ones */
  const int32_t *node_parent;   /* per new node: the old node whose constraint (fixed, or
                                   driven by which motion) it takes, -1: free. NULL: all free */
  const int32_t *element_parent; /* per new element: the old element whose material, fibre
                                   direction and plastic state it takes, -1: material 0,
                                   Fp = I. NULL: all -1 */
  const double *element_fraction; /* per new element of a solid: its material fraction in
                                   (0, 1] (piola_elastic_body_def.material_fractions). NULL:
                                   all whole */
} body_change;

/* Gives body b of world w the mesh and state of change and rebuilds every structure sized
 * or derived from its mesh: the kind's object (padded layout, damping pattern), plastic
 * state, per-node state and scratch, constraint flags, the collision surfaces, the elastic
 * force. b keeps its id, name and parameters. On error b and w are unchanged. Solids only
 * for now (a shell answers PIOLA_ERROR_UNSUPPORTED). */
piola_status piola__body_rebuild(piola_world *w, world_body *b, const body_change *change);

/* Asks the world's replanner for split solid b's split of its current mesh and sets it in
 * the replicated mode (work_split.h). Collective. */
piola_status piola__body_resplit(piola_world *w, world_body *b);

/* ---- the kinds' own code */

/* A body's explicit step from its rest bound (s) and its state-aware rate2 (1/s^2): the state
 * bound cfl / sqrt(rate2) where it is smaller by more than rounding, else the rest bound (at
 * rest the two agree up to rounding, and a state at rest keeps the rest step's bits;
 * docs/time-stepping.md, "Step size"). */
static inline double piola__state_or_rest_step(double rest, double cfl, double rate2) {
  const double state = rate2 > 0 ? cfl / sqrt(rate2) : INFINITY;
  return state < rest * (1.0 - 1e-9) ? state : rest;
}

/* world_solids.c */
piola_status piola__solid_update_forces(world_body *b, double t);
double piola__solid_stable_dt(const piola_world *w, const world_body *b, double scale);
piola_body_stats piola__solid_stats(world_body *b);
/* The boundary surface of solid b in b->boundary (its longest rest edge in boundary_reach),
 * built on the first call from the rest topology; positions are b->x. */
piola_status piola__solid_boundary(world_body *b);
/* The tree over solid b's boundary triangles (piola__solid_boundary first), fitted to its
 * current positions: built on the first call and when `rebuild` is set, else refit (the
 * same shape, the boxes of now: cheaper, and looser the more the body has deformed since
 * the build). NULL when memory runs out. */
const struct piola__bvh *piola__solid_boundary_tree(world_body *b, int rebuild);
/* world_shells.c */
piola_status piola__shell_update_forces(world_body *b, double t);
double piola__shell_stable_dt(const piola_world *w, const world_body *b, double scale);
piola_body_stats piola__shell_stats(const world_body *b);
/* One-way coupling: pushes the free nodes of shell b out of the solids' current boundary
 * surfaces at t1 after a step of dt, as obstacle collisions do (mark and surface_velocity
 * as for piola__body_collide_in_step). */
int32_t piola__shell_collide_with_solids(piola_world *w, world_body *b, double t1, double dt,
                                         uint8_t mark, double *surface_velocity);
/* world_plasticity.c: creation binds a plastic state to b->solid when def asks for one; the
 * update runs once per step, after the whole step succeeded, from the diagonalization of
 * the step's force evaluation; the stiffening factor (>= 1) divides the CFL step. */
piola_status piola__solid_plastic_create(world_body *b, const piola_solid_def *def);
void piola__solid_plastic_update(world_body *b, double dt);
double piola__solid_plastic_stiffening(const world_body *b);

#endif
