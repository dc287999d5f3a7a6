/* piola: a world of elastic solids and rigid obstacles, advanced in time.
 *
 * A world holds independent solids (tetrahedral elastic bodies with a material, damping,
 * gravity, initial state and constraints) and obstacles they collide with. It advances by
 * the Newmark scheme of paper section 9 (see docs/time-stepping.md): explicit elastic
 * forces, implicit damping solved by a conjugate gradient, collisions between
 * the position and the final velocity update, and a trapezoidal final velocity. The step
 * size is variable: the smallest of a user cap, a CFL bound and the time left to a target.
 *
 *   piola_world_def wdef = piola_default_world_def();
 *   piola_world *world;
 *   piola_world_create(&wdef, &world);
 *   piola_solid_def sdef = piola_default_solid_def();
 *   sdef.mesh = &mesh;                    // rest shape, world space, m
 *   piola_world_add_solid(world, &sdef, NULL);
 *   piola_obstacle_def ground = piola_default_obstacle_def();   // a plane z = 0
 *   piola_world_add_obstacle(world, &ground, NULL);
 *   piola_step_stats stats;
 *   if (piola_world_advance_to(world, 1.0 / 30, &stats) != PIOLA_OK) puts(piola_last_error());
 */
#ifndef PIOLA_WORLD_H
#define PIOLA_WORLD_H

#include <stdbool.h>
#include <stdint.h>

#include "piola/elastic_body.h"
#include "piola/export.h"
#include "piola/keyframes.h"
#include "piola/material.h"
#include "piola/math_types.h"
#include "piola/mesh.h"
#include "piola/obstacle.h"
#include "piola/plasticity.h"
#include "piola/rigid_motion.h"
#include "piola/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct piola_world piola_world;

/* How the world advances (docs/time-stepping.md). */
typedef enum piola_integrator_type {
  PIOLA_INTEGRATOR_NEWMARK = 0,   /* paper section 9: elastic forces explicit, damping
                                     implicit, CFL-bounded steps (default) */
  PIOLA_INTEGRATOR_BACKWARD_EULER, /* fully implicit: each step minimizes the incremental
                                     potential by Newton's method; steps of implicit_dt */
  PIOLA_INTEGRATOR_QUASISTATIC,   /* each step is the static equilibrium under the loads,
                                     constraints and obstacles of its end time */
  PIOLA_INTEGRATOR_COUNT
} piola_integrator_type;

/* Scene names "newmark", "backward_euler", "quasistatic". */
PIOLA_API const char *piola_integrator_type_name(piola_integrator_type type);
PIOLA_API bool piola_integrator_type_from_name(const char *name, piola_integrator_type *type);

/* The preconditioner of the implicit integrators' conjugate gradient
 * (docs/time-stepping.md, "Implicit integrators"). */
typedef enum piola_preconditioner_type {
  PIOLA_PRECONDITIONER_BLOCK_JACOBI = 0,  /* the inverse 3x3 diagonal blocks */
  PIOLA_PRECONDITIONER_INCOMPLETE_CHOLESKY, /* block IC(0) on the mesh edges (solids;
                                              shells use block Jacobi) */
  PIOLA_PRECONDITIONER_MULTIGRID, /* smoothed aggregation multigrid, one V-cycle (solids;
                                     shells use block Jacobi) */
  PIOLA_PRECONDITIONER_COUNT
} piola_preconditioner_type;

/* Scene names "block_jacobi", "incomplete_cholesky", "multigrid". */
PIOLA_API const char *piola_preconditioner_type_name(piola_preconditioner_type type);
PIOLA_API bool piola_preconditioner_type_from_name(const char *name,
                                                   piola_preconditioner_type *type);

/* The preconditioner of the Newton systems of a run split over MPI processes, solved by
 * PETSc's conjugate gradient on the distributed matrix (docs/mpi.md, "Implicit integrators
 * on several processes"). A single process ignores it. */
typedef enum piola_mpi_preconditioner {
  PIOLA_MPI_PRECONDITIONER_GAMG = 0,         /* PETSc's algebraic multigrid, told the rigid
                                                body modes */
  PIOLA_MPI_PRECONDITIONER_BLOCK_JACOBI_ICC, /* one block per process, each an incomplete
                                                Cholesky IC(0) */
  PIOLA_MPI_PRECONDITIONER_COUNT
} piola_mpi_preconditioner;

/* Scene names "gamg", "block_jacobi_icc". */
PIOLA_API const char *piola_mpi_preconditioner_name(piola_mpi_preconditioner type);
PIOLA_API bool piola_mpi_preconditioner_from_name(const char *name,
                                                  piola_mpi_preconditioner *type);

/* How tightly each Newton system is solved (docs/time-stepping.md, "Implicit integrators"). */
typedef enum piola_linear_forcing {
  PIOLA_FORCING_EISENSTAT_WALKER = 0, /* loose while Newton is far from converged, down to
                                         linear_tolerance as it converges */
  PIOLA_FORCING_FIXED,                /* every system to linear_tolerance */
  PIOLA_FORCING_COUNT
} piola_linear_forcing;

/* Scene names "eisenstat_walker", "fixed". */
PIOLA_API const char *piola_linear_forcing_name(piola_linear_forcing forcing);
PIOLA_API bool piola_linear_forcing_from_name(const char *name, piola_linear_forcing *forcing);

typedef struct piola_world_def {
  piola_track gravity[3];    /* m/s^2, keyframable. Default (0, 0, -9.81): z is up */
  double max_dt;             /* s, in (0, 1]: the user's cap on the step size. Default 1e-3 */
  double cfl;                /* dimensionless, in (0, 2]: dt <= cfl * min altitude / wave
                                speed. Default 0.5 */
  double cg_tolerance; /* damping solves stop at this fraction of the initial residual (the step's
                          velocity change), in (0, 1). Default 1e-4 */
  int32_t cg_max_iterations; /* in [1, 1000000]. Default 200 */
  /* s, in [0, 1]: the collision step of Bridson, Fedkiw and Anderson 2002 (docs/contact.md).
   * Self-collision processing (piola_self_collision_def) runs once per interval of this
   * length, from the positions at its start to those after the steps inside it, instead of
   * after every step; an interval ends with the first step that reaches its end, and
   * piola_world_advance_to's target always ends one, so the state it returns is
   * collision-processed.
   * 0 (default): after every step. Obstacles are handled inside every step either way. */
  double collision_interval;
  /* The integrator (default PIOLA_INTEGRATOR_NEWMARK). The fields below are used by the
   * implicit ones only (max_dt, cfl and the cg_ fields by Newmark only). */
  piola_integrator_type integrator;
  double implicit_dt;          /* s, > 0: the step of the implicit integrators; halved only
                                  when Newton fails to converge. Default 1/30 */
  double newton_tolerance;     /* dimensionless, in (0, 1): Newton stops when the mass-weighted RMS
                                  of the unbalanced force per mass is below this times
                                  9.81 m/s^2. Default 1e-5 */
  int32_t newton_max_iterations; /* in [1, 1000000]: past this the step counts as failed and is
                                  retried at half its size. Default 30 */
  double linear_tolerance;     /* dimensionless, in (0, 1): each Newton system is solved by
                                  preconditioned CG to this fraction of its initial residual
                                  (with PIOLA_FORCING_FIXED; the smallest fraction with
                                  PIOLA_FORCING_EISENSTAT_WALKER). Default 1e-3 */
  int32_t
      linear_max_iterations; /* in [1, 1000000]: CG iterations per Newton system. Default 1000 */
  piola_preconditioner_type preconditioner; /* the CG's preconditioner. Default
                                  PIOLA_PRECONDITIONER_BLOCK_JACOBI */
  piola_linear_forcing linear_forcing; /* each Newton system's CG tolerance, backward Euler
                                  and quasistatics alike: adapted (Eisenstat-Walker, within
                                  [linear_tolerance, 0.5], at most 0.1 after a step the line
                                  search shortened) or fixed at linear_tolerance. Default
                                  PIOLA_FORCING_EISENSTAT_WALKER */
  piola_mpi_preconditioner mpi_preconditioner; /* the preconditioner of PETSc's CG when
                                  the run is split over MPI processes. Default
                                  PIOLA_MPI_PRECONDITIONER_GAMG */
} piola_world_def;

PIOLA_API piola_world_def piola_default_world_def(void);

/* Which nodes a constraint holds, chosen by their rest positions (world space). */
typedef enum piola_selector_type {
  PIOLA_SELECT_BOX = 0, /* box_min <= X <= box_max componentwise (box_min <= box_max) */
  PIOLA_SELECT_SPHERE,  /* |X - center| <= radius */
  PIOLA_SELECT_INDICES, /* the listed vertex indices */
} piola_selector_type;

typedef struct piola_selector {
  piola_selector_type type;
  piola_vec3 box_min, box_max; /* m */
  piola_vec3 center;           /* m */
  double radius;               /* m, >= 0 */
  const int32_t *indices;      /* index_count vertex indices, copied */
  int32_t index_count;
} piola_selector;

/* Constrained nodes start at their rest positions (the solid's `initial` deformation does
 * not move them). A fixed node stays there; a driven node follows `motion` from there. */
typedef struct piola_constraint_def {
  piola_selector selector;
  bool driven;                   /* false: fixed. Default false */
  piola_rigid_motion_def motion; /* used when driven */
} piola_constraint_def;

/* Self-collision of a solid's boundary surface (or of a shell's triangles, piola_shell_def),
 * with itself and with every other solid or shell that has it enabled (Bridson, Fedkiw and
 * Anderson 2002; docs/contact.md), processed after every step, outside it (paper section 9),
 * or once per piola_world_def.collision_interval. Contact between two bodies is two-way:
 * impulses act on both. With backward Euler, solids with it also meet each other's
 * surfaces inside each step's solve (docs/time-stepping.md, "Solids against each other
 * inside the solve"). */
typedef struct piola_self_collision_def {
  bool enabled;     /* Default false */
  double thickness; /* m, > 0: surface pairs closer than this repel. Default 1e-3 */
  double friction;  /* Coulomb coefficient, >= 0. Default 0.3 */
} piola_self_collision_def;

typedef struct piola_solid_def {
  const char *name;               /* copied; NULL gives "solid<i>" */
  const piola_tet_mesh *mesh;     /* rest shape in world space (m), copied. Required */
  piola_material_def material;    /* default piola_default_material_def() */
  piola_track stiffness_scale;    /* dimensionless, >= 0, multiplies every stress. Default 1 */
  double density;                 /* kg/m^3, > 0. Default 1000 */
  piola_track shear_viscosity;    /* Pa s, >= 0: beta of section 6.2. Default 0 */
  piola_track bulk_viscosity;     /* Pa s, >= 0: alpha of section 6.2. Default 0 */
  piola_vec3 velocity;            /* m/s, initial velocity of every free node. Default 0 */
  const piola_constraint_def *constraints; /* constraint_count constraints, copied */
  int32_t constraint_count;
  /* Initial positions: x = c + A (X - c) + scramble, with c the centroid of the rest
   * positions X. A is any 3x3 matrix (singular and mirroring ones included). Default I. */
  piola_mat3 initial_matrix;
  double scramble_radius;         /* m, >= 0: each free node moves by a uniformly random
                                     point of a ball of this radius. Default 0 */
  uint64_t scramble_seed;         /* the random sequence is fixed by this seed. Default 1 */
  const piola_plasticity_def *plasticity; /* NULL (default): purely elastic. Read by
                                     add_solid only (goal positions included) */
  piola_self_collision_def self_collision; /* default: off */
  /* Muscle fibres (paper section 6.1; material.model PIOLA_MODEL_MUSCLE, see
   * piola_muscle_def): the fibre direction of each tet in rest space, 3 per tet, copied and
   * normalised (a zero one is an error naming the tet). NULL (default): no fibres. Not
   * supported together with plasticity. */
  const double *fiber_directions;
  piola_track activation;         /* dimensionless, in [0, 1], keyframable: the fibres'
                                     activation, set every step. Default 0 */
} piola_solid_def;

PIOLA_API piola_solid_def piola_default_solid_def(void);

PIOLA_API piola_status piola_world_create(const piola_world_def *def, piola_world **out);
PIOLA_API void piola_world_destroy(piola_world *world);

/* Adds a solid at the world's current time; index (may be NULL) receives its index. */
PIOLA_API piola_status piola_world_add_solid(piola_world *world, const piola_solid_def *def,
                                             int32_t *index);
/* Adds an obstacle (see piola/obstacle.h); index may be NULL. */
PIOLA_API piola_status piola_world_add_obstacle(piola_world *world, const piola_obstacle_def *def,
                                                int32_t *index);

typedef struct piola_step_stats {
  int32_t substeps;       /* steps taken */
  int32_t cg_iterations;  /* conjugate-gradient iterations, both solves of every step */
  int32_t colliding;      /* colliding nodes in the last step */
  double last_dt;         /* s */
  int64_t contacts;       /* self-collision: repulsion contacts, summed over the steps */
  int64_t impacts;        /* self-collision: collision impulses, summed over the steps */
  int32_t impact_zones;   /* self-collision: rigid impact zones, summed over the steps */
  int32_t collision_steps; /* self-collision: processing runs (every step, or one per
                              collision interval; 0 without self-collision) */
  int32_t newton_iterations; /* implicit integrators: Newton iterations, summed over the
                                steps and bodies (0 with Newmark) */
  int32_t linear_iterations; /* implicit integrators: CG iterations of the Newton systems */
  int32_t newton_failures;   /* implicit integrators: tries whose Newton did not converge,
                                retried at half the step or kept (time-stepping.md, "Failure") */
  int32_t step_retries;   /* steps redone at a quarter of their size because the state blew
                             up (docs/time-stepping.md, "Step retries") */
  int32_t energy_redos;   /* Newmark: steps redone at a quarter of their size because their
                             energy rose beyond what a stable step allows
                             (docs/time-stepping.md, "Energy check") */
} piola_step_stats;

/* The step size the next step would take with no target time: min(max_dt, CFL bound, the
 * CFL bounds of the last 16 steps' start states), s (docs/time-stepping.md, "Step size"). */
PIOLA_API double piola_world_stable_dt(const piola_world *world);

/* One step of min(stable dt, dt_limit) seconds; a dt_limit <= 0 (or INFINITY) sets no limit,
 * NaN is refused (PIOLA_ERROR_INVALID_ARGUMENT). With "backward_euler" and "quasistatic" the
 * step is integrator.dt's (the implicit_dt of the definition) instead of the stable dt. stats
 * (may be NULL) is overwritten. A step
 * whose state blows up (NaN, Inf, overflowing energy) is redone from the state before it at
 * a quarter of its size, up to PIOLA_STEP_MAX_RETRIES times; if the last try blows up too,
 * returns PIOLA_ERROR_NOT_FINITE and restores the state before the step. */
#define PIOLA_STEP_MAX_RETRIES 4
PIOLA_API piola_status piola_world_step(piola_world *world, double dt_limit,
                                        piola_step_stats *stats);

/* Steps until the world time equals t_end (s) exactly. stats (may be NULL) accumulates. A t_end
 * before the world's time is refused (PIOLA_ERROR_INVALID_ARGUMENT); one equal to it takes no
 * step. */
PIOLA_API piola_status piola_world_advance_to(piola_world *world, double t_end,
                                              piola_step_stats *stats);

PIOLA_API double piola_world_time(const piola_world *world); /* s */
PIOLA_API piola_integrator_type piola_world_integrator(const piola_world *world);

/* A NULL world: the functions of this header that take it and return a status give
 * PIOLA_ERROR_INVALID_ARGUMENT; piola_world_time and _stable_dt NAN, _integrator
 * PIOLA_INTEGRATOR_COUNT, _solid_count and _obstacle_count 0. */

/* Warnings: conditions a run survives but a user should know about. Each kind is raised at
 * most once per world; its message (the first occurrence, naming the body, the element or
 * the numbers) stays until the world is destroyed. docs/cli.md lists them. */
typedef enum piola_warning_kind {
  PIOLA_WARNING_CG_MAX_ITERATIONS = 0, /* a damping solve stopped at cg_max_iterations */
  PIOLA_WARNING_SMALL_STEP,            /* the state-aware step fell below a tenth of the CFL
                                          estimate of the rest state */
  PIOLA_WARNING_SLIVER,                /* a tet's rest altitude forces a step far below the
                                          others (found when the solid is added) */
  PIOLA_WARNING_NEWTON_FAILED,         /* an implicit step's last try, or a retry that
                                          halving did not help, did not converge and its last
                                          accepted iterate was kept */
  PIOLA_WARNING_EMPTY_SELECTION,       /* a fixed or driven constraint's selector picks no
                                          node (found when the body is added) */
  PIOLA_WARNING_STEP_KEPT_START,       /* a failed backward Euler step kept its start's
                                          positions (its iterate held more energy) */
  PIOLA_WARNING_STARTS_INSIDE,         /* at the world's first step from t = 0, free nodes lie
                                          inside an obstacle, deeper than 1% of the body's
                                          size: the step pushes them out at once */
  PIOLA_WARNING_UNSTABLE_CFL,          /* the explicit step's cfl is above 1, past the
                                          stability limit of well-shaped meshes (raised when
                                          the world is created) */
  PIOLA_WARNING_TANGLED_START,         /* at the world's first step from t = 0, a solid with
                                          self-collision starts tangled (an inverted or flat
                                          tet, or its surface through itself): its
                                          self-collision waits until it has untangled */
  PIOLA_WARNING_BODIES_CROSS,          /* at the world's first step from t = 0, the surfaces
                                          of two bodies with self-collision intersect:
                                          collision processing holds them hooked where they
                                          cross */
  PIOLA_WARNING_UNDAMPED_TANGLE,       /* at the world's first step from t = 0 with
                                          "newmark": an elastic solid with no damping starts
                                          with an inverted or flat tet; nothing dissipates the
                                          tangle's energy, so it does not settle, and a
                                          non-conservative inversion extension can add
                                          energy until the steps become tiny */
  PIOLA_WARNING_IGNORED_KEYS,          /* the scene sets integrator keys that its integrator
                                          does not use (raised by the scene reader when it
                                          builds the world) */
  PIOLA_WARNING_WITHIN_THICKNESS,      /* at the world's first step from t = 0, a vertex of
                                          a body with self-collision starts closer to another
                                          body's surface than their collision thickness: the
                                          first pass pushes them apart at once */
  PIOLA_WARNING_IMPLICIT_INTERVAL,     /* at the world's first step from t = 0 with
                                          "backward_euler" or "quasistatic": the collision
                                          interval is above 0 and a body has self-collision;
                                          frame-sized steps then pass through each other */
  PIOLA_WARNING_QUASISTATIC_CONTACT,   /* at the world's first step from t = 0 with
                                          "quasistatic": two or more bodies have
                                          self-collision; bodies that rest on or press into
                                          each other through it are not solved
                                          quasistatically */
  PIOLA_WARNING_KIND_COUNT
} piola_warning_kind;

/* The message of warning kind, or NULL while it has not been raised. */
PIOLA_API const char *piola_world_warning(const piola_world *world, piola_warning_kind kind);

/* Raises warning kind with message as the world raises its own (once per kind: nothing
 * happens when kind was raised already; the handler is called), for a front end's findings
 * about its input, such as the scene reader's PIOLA_WARNING_IGNORED_KEYS. */
PIOLA_API void piola_world_raise_warning(piola_world *world, piola_warning_kind kind,
                                         const char *message);

/* Called once per warning kind, as it is first raised (in the middle of a step or a frame,
 * on the thread that steps the world), with the message piola_world_warning then returns:
 * a run stuck inside a long frame can say why before the frame ends. NULL: none. */
typedef void piola_warning_handler(void *context, piola_warning_kind kind, const char *message);
PIOLA_API void piola_world_set_warning_handler(piola_world *world, piola_warning_handler *handler,
                                               void *context);
PIOLA_API int32_t piola_world_solid_count(const piola_world *world);
PIOLA_API int32_t piola_world_obstacle_count(const piola_world *world);

/* Per-solid data; pointers stay valid until the next step or set_state. */
PIOLA_API const char *piola_world_solid_name(const piola_world *world, int32_t solid);
PIOLA_API const piola_elastic_body *piola_world_solid_body(const piola_world *world, int32_t solid);
PIOLA_API const double *piola_world_solid_positions(const piola_world *world, int32_t solid);  /* m */
PIOLA_API const double *piola_world_solid_velocities(const piola_world *world, int32_t solid); /* m/s */
/* Vertex flags: 0 free, 1 fixed, 2 driven. */
PIOLA_API const uint8_t *piola_world_solid_constraint_flags(const piola_world *world, int32_t solid);

/* Replaces positions (m) and/or velocities (m/s) of a solid (either may be NULL) and
 * recomputes its elastic forces. */
PIOLA_API piola_status piola_world_solid_set_state(piola_world *world, int32_t solid,
                                                   const double *positions,
                                                   const double *velocities);

typedef struct piola_solid_stats {
  double kinetic_energy;  /* J */
  double elastic_energy;  /* J */
  int32_t inverted_count; /* tets with det F < 0 */
  double min_det_f;
} piola_solid_stats;

/* The plastic state of a plastic solid (NULL for an elastic one), and the statistics of its
 * last plastic update (zeros before the first step). See piola/plasticity.h. */
PIOLA_API const piola_plastic_state *piola_world_solid_plastic_state(const piola_world *world,
                                                                     int32_t solid);
PIOLA_API piola_plastic_stats piola_world_solid_plastic_stats(const piola_world *world,
                                                              int32_t solid);

/* Stats of one solid at the current state. */
PIOLA_API piola_solid_stats piola_world_solid_stats(const piola_world *world, int32_t solid);

#ifdef __cplusplus
}
#endif

#endif
