/* The implicit integrators: backward Euler and quasistatics (docs/time-stepping.md,
 * "Implicit integrators").
 *
 * Backward Euler. From (x^n, v^n) a step of dt finds x = x^n+1 with
 *   g(x) = M (x - x^n - dt v^n) - dt^2 (f_e(x) + D(x) v + M g(t^n+1)) = 0,  v = (x - x^n) / dt,
 * the gradient of the incremental potential (inertia, elastic energy, gravity, damping as
 * the rotated damping at the current iterate), by Newton's method: the system matrix
 * M - dt^2 K - dt D (stiffness_matrix.h) with K the projected stiffness, so it is symmetric
 * positive definite at any deformation, flat and inverted elements included; a
 * conjugate gradient preconditioned by block Jacobi, block IC(0)
 * (force/stiffness_incomplete_cholesky.h) or smoothed aggregation multigrid
 * (force/stiffness_multigrid.h), solved to Eisenstat and Walker's forcing term or a
 * fixed tolerance (forcing_term); and a backtracking line search.
 *
 * Why the line search is on the residual norm and not on the energy. The inversion
 * extension (docs/materials.md) has no potential where some entries of Fhat are below the
 * threshold and others above (its dPhat/dFhat is not symmetric there), and the rotated
 * damping at the current iterate is not the gradient of anything either. So the merit
 * function is |g|^2 in the M^-1 norm, which is consistent with the forces everywhere; a
 * step is accepted when it decreases by the Armijo fraction. With the projected Hessian the
 * Newton direction is a descent direction for it near a solution; far from one the
 * backtracking may fail, and then the step is undone and retried at half the size (the only
 * way the step shrinks). A quasistatic body (solid or shell) has no damping, and its g is
 * the gradient of the potential (elastic energy minus gravity's work) wherever the
 * extension is not mixed, so a step that decreases that potential by the Armijo fraction of
 * g . d is accepted too: the projected Hessian's direction always descends the potential,
 * not always |g| (a bending bar's projection is active: on the residual norm alone the
 * first Newton steps of the quasistatic bar of run_resume_examples.py were cut to 1/1024,
 * and its first increment failed 12 times; a flat cloth pinned at two corners found no
 * decrease of |g| at all along its first direction, every try, and never left its start;
 * docs/time-stepping.md).
 *
 * The tail. The projected matrix is not the Jacobian where elements are compressed (the
 * fix clamps their negative rotation eigenvalues), and Newton on it converges only
 * linearly. So after an iteration that took the full step with no Levenberg-Marquardt
 * shift (and, with IC(0), no contact change), the next systems keep those eigenvalues' sign
 * (PIOLA_STIFFNESS_SIGNED_TWIST, element_stiffness.h), with the last projected system's
 * preconditioner, or the multigrid's level 0 refreshed from the tail's matrix where the
 * contact set has moved since; a CG that meets non-positive curvature there is solved again
 * on the projected matrix, and a backtracking line search ends the tail for the step
 * (newton_direction; docs/time-stepping.md, "The Newton tail"). Quasistatic solids take the
 * tail too.
 *
 * Constraints. Fixed, driven and bone nodes sit at their positions of t^n+1 before the
 * first iteration and are filtered out of every residual and search direction. Obstacle
 * contacts are an active set: nodes found inside an obstacle (at the prediction and after
 * every Newton update) are projected to its surface and their normal component is filtered
 * like the collision-held normals of the Newmark step; a node the obstacle would have to
 * pull is released. After convergence the normal contact force (the filtered-out residual)
 * limits the tangential velocity relative to the obstacle by Coulomb's law, as the Newmark
 * step does with its normal impulse; where those moves are large against the tets around
 * them, the step is solved once more around them (implicit_contacts.c). Self-collision
 * runs after the step as with Newmark, and the bodies it moved are solved again behind their
 * pushed surfaces (self_collide_and_resolve); plasticity runs after the step.
 *
 * Momentum. K and D are translation invariant, so a free body's net residual changes only
 * through M. The preconditioned CG does not keep the net residual at zero by itself, so each
 * solution is moved by the uniform displacement that zeroes it: a free body's linear
 * momentum changes by exactly dt M g per step, whatever the tolerances.
 *
 * Quasistatics. g(x) = -(f_e(x) + M g(t^n+1)), the same Newton with the matrix -K + mu M:
 * mu (1/s^2) regularizes the rigid and soft modes (Levenberg-Marquardt), shrinking after
 * full steps and growing when the line search has to backtrack. Velocities are reported as
 * (x^n+1 - x^n) / dt; damping and contact friction do not act.
 *
 * Bodies. Solids and shells take the same steps; what differs (the matrix, the damping
 * force, the one-way coupling of shells to solids) goes through body.h's per-kind
 * operations. Bodies are solved one after the other in the world's order, solids first, so
 * a shell coupled to the solids sees them at t^n+1. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "force/elastic_body_internal.h"
#include "sim/failed_step_velocity.h"
#include "sim/implicit_problem.h"
#include "sim/implicit_split.h"
#include "sim/obstacle_internal.h"
#include "sim/solid_contacts.h"
#include "sim/world_internal.h"

#define STANDARD_GRAVITY 9.81
#define RANGES 16
/* A step whose Newton does not converge is undone and retried at half the size up to this
 * many times; the last try keeps its last accepted iterate (a force field that jumps, as the
 * extended stress of an element passing through a reflection does, may have no exact
 * root), or with backward Euler what holds no more energy than the step's start
 * (keep_failed_step), the step goes on, counted in newton_failures, and the user is warned
 * once. */
#define MAX_HALVINGS 3

/* The length of a last try (the user's step halved MAX_HALVINGS times): no failed try is
 * kept at a shorter one, unless the frame's remainder is shorter still. */
static double last_try_length(const piola_world *w) {
  return ldexp(w->def.implicit_dt, -MAX_HALVINGS);
}

/* A backward Euler try that would keep only its start's positions (keep_failed_step's last
 * case: its iterate held more energy than the start) is no result: a body whose every step
 * ends there never moves. Such a try is halved on instead, past the last try's length, at
 * most this many more times (dt / 512), in at most IMPLICIT_DEEPER_STEPS steps of a frame
 * (world_internal.h), so a frame still ends in a bounded number of steps. Gmsh's bunny.msh
 * collapsed to a point (Stable Neo-Hookean, one step per 1/30 s frame) froze from its fourth
 * frame on with 8,567 of 19,379 tets inverted, every try of every step failing, while a
 * try of dt / 32 got 93% of the way to convergence (try_progress); with the deeper tries it
 * recovers (docs/time-stepping.md, "Failure"). Halving on only while it helps
 * (HALVING_GAIN) did not unfreeze it: near the freeze a try's progress does not grow
 * steadily as the step shrinks. A try that got less than DEEPER_MIN_PROGRESS of the way
 * (try_progress) keeps its start as before: the energy mode's frozen scrambles of
 * docs/materials.md get nowhere at any length (each try ends in its first line search), and
 * halving them on to dt / 512 took 10 times the time and moved nothing. */
#define DEEPER_HALVINGS 6
#define DEEPER_MIN_PROGRESS 0.1

/* A failed try is retried at half the size only while halving helps: a retry that gets less
 * than HALVING_GAIN times as far toward convergence as the try before it (try_progress) is
 * kept as a last try is. In a tangle the elastic forces dwarf the inertia M / dt^2 that
 * halving raises, and every try takes the same path: on Gmsh's bunny.msh scrambled by half
 * its diagonal (corotated) the tries at dt and dt / 2 went 5.8% and 6.0% of the way, all
 * four tries of nearly every step failed, up to 29 s a frame; with this rule the 2 s ran in
 * 130 s instead of 551 s, 31 tets inverted at the end instead of 43 (docs/time-stepping.md,
 * "Failure"). */
#define HALVING_GAIN 1.5

/* After a backward Euler step that kept its start's positions (keep_failed_step's last case),
 * a failed try from a start with a flat or inverted tet whose iterate, with its velocity
 * (x - x^n) / dt, holds less energy than the start by at least RECOVERING_DROP of the start's
 * elastic energy is kept as a last try is, instead of halved: it is a tangle letting go, and
 * its halves would start again from the tangle and end where the last step did.
 * armadillo_4k rotated z-up, scrambled by two diagonals (the spline, seed 2; a scene written
 * from the docs): each frame's first try took the energy from 3.9e13 to 2.8e8 J in its 30
 * Newton iterations without converging, the halves failed, and the last try kept its start,
 * frame after frame: the body stood frozen with 1,763 tets inverted. Kept at every tangled
 * step instead of only after a frozen one, the rule changed how the armadillo scrambles of
 * docs/time-stepping.md recover, for better and for worse (one bunny scramble timed out). */
#define RECOVERING_DROP 0.9

/* Backward Euler's first guess is the prediction x^n + dt v^n plus the step gravity alone
 * would give (dt^2 g: 1.1 cm at 1/30 s), which is exact for a free fall. A solid that is
 * supported (held by a constraint, or that step would take a node into an obstacle) takes
 * only this fraction of it (11 um at 1/30 s): its nodes resting on an obstacle are pushed
 * just inside it, so they are held from the first solve on, while nodes above it stay free.
 * The whole step pushed every node within 1.1 cm of the obstacle into it, and all were held:
 * a torus resting on a plane released 60-150 of them after the first solve and then added
 * and released dozens per iteration, 15-17 Newton iterations a frame where this guess takes
 * 5-8; a hanging muscle spindle took 50 iterations in 6 frames, 33 with it (BENCHMARKS.md,
 * "The first guess"). With no nudge at all, resting nodes a rounding error above the surface
 * were missed. Shells keep the whole step: on cloth folding over on the ground the fraction
 * doubled the failed Newton steps. */
#define GUESS_GRAVITY_FRACTION 1e-3

void piola__implicit_state_free(struct implicit_state *st) {
  if (!st) return;
  piola__stiffness_matrix_free(&st->matrix);
  piola__incomplete_cholesky_free(&st->factor);
  piola__multigrid_free(&st->multigrid);
  free(st->prediction), free(st->residual), free(st->step), free(st->base), free(st->damping);
  for (int k = 0; k < 4; ++k) free(st->cg[k]);
  free(st->scratch_v), free(st->surface_v), free(st->surface_mu), free(st->friction);
  free(st->friction_free), free(st->hit), free(st->retry_guess);
  free(st);
}

/* The state of s's implicit steps, with room for the preconditioner's factor or hierarchy
 * (solids). */
static piola_status implicit_state_make(world_body *s, piola_preconditioner_type preconditioner) {
  if (s->implicit) return PIOLA_OK;
  struct implicit_state *st = calloc(1, sizeof *st);
  if (!st) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "implicit step: out of memory");
  size_t v3 = sizeof(double) * 3 * (size_t)(s->n > 0 ? s->n : 1);
  st->prediction = malloc(v3), st->residual = malloc(v3), st->step = malloc(v3);
  st->base = malloc(v3), st->damping = malloc(v3), st->scratch_v = malloc(v3);
  st->surface_v = malloc(v3);
  st->surface_mu = malloc(sizeof(double) * (size_t)(s->n > 0 ? s->n : 1));
  st->friction = malloc(v3);
  st->friction_free = malloc(2 * v3);
  st->retry_guess = malloc(v3);
  for (int k = 0; k < 4; ++k) st->cg[k] = malloc(v3);
  st->hit = malloc((size_t)(s->n > 0 ? s->n : 1));
  int ok = st->prediction && st->residual && st->step && st->base && st->damping && st->scratch_v &&
           st->surface_v && st->surface_mu && st->friction && st->hit && st->cg[0] && st->cg[1] &&
           st->cg[2] && st->cg[3] && st->friction_free && st->retry_guess;
  if (ok && piola__body_stiffness_init(s, &st->matrix) != PIOLA_OK) ok = 0;
  if (ok && preconditioner == PIOLA_PRECONDITIONER_INCOMPLETE_CHOLESKY &&
      s->kind == PIOLA_BODY_SOLID &&
      piola__incomplete_cholesky_init(&st->factor, s->solid) != PIOLA_OK)
    ok = 0;
  if (ok && preconditioner == PIOLA_PRECONDITIONER_MULTIGRID && s->kind == PIOLA_BODY_SOLID &&
      piola__multigrid_init(&st->multigrid, s->solid) != PIOLA_OK)
    ok = 0;
  if (!ok) {
    piola__implicit_state_free(st);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "implicit step: out of memory");
  }
  s->implicit = st;
  return PIOLA_OK;
}

/* ------------------------------------------------------------------ constraints */

/* Zeroes the constrained components of node i of r: all of a fixed/driven node or of one
 * friction stopped, the normal of a node held by an obstacle. */
static inline void filter_vector(const world_body *s, int32_t i, double ri[3]) {
  if (s->flags[i] != NODE_FREE || s->inverse_mass[i] == 0 || s->colliding[i] == HELD_BY_FRICTION) {
    ri[0] = ri[1] = ri[2] = 0;
  } else if (s->colliding[i]) {
    const double *nrm = s->normals + 3 * i;
    double dn = ri[0] * nrm[0] + ri[1] * nrm[1] + ri[2] * nrm[2];
    for (int k = 0; k < 3; ++k) ri[k] -= dn * nrm[k];
  }
}

static inline void filter_node(const world_body *s, int32_t i, double *r) {
  filter_vector(s, i, r + 3 * i);
}

/* True when a node with mass is held (constrained or in contact): then external forces act.
 * Massless vertices (in no tet) are held fixed but carry no momentum. */
static int has_filtered_nodes(const world_body *s) {
  for (int32_t i = 0; i < s->n; ++i)
    if (s->mass[i] > 0 && (s->flags[i] != NODE_FREE || s->colliding[i])) return 1;
  return 0;
}

/* ------------------------------------------------------------------ fixed node ranges */

/* The vector passes (the residual, the CG's phases) run over RANGES fixed node ranges, in
 * parallel from parallel_min nodes on; each range is summed by one thread and the ranges'
 * sums are added in order, so results do not depend on the thread count. */
typedef double range_pass(const void *context, int32_t i0, int32_t i1);

static inline int32_t range_start(int32_t n, int range) {
  return (int32_t)((int64_t)n * range / RANGES);
}

static double sum_over_ranges(int32_t n, int32_t parallel_min, range_pass *pass,
                              const void *context) {
  double part[RANGES];
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) \
    if (n >= parallel_min)
  for (int range = 0; range < RANGES; ++range)
    part[range] = pass(context, range_start(n, range), range_start(n, range + 1));
  double sum = 0;
  for (int range = 0; range < RANGES; ++range) sum += part[range];
  return sum;
}

/* ------------------------------------------------------------------ the step's problem */

/* Nodes i0 .. i1 - 1 of the residual; returns their part of |S g|^2_{M^-1}. */
static double residual_range(const void *ctx, int32_t i0, int32_t i1) {
  const newton_problem *pb = ctx;
  const world_body *s = pb->s;
  struct implicit_state *st = pb->st;
  const double w = pb->force_weight;
  double sum = 0;
  for (int32_t i = i0; i < i1; ++i) {
    double *g = st->residual + 3 * i;
    for (int k = 0; k < 3; ++k) {
      const int64_t j = 3 * (int64_t)i + k;
      double f = s->force[j] + s->mass[i] * pb->g1[k] + (pb->damped ? st->damping[j] : 0.0);
      if (pb->friction_held && s->colliding[i]) f += st->friction[j];
      g[k] = pb->mass_weight * s->mass[i] * (s->x[j] - st->prediction[j]) - w * f;
    }
    double gf[3] = {g[0], g[1], g[2]};
    filter_vector(s, i, gf);
    sum += s->inverse_mass[i] * (gf[0] * gf[0] + gf[1] * gf[1] + gf[2] * gf[2]);
  }
  return sum;
}

/* The residual g at the body's current state (its last update is at s->x) into
 * st->residual; returns the squared filtered norm |S g|^2_{M^-1}. */
static double residual(newton_problem *pb) {
  world_body *s = pb->s;
  struct implicit_state *st = pb->st;
  const int32_t n = s->n;
  const double inv_dt = 1.0 / pb->dt;
  if (pb->damped) {
    double *v = st->scratch_v;
    for (int64_t j = 0; j < 3 * (int64_t)n; ++j) v[j] = (s->x[j] - s->x_old[j]) * inv_dt;
    piola__body_damping_forces(s, v, pb->beta, pb->alpha, st->damping);
  }
  return sum_over_ranges(n, PIOLA_PARALLEL_MIN_VERTICES, residual_range, pb);
}

/* The CG's vector work: one pass per CG phase over the 16 fixed node ranges (in parallel
 * for large bodies, each range's sum added in order, so results do not depend on the thread
 * count), so each vector is read once per phase and no phase runs on one core alone. A pass
 * is a few microseconds per thousand nodes, so below CG_PARALLEL_MIN_VERTICES the fork and
 * the barrier cost more than they save (and on a loaded machine a barrier can wait a whole
 * scheduler slice for a descheduled thread). */
#define CG_PARALLEL_MIN_VERTICES 16384

typedef struct cg_vectors {
  const world_body *s;
  const piola__stiffness_matrix *mx;
  const piola__incomplete_cholesky *factor; /* NULL: block Jacobi (or multigrid) */
  piola__multigrid *multigrid;              /* NULL: block Jacobi (or IC(0)) */
  double *d, *r, *z, *p, *q;
  const double *g; /* the residual the solve starts from */
  double alpha;    /* the step length of cg_update_range */
} cg_vectors;

/* z_i = S_i P_i^-1 r_i, P_i the diagonal block (block Jacobi; with the IC(0) factor or the
 * multigrid z is formed after the pass, see precondition_factored); returns r_i . z_i. */
static inline double precondition_node(const cg_vectors *c, int32_t i) {
  if (c->factor || c->multigrid) return 0;
  const double *b = c->mx->inverse_diagonal + 9 * (size_t)i, *x = c->r + 3 * i;
  double *y = c->z + 3 * i;
  y[0] = b[0] * x[0] + b[1] * x[1] + b[2] * x[2];
  y[1] = b[3] * x[0] + b[4] * x[1] + b[5] * x[2];
  y[2] = b[6] * x[0] + b[7] * x[1] + b[8] * x[2];
  filter_node(c->s, i, c->z);
  return x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
}

/* With the multigrid or IC(0): node i's part of |r|^2 in the M^-1 norm, the line search's
 * (for the CG's second stopping test, see solve_newton_system); 0 with block Jacobi. */
static inline double factored_merit_node(const cg_vectors *c, int32_t i) {
  if (!c->multigrid && !c->factor) return 0;
  const double *r = c->r + 3 * i;
  return c->s->inverse_mass[i] * (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
}

/* z = S (U^T D U)^-1 r over the whole body (the substitutions are sequential), or
 * z = S V-cycle(r); returns r . z. The factor is of the filtered matrix, so its z is filtered
 * already up to rounding; the filter keeps the constrained components exactly zero (and
 * makes the V-cycle, which maps the free subspace to itself only approximately, act on it
 * as the filtered CG needs: S V S is symmetric positive definite there). */
static double r_dot_z_range(const void *context, int32_t i0, int32_t i1) {
  const cg_vectors *c = context;
  double sum = 0;
  for (int32_t i = i0; i < i1; ++i) {
    filter_node(c->s, i, c->z);
    const double *r = c->r + 3 * i, *z = c->z + 3 * i;
    sum += r[0] * z[0] + r[1] * z[1] + r[2] * z[2];
  }
  return sum;
}

static double precondition_factored(const cg_vectors *c) {
  if (c->multigrid) piola__multigrid_apply(c->multigrid, c->s->solid, c->r, c->z);
  else piola__incomplete_cholesky_apply(c->factor, c->s->solid, c->r, c->z);
  return sum_over_ranges(c->s->n, CG_PARALLEL_MIN_VERTICES, r_dot_z_range, c);
}

/* d = 0, r = -S g, z = S P^-1 r, p = z over nodes i0 .. i1 - 1 (g = c->g);
 * returns their part of r . z (with the multigrid or IC(0): of |r|^2_{M^-1}). */
static double cg_start_range(const void *context, int32_t i0, int32_t i1) {
  const cg_vectors *c = context;
  const double *g = c->g;
  double sum = 0;
  for (int32_t i = i0; i < i1; ++i) {
    for (int k = 0; k < 3; ++k) c->d[3 * i + k] = 0, c->r[3 * i + k] = -g[3 * i + k];
    filter_node(c->s, i, c->r);
    sum += precondition_node(c, i) + factored_merit_node(c, i);
    for (int k = 0; k < 3; ++k) c->p[3 * i + k] = c->z[3 * i + k];
  }
  return sum;
}

/* q = S q (q = A p on entry); returns this range's part of p . q. */
static double cg_curvature_range(const void *context, int32_t i0, int32_t i1) {
  const cg_vectors *c = context;
  double sum = 0;
  for (int32_t i = i0; i < i1; ++i) {
    filter_node(c->s, i, c->q);
    const double *p = c->p + 3 * i, *q = c->q + 3 * i;
    sum += p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
  }
  return sum;
}

/* d += a p, r -= a q, z = S P^-1 r (a in c->alpha); returns this range's part of r . z
 * (with the multigrid or IC(0): of |r|^2_{M^-1}). */
static double cg_update_range(const void *context, int32_t i0, int32_t i1) {
  const cg_vectors *c = context;
  const double a = c->alpha;
  double sum = 0;
  for (int32_t i = i0; i < i1; ++i) {
    for (int k = 0; k < 3; ++k) {
      c->d[3 * i + k] += a * c->p[3 * i + k];
      c->r[3 * i + k] -= a * c->q[3 * i + k];
    }
    sum += precondition_node(c, i) + factored_merit_node(c, i);
  }
  return sum;
}

static double cg_pass(const cg_vectors *c, range_pass *pass) {
  return sum_over_ranges(c->s->n, CG_PARALLEL_MIN_VERTICES, pass, c);
}

/* p = z + b p. */
static void cg_direction(const cg_vectors *c, double b) {
  const int64_t m = 3 * (int64_t)c->s->n;
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) \
    if (c->s->n >= CG_PARALLEL_MIN_VERTICES)
  for (int64_t j = 0; j < m; ++j) c->p[j] = c->z[j] + b * c->p[j];
}

/* How a solid's vertex is held, for the IC(0) factor and the multigrid (filter_vector's
 * projection). */
static int vertex_constraint(const void *context, int32_t i, double normal[3]) {
  const world_body *s = context;
  if (s->flags[i] != NODE_FREE || s->inverse_mass[i] == 0 || s->colliding[i] == HELD_BY_FRICTION)
    return 1;
  if (!s->colliding[i]) return 0;
  for (int k = 0; k < 3; ++k) normal[k] = s->normals[3 * i + k];
  return 2;
}

/* Factors the Newton system just assembled when the preconditioner is IC(0), or prepares
 * the multigrid hierarchy for it (solids): set up once per step, at its first Newton system,
 * and refreshed on its finest level for the later ones (stiffness_multigrid.h; measured in
 * BENCHMARKS.md, "Implicit integrators": the full setup at every Newton iteration costs more
 * than the iterations it saves). */
static piola_status factor_newton_system(newton_problem *pb) {
  struct implicit_state *st = pb->st;
  /* the tail keeps the last projected system's preconditioner, unless the contact set has
   * changed since (follows_contacts): its constraints are then the old ones */
  if (pb->signed_twist && !pb->contacts_moved) return PIOLA_OK;
  pb->contacts_moved = 0;
  st->factored = pb->w->def.preconditioner == PIOLA_PRECONDITIONER_INCOMPLETE_CHOLESKY &&
                 pb->s->kind == PIOLA_BODY_SOLID && st->factor.pair_start &&
                 !piola__implicit_split_of(pb->s);
  if (st->factored)
    piola__incomplete_cholesky_factor(&st->factor, &st->matrix, pb->s->solid, vertex_constraint,
                                      pb->s);
  st->multigrid_ready = pb->w->def.preconditioner == PIOLA_PRECONDITIONER_MULTIGRID &&
                        pb->s->kind == PIOLA_BODY_SOLID && st->multigrid.entry_edge &&
                        !piola__implicit_split_of(pb->s);
  if (!st->multigrid_ready) return PIOLA_OK;
  if (st->multigrid_fresh) {
    piola__multigrid_refresh(&st->multigrid, &st->matrix, pb->s->solid, vertex_constraint, pb->s);
    return PIOLA_OK;
  }
  PIOLA_TRY(piola__multigrid_setup(&st->multigrid, &st->matrix, pb->s->solid, vertex_constraint,
                                   pb->s));
  st->multigrid_fresh = 1;
  return PIOLA_OK;
}

/* Eisenstat and Walker's forcing term (1996, choice 2 with gamma 0.9, exponent 2): the CG
 * tolerance of a Newton system, from the squared residual norms phi of this iteration and
 * the last (phi_last < 0: the first iteration) and the last tolerance. Loose while Newton
 * is far from the solution or converging slowly (solving a linear model accurately there
 * buys nothing: the next iteration has another one), tight where it converges fast; not
 * tighter than half of what lands on the Newton target target2 (no oversolving on the last
 * iteration), nor than linear_tolerance; never above FORCING_MAX.
 *
 * The ratio |g_k| / |g_k-1| measures how well the last linear model predicted the residual
 * only when the last step was a full one. After the line search shortened it (shortened),
 * a barely falling residual is the globalization's doing (the backtracking, the
 * Levenberg-Marquardt shift it grows), and reading it as "converging slowly, solve loosely"
 * feeds on itself: half-solved regularized systems give poorer directions, shorter steps,
 * a larger shift. Without inertia in the matrix this stalled a quasistatic cantilever
 * (docs/time-stepping.md), so then the tolerance is at most FORCING_AFTER_SHORT_STEP. */
#define FORCING_MAX 0.5
#define FORCING_AFTER_SHORT_STEP 0.1

static double forcing_term(const piola_world_def *def, double phi, double phi_last,
                           double eta_last, double target2, int shortened) {
  if (def->linear_forcing == PIOLA_FORCING_FIXED) return def->linear_tolerance;
  double eta = FORCING_MAX;
  if (phi_last > 0) {
    eta = 0.9 * phi / phi_last; /* (|g_k| / |g_k-1|)^2 */
    const double safeguard = 0.9 * eta_last * eta_last;
    if (safeguard > 0.1) eta = fmax(eta, safeguard);
  }
  if (phi > 0) eta = fmax(eta, 0.5 * sqrt(target2 / phi));
  if (shortened) eta = fmin(eta, FORCING_AFTER_SHORT_STEP);
  return fmax(fmin(eta, FORCING_MAX), def->linear_tolerance);
}

/* Solves A d = -S g by the filtered preconditioned CG from d = 0 to the relative tolerance
 * eta; returns the iterations.
 *
 * The CG measures its residual in the preconditioner's norm (r . z). Block Jacobi's is a
 * diagonal scaling like the line search's M^-1 norm, so "r . z down by eta^2" also means
 * |r|_{M^-1} <= about eta |g|_{M^-1}, and the direction decreases the merit function. The
 * multigrid's V-cycle is close to A^-1, whose norm discounts exactly the rough residual
 * that dominates the M^-1 norm: after the few CG iterations a loose eta allows, |r|_{M^-1}
 * was up to 13 times |g|_{M^-1} in quasistatic steps (no mass in the matrix), no descent
 * direction, and Newton failed (docs/time-stepping.md). IC(0) is close to A^-1 too: with
 * Eisenstat-Walker's loose eta a clamped bar's first backward Euler step found no descent
 * along its second direction, failed three tries and kept a step 28% off. So with either
 * the CG also runs until |r|_{M^-1} <= eta |S g|_{M^-1}. */
static int32_t solve_newton_system(newton_problem *pb, double eta) {
  world_body *s = pb->s;
  struct implicit_state *st = pb->st;
  const int32_t n = s->n;
  const double mass_weight = pb->mass_weight + s->quasistatic_mu;
  double *d = st->step;
  cg_vectors c = {s,          &st->matrix, st->factored ? &st->factor : NULL,
                  st->multigrid_ready ? &st->multigrid : NULL,
                  d,          st->cg[0],   st->cg[1],
                  st->cg[2],  st->cg[3],   st->residual,
                  0};
  /* a split solid: the split's solver (PETSc, docs/mpi.md) instead of the loop below */
  const int split = piola__implicit_split_of(s) != NULL;
  int32_t it = split ? piola__implicit_split_solve(s, &st->matrix, st->residual, eta, &pb->w->def,
                                                   st->split_systems++, st->cg[0], d)
                     : 0;
  if (it < 0) it = 0; /* a failed solve leaves its best d; the line search judges it */
  pb->indefinite = 0;
  double rz = split ? 0.0 : cg_pass(&c, cg_start_range);
  double merit = rz; /* |r|^2_{M^-1} with the multigrid or IC(0) */
  if (!split && (c.factor || c.multigrid)) {
    rz = precondition_factored(&c);
    memcpy(c.p, c.z, sizeof(double) * 3 * (size_t)n);
  }
  const double stop = eta * eta * rz, merit_stop = eta * eta * merit;
  const int factored = c.factor || c.multigrid;
  while ((rz > stop || (factored && merit > merit_stop)) && rz > 0 &&
         it < pb->w->def.linear_max_iterations) {
    piola__body_stiffness_apply(s, c.mx, mass_weight, c.p, c.q);
    const double pq = cg_pass(&c, cg_curvature_range);
    if (!(pq > 0)) {
      pb->indefinite = 1;
      break;
    }
    c.alpha = rz / pq;
    double rz_new = cg_pass(&c, cg_update_range);
    if (factored) merit = rz_new, rz_new = precondition_factored(&c);
    cg_direction(&c, rz_new / rz);
    rz = rz_new;
    ++it;
  }
  if (!(rz >= 0)) pb->indefinite = 1; /* an indefinite preconditioner (block Jacobi's) */
  /* a free body: move d by the uniform displacement that makes sum M d = -sum g (K and D
   * ignore uniform fields, so the net residual after a full step is then zero whatever the
   * CG's accuracy or the regularization), so the linear momentum comes out exact */
  if (!pb->quasistatic && !has_filtered_nodes(s)) {
    double net[3] = {0, 0, 0};
    for (int32_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) net[k] += st->residual[3 * i + k] + s->mass[i] * d[3 * i + k];
    for (int32_t i = 0; i < n; ++i)
      if (s->mass[i] > 0)
        for (int k = 0; k < 3; ++k) d[3 * i + k] -= net[k] / pb->total_mass;
  }
  return it;
}

static piola_status update(newton_problem *pb) {
  return piola__body_update_forces(pb->s, pb->t1);
}

/* g . d, the potential's slope along the Newton direction (d is filtered, so held and
 * prescribed components do not count). */
static double residual_dot_step(const newton_problem *pb) {
  double slope = 0;
  for (int64_t j = 0; j < 3 * (int64_t)pb->s->n; ++j) slope += pb->st->residual[j] * pb->st->step[j];
  return slope;
}

/* The body's elastic energy of the last update (J). Collective on a split solid (the sum, the
 * same bits on every process). */
static double strain_energy(const newton_problem *pb) {
  world_body *s = pb->s;
  return s->kind == PIOLA_BODY_SOLID ? piola__elastic_body_total_energy(s->solid)
                                     : piola__body_stats(s).elastic_energy;
}

/* The work of gravity at t1 from the origin to positions x, sum m_i g1 . x_i (J): minus
 * gravity's potential, zero where the origin is. */
static double gravity_work(const newton_problem *pb, const double *x) {
  const world_body *s = pb->s;
  double work = 0;
  for (int64_t j = 0; j < 3 * (int64_t)s->n; ++j) work += s->mass[j / 3] * pb->g1[j % 3] * x[j];
  return work;
}

/* Quasistatics: the potential whose gradient g is, elastic energy minus the work of
 * gravity, sum V0 psi - sum m_i g1 . x_i (J), at the last update; a shell's elastic energy is
 * its membrane's and its hinges' bending energy. Collective on a split solid (the energy's
 * sum). */
static double quasistatic_potential(const newton_problem *pb) {
  return strain_energy(pb) - gravity_work(pb, pb->s->x);
}

/* The body's kinetic energy at velocities v and its elastic energy of the last update (J):
 * the part of total_energy below that does not depend on where gravity's potential is zero. */
static double motion_and_strain_energy(const newton_problem *pb, const double *v) {
  world_body *s = pb->s;
  double kinetic = 0;
  for (int64_t j = 0; j < 3 * (int64_t)s->n; ++j) kinetic += s->mass[j / 3] * v[j] * v[j];
  return 0.5 * kinetic + strain_energy(pb);
}

/* The body's total energy (J) at positions x with velocities v: kinetic, elastic (of the last
 * update, which must be at x) and gravity's potential at t1, so that every process of a
 * split solid keeps the same thing. */
static double total_energy(const newton_problem *pb, const double *x, const double *v) {
  return motion_and_strain_energy(pb, v) - gravity_work(pb, x);
}

/* Friction's moves may raise a shell's energy by this fraction of its kinetic and elastic
 * energy before they call for a second solve: resting contact raises it by a few tenths of
 * a percent a step, which a second solve would answer at a third more CG iterations; the
 * moves that matter (a stiff cloth landing on a frictional sphere) stored several times the
 * body's energy. */
#define FRICTION_ENERGY_RISE 0.1

/* How far a Newton try got: the fraction of the way, on a log scale, from its first
 * residual phi_first to the stop target2 that its last residual phi went; 0 for none (or
 * a residual that rose), 1 at convergence. */
static double try_progress(double phi_first, double phi, double target2) {
  if (!(phi_first > target2) || !(phi > 0) || !(phi < phi_first)) return 0;
  return log(phi_first / phi) / log(phi_first / target2);
}

/* A free body's failed iterate, moved uniformly so that its velocity (x - x^n) / dt carries
 * the start's momentum plus dt M g exactly. Each Newton direction is corrected so that a full
 * step keeps it, but a try that fails ends on a shortened step, and the correction also takes
 * in the rounding of the internal forces' sum, which in a scramble (forces of 1e10 N) is far
 * from zero: a scrambled armadillo with an initial velocity lost 1.6e-7 of its momentum in
 * its failed first frame. Internal forces ignore a translation, so nothing else changes. */
static void keep_free_momentum(newton_problem *pb) {
  world_body *s = pb->s;
  if (pb->quasistatic || has_filtered_nodes(s) || !(pb->total_mass > 0)) return;
  const double dt = pb->dt;
  double net[3] = {0, 0, 0};
  for (int32_t i = 0; i < s->n; ++i)
    for (int k = 0; k < 3; ++k) {
      const int64_t j = 3 * (int64_t)i + k;
      net[k] += s->mass[i] * (s->x[j] - s->x_old[j] - dt * s->v_old[j] - dt * dt * pb->g1[k]);
    }
  for (int32_t i = 0; i < s->n; ++i) {
    if (!(s->mass[i] > 0)) continue;
    for (int k = 0; k < 3; ++k) {
      const int64_t j = 3 * (int64_t)i + k;
      s->x[j] -= net[k] / pb->total_mass;
      s->v[j] = (s->x[j] - s->x_old[j]) / dt;
    }
  }
}

/* What a failed backward Euler try keeps (docs/time-stepping.md, "What a failed step keeps"):
 * its iterate and velocity (x - x^n) / dt, turned to the start's angular momentum, when they
 * hold no more energy than the step's start (x^n, v^n); else the iterate with the rigid
 * velocity of the start's momentum (failed_step_velocity.h) when that holds no more; else the
 * start's positions with that velocity. The start's energy takes an update at x^n and one
 * back; a failed last try costs far more. */
static piola_status keep_failed_step(newton_problem *pb) {
  world_body *s = pb->s;
  struct implicit_state *st = pb->st;
  const size_t bytes = sizeof(double) * 3 * (size_t)s->n;
  keep_free_momentum(pb);
  piola__failed_step_keep_angular_momentum(s->n, s->mass, s->x_old, s->v_old, s->x, s->v);
  const double end = total_energy(pb, s->x, s->v);
  memcpy(st->base, s->x, bytes);
  memcpy(s->x, s->x_old, bytes);
  PIOLA_TRY(update(pb));
  const double start = total_energy(pb, s->x_old, s->v_old);
  if (end <= start) {
    memcpy(s->x, st->base, bytes);
    return update(pb);
  }
  /* the start's positions (prescribed nodes at t1), unless the iterate holds no more energy
   * with the rigid velocity. Those hold no more than the start plus a step of gravity's work:
   * at the start's shape the rigid motion has the least kinetic energy of any velocity with
   * the start's momentum */
  memcpy(s->x, st->base, bytes);
  PIOLA_TRY(update(pb));
  piola__failed_step_velocity(s->n, s->mass, s->x_old, s->v_old, s->x, pb->g1, pb->dt, s->v);
  const double rigid = total_energy(pb, s->x, s->v);
  if (rigid <= start) return PIOLA_OK;
  if (st->may_go_deeper) {
    st->went_deeper = 1; /* the caller undoes the try and halves it */
    return PIOLA_ERROR_NOT_CONVERGED;
  }
  piola__world_warn(pb->w, PIOLA_WARNING_STEP_KEPT_START,
                    "%s '%s': the failed backward Euler step to t = %g s kept its start's "
                    "positions with a rigid velocity, since its iterate held more energy than "
                    "the start (time-stepping.md, \"What a failed step keeps\"); a body whose "
                    "every step does this does not move. The energy inversion mode freezes "
                    "this way on scrambled meshes; with any extension, more damping or a "
                    "shorter integrator.dt can help (materials.md, \"With backward Euler, "
                    "scrambles can freeze\")",
                    piola__body_kind_name(s->kind), s->name, pb->t1);
  memcpy(s->x, s->x_old, bytes);
  s->kept_start = 1;
  piola__failed_step_velocity(s->n, s->mass, s->x_old, s->v_old, s->x, pb->g1, pb->dt, s->v);
  for (int32_t i = 0; i < s->n; ++i)
    if (s->flags[i] != NODE_FREE)
      piola__body_constrained_state(s, i, pb->t1, s->x + 3 * i, s->v + 3 * i);
  PIOLA_TRY(update(pb));
  (void)residual(pb);
  return PIOLA_OK;
}

/* The step's problem for solid s over [t, t + dt]; reads no state. */
static newton_problem problem_of(piola_world *w, world_body *s, double t, double dt) {
  newton_problem pb;
  memset(&pb, 0, sizeof pb);
  pb.w = w, pb.s = s, pb.st = s->implicit, pb.dt = dt, pb.t1 = t + dt;
  pb.quasistatic = w->def.integrator == PIOLA_INTEGRATOR_QUASISTATIC;
  for (int k = 0; k < 3; ++k) pb.g1[k] = piola_track_eval(&w->def.gravity[k], pb.t1);
  pb.beta = piola_track_eval(&s->shear_viscosity, pb.t1);
  pb.alpha = piola_track_eval(&s->bulk_viscosity, pb.t1);
  pb.damped = !pb.quasistatic && !piola__body_undamped(s, pb.beta, pb.alpha);
  pb.force_weight = pb.quasistatic ? 1.0 : dt * dt;
  pb.mass_weight = pb.quasistatic ? 0.0 : 1.0;
  for (int32_t i = 0; i < s->n; ++i) pb.total_mass += s->mass[i];
  return pb;
}

static piola_status newton_iterate(const newton_problem *problem, int accept_unconverged,
                                   piola_step_stats *stats);
static int same_quasistatic_load(const piola_world *w, const world_body *s, double t_a,
                                 double t_b);

/* Newton's method for one body over [t, t + dt]. Returns PIOLA_OK when converged,
 * PIOLA_ERROR_NOT_CONVERGED when not (the caller undoes and halves), or another error. */
static piola_status newton_body(piola_world *w, world_body *s, double t, double dt, int halvings,
                                piola_step_stats *stats) {
  PIOLA_TRY(implicit_state_make(s, w->def.preconditioner));
  struct implicit_state *st = s->implicit;
  st->multigrid_fresh = 0; /* a new step: the hierarchy is set up again */
  st->split_systems = 0;   /* likewise the split solver's preconditioner */
  piola__solid_contacts_solve_begins(w);
  if (halvings == 0) st->failed_progress = -1, st->has_retry_guess = 0;
  st->halvings = halvings;
  st->may_go_deeper = 0, st->went_deeper = 0;
  const int accept_unconverged = halvings >= MAX_HALVINGS;
  const int32_t n = s->n;
  const int64_t m = 3 * (int64_t)n;
  newton_problem pb = problem_of(w, s, t, dt);
  if (!pb.quasistatic) s->quasistatic_mu = 0;

  /* after a step that kept its start, a tangled start's energy, for RECOVERING_DROP (the
   * forces, and so the energy densities, are those of x^n) */
  if (halvings == 0) st->after_kept_start = s->kept_start, s->kept_start = 0;
  st->start_elastic = 0;
  double det = 0;
  if (st->after_kept_start && s->kind == PIOLA_BODY_SOLID && !pb.quasistatic &&
      piola__solid_flat_or_inverted_tet(s, s->x, &det, 0.0) >= 0) {
    st->start_elastic = piola__elastic_body_total_energy(s->solid);
    st->start_energy = total_energy(&pb, s->x, s->v);
  }

  /* the prediction, and the first guess: the prediction plus a step of gravity, or for a
   * solid held by a constraint or whose step of gravity would take a node into an obstacle
   * only GUESS_GRAVITY_FRACTION of it (backward Euler); the last equilibrium, its nodes
   * resting on obstacles held (quasistatics); prescribed nodes at t1. The contacts of the
   * last step are cleared first: a resumed run has none, and must take the same guess. */
  memcpy(s->x_old, s->x, sizeof(double) * (size_t)m);
  memcpy(s->v_old, s->v, sizeof(double) * (size_t)m);
  memcpy(s->force_old, s->force, sizeof(double) * (size_t)m);
  for (int64_t j = 0; j < m; ++j) st->prediction[j] = s->x[j] + (pb.quasistatic ? 0.0 : dt * s->v[j]);
  if (n > 0) memset(s->colliding, 0, (size_t)n);
  for (int32_t i = 0; i < n; ++i) st->surface_mu[i] = NAN; /* no solid contact yet */
  if (!pb.quasistatic) {
    double fraction = 1.0;
    if (s->kind == PIOLA_BODY_SOLID) {
      const int supported =
          has_filtered_nodes(s) ? 1 : piola__newton_gravity_step_enters_obstacle(&pb);
      if (supported < 0) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "implicit step: out of memory");
      if (supported) fraction = GUESS_GRAVITY_FRACTION;
    }
    for (int32_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k)
        s->x[3 * (int64_t)i + k] = st->prediction[3 * (int64_t)i + k] + fraction * dt * dt * pb.g1[k];
  }
  for (int32_t i = 0; i < n; ++i) {
    if (s->flags[i] == NODE_FREE) continue;
    double vp[3];
    piola__body_constrained_state(s, i, pb.t1, s->x + 3 * i, vp);
  }
  if (pb.quasistatic && halvings > 0 && st->has_retry_guess &&
      same_quasistatic_load(w, s, st->retry_guess_t1, pb.t1))
    for (int32_t i = 0; i < n; ++i)
      if (s->flags[i] == NODE_FREE) memcpy(s->x + 3 * i, st->retry_guess + 3 * i, sizeof(double) * 3);
  (void)piola__newton_resting_contacts(&pb);
  if (piola__newton_contacts(&pb) < 0)
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "implicit step: out of memory");
  PIOLA_TRY(update(&pb));
  return newton_iterate(&pb, accept_unconverged, stats);
}

/* Assembles, factors and solves the Newton system at the current iterate into st->step.
 * The tail's matrix (pb->signed_twist) is not definite everywhere: where its CG meets
 * non-positive curvature, or block Jacobi's diagonal turns out indefinite, the system is
 * assembled projected and solved again, and the tail stays off for the rest of the step
 * (*tail_allowed = 0). */
static piola_status newton_direction(newton_problem *pb, double eta, int *tail_allowed,
                                     piola_step_stats *stats) {
  piola_world *w = pb->w;
  world_body *s = pb->s;
  struct implicit_state *st = pb->st;
  const double dt = pb->dt;
  /* the damping matrix does not depend on the stiffness's projection: once, before a
   * fallback's second assembly */
  if (pb->damped) piola__body_damping_prepare(s, pb->beta, pb->alpha);
  for (;;) {
    if (s->kind == PIOLA_BODY_SOLID) s->solid->signed_twist = pb->signed_twist;
    piola__body_stiffness_assemble(s, &st->matrix, pb->force_weight, pb->damped ? dt : 0.0,
                                   pb->beta, pb->alpha, pb->mass_weight);
    if (pb->quasistatic) {
      if (!(s->quasistatic_mu > 0)) {
        /* the first regularization: a small fraction of the mean stiffness per mass */
        const double trace = piola__implicit_matrix_trace(s, &st->matrix);
        s->quasistatic_mu = 1e-6 * trace / (3.0 * pb->total_mass);
        if (!(s->quasistatic_mu > 0)) s->quasistatic_mu = 1.0;
      }
      piola__body_stiffness_set_mass_weight(s, &st->matrix, pb->force_weight, 0.0, pb->beta,
                                            pb->alpha, s->quasistatic_mu);
    } else if (s->quasistatic_mu > 0) {
      piola__body_stiffness_set_mass_weight(s, &st->matrix, pb->force_weight,
                                            pb->damped ? dt : 0.0, pb->beta, pb->alpha,
                                            pb->mass_weight + s->quasistatic_mu);
    }
    PIOLA_TRY(factor_newton_system(pb));
    piola__step_profile_mark(&w->profile, STEP_PHASE_ASSEMBLE);
    stats->linear_iterations += solve_newton_system(pb, eta);
    piola__step_profile_mark(&w->profile, STEP_PHASE_LINEAR);
    if (!(pb->signed_twist && pb->indefinite)) return PIOLA_OK;
    pb->signed_twist = 0, *tail_allowed = 0;
  }
}

/* Quasistatics: how far one Newton iteration may move a node, and how far a failed step's
 * kept iterate may have moved one: the body's size (the larger bounding-box diagonal of its
 * rest shape and of the step's start; a solid collapsed to a point still has its rest size).
 * A body held by frictionless obstacle contacts alone slides and turns along them at no cost
 * in potential or residual, so -K + mu M is singular there but for mu, which full steps
 * shrink a tenfold each: a unit ball resting on a plane (medit/unit_ball.mesh, E = 100 kPa)
 * took a step of 1.7e13 m along the plane, and its failed frames kept iterates 1e11 m away.
 * Converged steps take far shorter steps than this. */
static double quasistatic_reach(const world_body *s) {
  double reach = piola__bounding_diagonal(s->n, s->x_old);
  if (s->kind == PIOLA_BODY_SOLID)
    reach = fmax(reach, piola__bounding_diagonal(s->n, s->solid->rest_positions));
  return reach > 0 ? reach : INFINITY;
}

/* Scales the Newton step down so that no node moves further than reach; 1 when it did. */
static int limit_step(newton_problem *pb, double reach) {
  const world_body *s = pb->s;
  double longest2 = 0;
  for (int32_t i = 0; i < s->n; ++i) {
    const double *d = pb->st->step + 3 * (size_t)i;
    longest2 = fmax(longest2, d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  }
  if (!(longest2 > reach * reach)) return 0;
  const double scale = reach / sqrt(longest2);
  for (int64_t j = 0; j < 3 * (int64_t)s->n; ++j) pb->st->step[j] *= scale;
  return 1;
}

/* 1 when a node of s that has mass is fixed, driven or held by a bone (a vertex in no
 * element is held, but holds nothing). */
static int held_by_nodes(const world_body *s) {
  for (int32_t i = 0; i < s->n; ++i)
    if (s->mass[i] > 0 && s->flags[i] != NODE_FREE) return 1;
  return 0;
}

/* 1 when a free node of s is further than reach from where the step started. */
static int moved_beyond(const world_body *s, double reach) {
  for (int32_t i = 0; i < s->n; ++i) {
    if (s->flags[i] != NODE_FREE) continue;
    double d2 = 0;
    for (int k = 0; k < 3; ++k) {
      const double d = s->x[3 * (size_t)i + k] - s->x_old[3 * (size_t)i + k];
      d2 += d * d;
    }
    if (d2 > reach * reach) return 1;
  }
  return 0;
}

/* 1 when a failed quasistatic try's iterate is no result: a free node went further than the
 * body's size (reach), or twice that for a body held at a node, which turning about it
 * takes that far (a flat cloth pinned at two corners of an edge hangs with its far edge 1.03
 * times its diagonal from where it started). */
static int moved_beyond_kept_reach(const world_body *s, double reach) {
  return moved_beyond(s, held_by_nodes(s) ? 2.0 * reach : reach);
}

/* 1 when the quasistatic problems of s ending at t_a and at t_b are the same: gravity, the
 * body's activation and stiffness scale, its prescribed nodes' positions and every
 * obstacle's pose, bit for bit. Halving a failed try then changes nothing but the time, so
 * the retry goes on from the failed try's iterate instead of solving it again from the
 * step's start. */
static int same_quasistatic_load(const piola_world *w, const world_body *s, double t_a,
                                 double t_b) {
  for (int k = 0; k < 3; ++k)
    if (piola_track_eval(&w->def.gravity[k], t_a) != piola_track_eval(&w->def.gravity[k], t_b))
      return 0;
  if (piola_track_eval(&s->activation, t_a) != piola_track_eval(&s->activation, t_b) ||
      piola_track_eval(&s->stiffness_scale, t_a) != piola_track_eval(&s->stiffness_scale, t_b))
    return 0;
  for (int32_t i = 0; i < s->n; ++i) {
    if (s->flags[i] == NODE_FREE) continue;
    double xa[3], xb[3], v[3];
    piola__body_constrained_state(s, i, t_a, xa, v);
    piola__body_constrained_state(s, i, t_b, xb, v);
    if (xa[0] != xb[0] || xa[1] != xb[1] || xa[2] != xb[2]) return 0;
  }
  for (int32_t o = 0; o < w->obstacle_count; ++o) {
    if (!w->obstacles[o]) continue;
    piola__rigid_state a, b;
    piola__rigid_motion_state(&w->obstacles[o]->motion, t_a, &a);
    piola__rigid_motion_state(&w->obstacles[o]->motion, t_b, &b);
    if (memcmp(&a.rotation, &b.rotation, sizeof a.rotation) != 0 ||
        memcmp(&a.translation, &b.translation, sizeof a.translation) != 0)
      return 0;
  }
  return 1;
}

/* The Newton failure warning's advice for a quasistatic body (time-stepping.md,
 * "Quasistatics"): held by nothing, or by obstacle contacts alone, it may have no
 * equilibrium; held by constrained nodes, a load it cannot take in one step converges when
 * ramped (a soft HGO elbow, medit/elbow.mesh, under the whole of gravity at once: its first
 * step failed after three halvings, which do not shrink a quasistatic load; with gravity
 * keyframed up from 0 over 0.2 s, none failed). The contacts are those of the failed try
 * (colliding is cleared at each step's start). Backward Euler: none. */
static const char *failure_advice(const newton_problem *pb) {
  if (!pb->quasistatic) return "";
  const world_body *s = pb->s;
  if (held_by_nodes(s))
    return ". A load a quasistatic body cannot take in one step (the whole of gravity at "
           "once on a soft solid, a muscle's activation switched on at once, a large jump "
           "of a driven node) converges when ramped: keyframe gravity (or the activation, "
           "or the motion) up from 0 over a few frames (time-stepping.md, \"Quasistatics\")";
  int touching = 0;
  for (int32_t i = 0; i < s->n; ++i)
    if (s->mass[i] > 0 && s->colliding[i]) touching = 1;
  if (!touching)
    return ". A quasistatic body with nothing holding it (no fixed, driven or bone node, no "
           "obstacle contact) has no equilibrium under gravity: fix or drive a node, or use "
           "\"backward_euler\" (time-stepping.md, \"Quasistatics\")";
  return ". A quasistatic body held by obstacle contacts alone has no equilibrium: fix or "
         "drive a node, or use \"backward_euler\" (time-stepping.md, \"Quasistatics\")";
}

/* Newton's iterations from the body's current state (its forces up to date), then the
 * velocities, friction and prescribed nodes. */
static piola_status newton_iterate(const newton_problem *problem, int accept_unconverged,
                                   piola_step_stats *stats) {
  newton_problem pb = *problem;
  piola_world *w = pb.w;
  world_body *s = pb.s;
  struct implicit_state *st = pb.st;
  const int32_t n = s->n;
  const int64_t m = 3 * (int64_t)n;
  const double dt = pb.dt;
  const double target = w->def.newton_tolerance * STANDARD_GRAVITY * pb.force_weight;
  const double target2 = target * target * pb.total_mass;
  double phi = residual(&pb);
  const double phi_first = phi;
  double phi_last = -1, eta = w->def.linear_tolerance;
  double last_alpha = 1.0; /* the last line search's step (the forcing term reads it) */
  /* the tail's matrix (see the head of this file): solids on one process, backward Euler
   * and quasistatics alike; once it has failed, not again in this step */
  int tail_allowed = s->kind == PIOLA_BODY_SOLID && !piola__implicit_split_of(s);
  /* whether the tail may follow a contact change: with block Jacobi (its preconditioner is
   * the matrix's own diagonal) and the multigrid (factor_newton_system refreshes level 0
   * from the tail's matrix when the contact set has moved); IC(0) keeps its last projected
   * factor, so there a contact change returns to the projected matrix. Measured on the
   * Figure 2 torus resting on its plane: 6, 5, 5 Newton iterations per resting frame instead
   * of 8, 7, 5 (docs/time-stepping.md, "The Newton tail") */
  const int follows_contacts =
      w->def.preconditioner != PIOLA_PRECONDITIONER_INCOMPLETE_CHOLESKY;
  pb.signed_twist = 0;
  int converged = 0;
  const double reach = pb.quasistatic ? quasistatic_reach(s) : INFINITY;
  /* the test runs once more after the last iteration: an iterate that converges there is
   * a converged step, not a failed one */
  for (int32_t iter = 0;; ++iter) {
    if (!isfinite(phi)) break;
    if (phi <= target2) {
      if (piola__newton_release_contacts(&pb, 1) == 0) {
        converged = 1;
        break;
      }
      phi = residual(&pb);
      if (phi <= target2) {
        converged = 1;
        break;
      }
    }
    if (iter == w->def.newton_max_iterations) break;
    /* contacts whose force pulls are released at every iteration after the first (whose
     * residual reflects the first guess more than the contact): releasing them only once
     * converged costs a whole Newton solve per round of releases (measured on a torus
     * landing on a plane: 22-24 iterations per frame, 10-13 this way) */
    const int32_t released = iter > 0 ? piola__newton_release_contacts(&pb, 0) : 0;
    if (released > 0) phi = residual(&pb);
    stats->newton_iterations++;
    piola__step_profile_mark(&w->profile, STEP_PHASE_UPDATE);
    if (released > 0 && !follows_contacts) pb.signed_twist = 0;
    eta = forcing_term(&w->def, phi, phi_last, eta, target2, last_alpha < 1.0);
    phi_last = phi;
    PIOLA_TRY(newton_direction(&pb, eta, &tail_allowed, stats));
    const int limited = pb.quasistatic && limit_step(&pb, reach);
    /* backtracking line search on |S g|^2, and for a quasistatic body also on its
     * potential: a step is accepted when either decreases by the Armijo fraction (see the
     * head of this file) */
    memcpy(st->base, s->x, sizeof(double) * (size_t)m);
    double potential = 0, slope = 0;
    int on_potential = 0;
    if (pb.quasistatic) {
      potential = quasistatic_potential(&pb);
      slope = residual_dot_step(&pb);
      on_potential = isfinite(potential) && slope < 0;
    }
    double alpha = 1.0, best_phi = phi, best_alpha = 0.0;
    int accepted = 0;
    for (int tries = 0; tries < 12; ++tries) {
      for (int64_t j = 0; j < m; ++j) s->x[j] = st->base[j] + alpha * st->step[j];
      piola_status us = update(&pb);
      double trial = us == PIOLA_OK ? residual(&pb) : INFINITY;
      const int descends = on_potential && isfinite(trial) &&
                           quasistatic_potential(&pb) <= potential + 1e-4 * alpha * slope;
      if (trial <= (1.0 - 1e-4 * alpha) * phi || descends) {
        phi = trial;
        accepted = 1;
        break;
      }
      if (trial < best_phi) best_phi = trial, best_alpha = alpha;
      alpha *= 0.5;
    }
    if (!accepted) {
      if (!(best_alpha > 0)) {
        /* no decrease at all: Newton failed. Quasistatics ends at the iterate the search
         * started from: the last trial, 1/2048 of a step that the nearly singular -K + mu M
         * can make huge, is no result (a last try kept it: armadillo_4k on a frictionless
         * plane ended 1e9 m away). Backward Euler keeps that trial: M / dt^2 bounds its
         * step, and it is how a body collapsed to a point leaves the point (restoring the
         * start left test_backward_euler_recovery's point collapse there, every step
         * failing) */
        if (pb.quasistatic) {
          memcpy(s->x, st->base, sizeof(double) * (size_t)m);
          PIOLA_TRY(update(&pb));
          phi = residual(&pb);
        }
        break;
      }
      alpha = best_alpha;
      for (int64_t j = 0; j < m; ++j) s->x[j] = st->base[j] + alpha * st->step[j];
      PIOLA_TRY(update(&pb));
      phi = residual(&pb);
    }
    last_alpha = alpha;
    if (pb.quasistatic) {
      /* a step the reach cut short: the regularization is too weak for the body's
       * (nearly) free directions, as after a short step */
      if (limited)
        s->quasistatic_mu *= 10.0;
      else if (alpha == 1.0)
        s->quasistatic_mu = fmax(s->quasistatic_mu / 10.0, 1e-300);
      else if (alpha < 0.25)
        s->quasistatic_mu *= 10.0;
    } else {
      /* backward Euler: an iteration that had to backtrack far adds a multiple of M to the
       * matrix (Levenberg-Marquardt: shorter, more gradient-like steps), full steps take it
       * away again */
      if (alpha < 0.25)
        s->quasistatic_mu = s->quasistatic_mu > 0 ? fmin(4.0 * s->quasistatic_mu, 1e8) : 1.0;
      else if (alpha == 1.0)
        s->quasistatic_mu = s->quasistatic_mu > 1e-3 ? 0.25 * s->quasistatic_mu : 0.0;
    }
    int32_t added = piola__newton_contacts(&pb);
    if (added < 0) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "implicit step: out of memory");
    if (pb.signed_twist && alpha < 1.0) tail_allowed = 0;
    /* backward Euler: not while a Levenberg-Marquardt shift is on. Quasistatics always has
     * one, which a full step has just divided by 10: there the tail follows every full
     * step (examples/muscle_spindle_hanging.json as quasistatic: 30 Newton iterations in
     * 10 frames instead of 523 and 8 failed tries) */
    pb.signed_twist = tail_allowed && alpha == 1.0 && !limited &&
                      (follows_contacts || (added == 0 && released == 0)) &&
                      (pb.quasistatic || !(s->quasistatic_mu > 0));
    if (added > 0) {
      PIOLA_TRY(update(&pb));
      phi = residual(&pb);
    }
  }
  if (s->kind == PIOLA_BODY_SOLID) s->solid->signed_twist = 0;
  if (!converged) {
    /* the regularization a failed Newton shrank or grew is no start for the retry (a
     * quasistatic retry that began at the failed try's mu of 1e-22 took a first step of
     * 1e38 m): it starts again from the first one */
    if (pb.quasistatic) s->quasistatic_mu = 0;
    /* backward Euler after a frozen step: a try that lets go of the tangle is kept whole
     * (RECOVERING_DROP) */
    if (!pb.quasistatic && isfinite(phi) && !accept_unconverged && s->kind == PIOLA_BODY_SOLID &&
        st->start_elastic > 0) {
      for (int64_t j = 0; j < m; ++j) s->v[j] = (s->x[j] - s->x_old[j]) / dt;
      accept_unconverged =
          total_energy(&pb, s->x, s->v) <= st->start_energy - RECOVERING_DROP * st->start_elastic;
    }
    /* backward Euler: a retry that halving did not help is kept (HALVING_GAIN), unless it
     * is shorter than a last try: kept halves of what is left of a frame would shrink
     * geometrically, and the frame would never end. A kept try that would keep only its
     * start is halved on, when it got anywhere: to the last try's length, and past it
     * (DEEPER_HALVINGS) */
    if (!pb.quasistatic && isfinite(phi)) {
      const double progress = try_progress(phi_first, phi, target2);
      const int helped = st->failed_progress < 0 || progress > HALVING_GAIN * st->failed_progress;
      if (!accept_unconverged) accept_unconverged = !helped && dt >= last_try_length(w);
      st->may_go_deeper = !pb.resolving && progress >= DEEPER_MIN_PROGRESS &&
                          st->halvings < MAX_HALVINGS + DEEPER_HALVINGS &&
                          (st->halvings < MAX_HALVINGS || w->deeper_steps_left != 0);
      st->failed_progress = progress;
    }
    /* quasistatics: where the retry's load is the failed try's, it goes on from here */
    if (!accept_unconverged && pb.quasistatic && isfinite(phi) && !moved_beyond_kept_reach(s, reach)) {
      memcpy(st->retry_guess, s->x, sizeof(double) * (size_t)m);
      st->retry_guess_t1 = pb.t1, st->has_retry_guess = 1;
    }
    if (!accept_unconverged || !isfinite(phi)) return PIOLA_ERROR_NOT_CONVERGED;
    stats->newton_failures++;
    /* quasistatics: an iterate that took a node further than the body's size along its
     * free directions is no result; the free nodes stay where the step started */
    if (pb.quasistatic && moved_beyond_kept_reach(s, reach)) {
      for (int32_t i = 0; i < n; ++i)
        if (s->flags[i] == NODE_FREE) memcpy(s->x + 3 * i, s->x_old + 3 * i, sizeof(double) * 3);
      PIOLA_TRY(update(&pb));
    }
    /* only the clause of the body's own integrator: the other's would mislead */
    piola__world_warn(w, PIOLA_WARNING_NEWTON_FAILED,
                      "%s '%s': the %s step to t = %g s did not converge (Newton, on its "
                      "last try, or a retry that halving did not help); its last iterate was "
                      "kept (%s) and the run goes on "
                      "(stats.csv newton_failures counts failed tries)%s",
                      piola__body_kind_name(s->kind), s->name,
                      pb.quasistatic ? "quasistatic" : "backward Euler", pb.t1,
                      pb.quasistatic ? "unless it moved a node further than the body's size "
                                       "(twice that for a body held at a node), then the "
                                       "step's start"
                                     : "unless it held more energy than the step's start, "
                                       "time-stepping.md \"What a failed step keeps\"",
                      failure_advice(&pb));
  }
  /* velocities; friction; prescribed velocities */
  const double inv_dt = 1.0 / dt;
  for (int64_t j = 0; j < m; ++j) s->v[j] = (s->x[j] - s->x_old[j]) * inv_dt;
  if (!converged && !pb.quasistatic) PIOLA_TRY(keep_failed_step(&pb));
  const int may_slide =
      !pb.quasistatic && !pb.friction_held && converged && piola__newton_body_may_slide(&pb);
  if (may_slide && piola__newton_kinetic_friction(&pb) > 0) {
    /* a body that may slide as a whole: solved again with kinetic friction on every contact,
     * then the contacts friction stops are held (hold_reversed_slips) and those whose hold
     * leaves Coulomb's cone slip again (release_slipping_holds), up to FRICTION_SLIP_ROUNDS
     * rounds (docs/time-stepping.md, "Friction after the solve") */
    pb.friction_held = 1, pb.kinetic = 1, pb.contacts_moved = 1, pb.slip_rounds = 0;
    return newton_iterate(&pb, accept_unconverged, stats);
  }
  /* the most energy friction may leave the body (see below), from the converged iterate,
   * whose forces are the last update's, and that iterate's positions to fall back on */
  const int energy_checked = !pb.quasistatic && !pb.friction_held && converged;
  const double rise =
      energy_checked ? FRICTION_ENERGY_RISE * motion_and_strain_energy(&pb, s->v) : NAN;
  const double energy_allowed = energy_checked ? total_energy(&pb, s->x, s->v) + rise : NAN;
  const double strain_allowed = energy_checked ? strain_energy(&pb) + rise : NAN;
  double *kept = energy_checked ? st->friction_free : NULL;
  if (kept) memcpy(kept, s->x, sizeof(double) * (size_t)m);
  if (!pb.quasistatic && !pb.friction_held && piola__newton_contact_friction(&pb) > 0) {
    PIOLA_TRY(update(&pb));
    /* friction only takes energy away; moves that stored more in the body than they took
     * from its motion (a stiff cloth on a frictional sphere: 0.25 J of stretch in a 0.2 J
     * body; a stiff box under a ball and a lid: 3.6 J in a 2 J scene, with moves below the
     * altitude rule's) are answered by the rest of the body */
    const int energy_rose = kept && !(total_energy(&pb, s->x, s->v) <= energy_allowed);
    /* Friction moved nodes after the solve, and the rest of the body has not answered. Where
     * the moves could flatten or invert tets, or raised the body's energy, the step is solved
     * once more: the nodes friction stopped held where it put them (the hold supplies all of
     * their friction), the others pushed by the force it applied to them
     * (docs/time-stepping.md, "Friction after the solve") */
    if (energy_rose || piola__newton_friction_moves_deform(&pb)) {
      for (int32_t i = 0; i < n; ++i)
        if (st->hit[i] == 2) s->colliding[i] = HELD_BY_FRICTION; /* stopped */
      pb.friction_held = 1, pb.contacts_moved = 1;
      if (kept) memcpy(kept + m, s->v, sizeof(double) * (size_t)m); /* friction's velocities */
      piola_status resolved = newton_iterate(&pb, accept_unconverged, stats);
      /* where the holds stored energy too (a dented torus shell landing: 1.36 J of stretch
       * against 0.05 J before it), friction acts on the velocities alone in this step: the
       * positions of the first solve, its velocities limited as friction limited them. The
       * body's energy then falls, its kinetic energy being all that changed. A second solve
       * that does not converge is halved as any other: taking the first solve's positions
       * there instead let a box sliding on a box creep on (0.09 J left at rest). Stored as
       * strain: holds that keep a body where the step started give back the potential
       * energy the frictionless solve spent, a rise that is no stored energy, and taking the
       * first solve's positions there let a cloth that friction holds on a slope creep down
       * it by a step of its acceleration each step */
      if (energy_rose && resolved == PIOLA_OK &&
          !(total_energy(&pb, s->x, s->v) <= energy_allowed) &&
          !(strain_energy(&pb) <= strain_allowed)) {
        memcpy(s->x, kept, sizeof(double) * (size_t)m);
        memcpy(s->v, kept + m, sizeof(double) * (size_t)m);
        for (int32_t i = 0; i < n; ++i)
          if (s->flags[i] != NODE_FREE)
            piola__body_constrained_state(s, i, pb.t1, s->x + 3 * i, s->v + 3 * i);
        resolved = update(&pb);
      }
      return resolved;
    }
  } else if (pb.kinetic && converged && pb.slip_rounds < FRICTION_SLIP_ROUNDS &&
             piola__newton_next_friction_round(&pb)) {
    /* holds beyond Coulomb's cone slip, slips friction reverses are held, the kinetic
     * friction follows the normal forces: solved again */
    pb.slip_rounds++;
    PIOLA_TRY(update(&pb));
    return newton_iterate(&pb, accept_unconverged, stats); /* its forces are those of x */
  }
  int32_t colliding = 0;
  for (int32_t i = 0; i < n; ++i) {
    colliding += s->colliding[i] && s->flags[i] == NODE_FREE;
    if (s->flags[i] == NODE_FREE) continue;
    piola__body_constrained_state(s, i, pb.t1, s->x + 3 * i, s->v + 3 * i);
  }
  stats->colliding += colliding;
  for (int64_t j = 0; j < m; ++j)
    if (!isfinite(s->v[j]) || !isfinite(s->x[j]))
      return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE,
                        "%s '%s': state of vertex %lld became non-finite at t = %g s",
                        piola__body_kind_name(s->kind), s->name, (long long)(j / 3), pb.t1);
  return PIOLA_OK;
}

/* Contacts between bodies (self_collision) are resolved after the Newton solves by the
 * collision pass (contact.md), which changes the velocities of surface nodes only. A Newmark
 * step is short enough for the elastic forces to carry that change inwards before the next
 * one; a frame-sized step is not: the interior would keep the velocity the surface lost and
 * pass through it, inverting the elements behind every impact. So each body whose nodes
 * the pass moved is solved again from there, each moved node held along the push it got
 * (as an obstacle holds a node along its normal; released if it would have to pull), and
 * the pass runs once more on the result, which leaves the surfaces apart as before. Only
 * with the per-step collision pass (collision_interval 0), where each pass covers exactly
 * this step. */
/* Whether nothing outside the bodies held body s in this step: no prescribed node with mass,
 * no node held by an obstacle, by friction or (a coupled shell) by a solid. */
static int held_by_bodies_only(const world_body *s) {
  /* a solid's HELD_BY_SOLID is another solid's surface; a shell's, a solid that does not
   * feel it */
  const int solid = s->kind == PIOLA_BODY_SOLID && s->implicit;
  for (int32_t i = 0; i < s->n; ++i) {
    if (!(s->mass[i] > 0)) continue;
    if (s->flags[i] != NODE_FREE) return 0;
    const uint8_t held = s->colliding[i];
    if (!held || held == HELD_BY_COLLISION) continue;
    /* where friction stopped a solid's node on another solid (surface_mu is set) */
    if (solid && (held == HELD_BY_SOLID ||
                  (held == HELD_BY_FRICTION && isfinite(s->implicit->surface_mu[i]))))
      continue;
    return 0;
  }
  return 1;
}

/* Adds the velocity dv (m/s) to every node of s, moving it by dt dv with it (x = x^n + dt v):
 * a momentum taken back without changing the bodies' relative motion. */
static void add_uniform_velocity(world_body *s, const double dv[3], double dt) {
  for (int32_t i = 0; i < s->n; ++i)
    for (int k = 0; k < 3; ++k) {
      s->v[3 * i + k] += dv[k];
      s->x[3 * i + k] += dt * dv[k];
    }
}

/* Whether solid s met another solid inside its solve, or another solid met it, in this
 * step's try (solid_contacts.c); a hold released before convergence counts too, since a try
 * kept unconverged keeps what it did. */
static int in_solid_contact(const world_body *s) {
  return s->kind == PIOLA_BODY_SOLID && s->implicit && s->solid_contacts > 0;
}

/* Solids that met inside their solves each took the other as fixed where it was, so the
 * forces of their holds are not equal and opposite. Where nothing outside the bodies held
 * any of them, their momentum is made the start's plus dt M g, by one uniform velocity of
 * all of them, positions moved with it (x = x^n + dt v): their relative motion is
 * unchanged (as after the collision pass's solves, self_collide_and_resolve). */
static void keep_solid_contact_momentum(piola_world *w, double t1, double dt) {
  if (w->def.integrator != PIOLA_INTEGRATOR_BACKWARD_EULER) return;
  double excess[3] = {0, 0, 0}, mass = 0, g1[3];
  for (int k = 0; k < 3; ++k) g1[k] = piola_track_eval(&w->def.gravity[k], t1);
  int any = 0;
  for (int32_t b = 0; b < w->body_count; ++b) {
    const world_body *s = &w->bodies[b];
    if (!in_solid_contact(s)) continue;
    if (!held_by_bodies_only(s)) return;
    any = 1;
    for (int32_t i = 0; i < s->n; ++i) {
      mass += s->mass[i];
      for (int k = 0; k < 3; ++k)
        excess[k] += s->mass[i] * (s->v[3 * i + k] - s->v_old[3 * i + k] - dt * g1[k]);
    }
  }
  if (!any || !(mass > 0)) return;
  const double dv[3] = {-excess[0] / mass, -excess[1] / mass, -excess[2] / mass};
  for (int32_t b = 0; b < w->body_count; ++b)
    if (in_solid_contact(&w->bodies[b])) add_uniform_velocity(&w->bodies[b], dv, dt);
}

/* Adds body s's momentum times `sign` to p (kg m/s); returns its mass (kg). */
static double add_momentum(const world_body *s, double sign, double p[3]) {
  double mass = 0;
  for (int32_t i = 0; i < s->n; ++i) {
    mass += s->mass[i];
    for (int k = 0; k < 3; ++k) p[k] += sign * s->mass[i] * s->v[3 * i + k];
  }
  return mass;
}

static piola_status self_collide_and_resolve(piola_world *w, double dt, int closes,
                                             piola_step_stats *stats) {
  const double t1 = w->time + dt;
  const int per_step = !(w->def.collision_interval > 0);
  for (int32_t b = 0; b < w->body_count && per_step; ++b) {
    world_body *s = &w->bodies[b];
    if (s->implicit) memcpy(s->implicit->base, s->x, sizeof(double) * 3 * (size_t)s->n);
  }
  PIOLA_TRY(piola__world_self_collide(w, dt, t1, closes, stats));
  if (!per_step || stats->impacts + stats->contacts == 0) return PIOLA_OK;
  int resolved = 0;
  /* the solves below, each body's alone, hold the pushed nodes: the pass's impulses were
   * equal and opposite, the holds' forces are not (two balls meeting head-on came apart with
   * 8% of one ball's momentum left over). Where nothing outside the bodies held any of them,
   * the momentum those solves added in all is taken back (see below) */
  double added[3] = {0, 0, 0}, resolved_mass = 0;
  int bodies_only = 1;
  uint8_t *was_resolved = calloc((size_t)w->body_count, 1);
  if (!was_resolved) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "self-collision: out of memory");
  for (int32_t b = 0; b < w->body_count; ++b) {
    world_body *s = &w->bodies[b];
    if (!s->implicit) continue;
    const double *before = s->implicit->base;
    int32_t held = 0;
    for (int32_t i = 0; i < s->n; ++i) {
      if (s->flags[i] != NODE_FREE || s->inverse_mass[i] == 0) continue;
      double push[3], len2 = 0;
      for (int k = 0; k < 3; ++k) {
        push[k] = s->x[3 * i + k] - before[3 * i + k];
        len2 += push[k] * push[k];
      }
      if (!(len2 > 0)) continue;
      const double inv = 1.0 / sqrt(len2);
      s->colliding[i] = HELD_BY_COLLISION;
      for (int k = 0; k < 3; ++k) s->normals[3 * i + k] = push[k] * inv;
      held++;
    }
    if (held == 0) continue;
    bodies_only = bodies_only && held_by_bodies_only(s);
    (void)add_momentum(s, -1.0, added);
    newton_problem pb = problem_of(w, s, w->time, dt);
    pb.resolving = 1;
    piola__solid_contacts_solve_begins(w); /* the pass moved the other bodies */
    const int64_t colliding = stats->colliding;
    piola_status st = newton_iterate(&pb, 1, stats);
    if (st == PIOLA_ERROR_NOT_CONVERGED) /* a kept try that is not finite */
      st = PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE,
                      "%s '%s': the backward Euler step to t = %g s, solved again after the "
                      "collision pass, became non-finite",
                      piola__body_kind_name(s->kind), s->name, pb.t1);
    if (st != PIOLA_OK) {
      free(was_resolved);
      return st;
    }
    stats->colliding = colliding;
    bodies_only = bodies_only && held_by_bodies_only(s);
    resolved_mass += add_momentum(s, 1.0, added);
    was_resolved[b] = 1;
    resolved = 1;
  }
  /* Taken back as one uniform velocity of every body solved again, positions moved with it
   * (x = x^n + dt v): their relative motion, which keeps the surfaces apart, is unchanged. A
   * body held by an obstacle or a prescribed node takes its support through those holds
   * (examples/solids_stack.json: a ball on the ground under a landing torus), and there
   * nothing is taken back. Backward Euler only: a quasistatic body has no momentum. */
  const int dynamic = w->def.integrator == PIOLA_INTEGRATOR_BACKWARD_EULER;
  if (resolved && bodies_only && dynamic && resolved_mass > 0) {
    const double dv[3] = {-added[0] / resolved_mass, -added[1] / resolved_mass,
                          -added[2] / resolved_mass};
    for (int32_t b = 0; b < w->body_count; ++b) {
      if (!was_resolved[b]) continue;
      add_uniform_velocity(&w->bodies[b], dv, dt);
    }
  }
  free(was_resolved);
  if (!resolved) return PIOLA_OK;
  /* the step's contact counts are those of the first pass */
  const piola_step_stats first = *stats;
  PIOLA_TRY(piola__world_self_collide(w, dt, t1, closes, stats));
  stats->contacts = first.contacts, stats->impacts = first.impacts;
  stats->impact_zones = first.impact_zones, stats->collision_steps = first.collision_steps;
  stats->colliding = first.colliding;
  return PIOLA_OK;
}

/* Every free node still inside an obstacle when all bodies have stepped is put back on its
 * surface with the obstacle's normal velocity, as collisions do (piola_obstacles_collide),
 * and its body's forces are updated: the collision pass between bodies can push a node into
 * an obstacle (a layer of cloth pressed onto the ground by the layer landing on it), and
 * friction's move after the solve, along the tangent plane of the obstacle at the node, can
 * end inside a curved or cornered one (a gear's tooth). A Newmark step's next collision
 * processing puts such a node back; a frame-sized step must not end there
 * (docs/time-stepping.md, "The step's end: out of every obstacle"). */
static piola_status obstacles_at_step_end(piola_world *w, double t1, double dt) {
  for (int32_t b = 0; b < w->body_count && w->obstacle_count > 0; ++b) {
    world_body *s = &w->bodies[b];
    struct implicit_state *st = s->implicit;
    if (!st || s->n == 0) continue;
    memcpy(st->scratch_v, s->x, sizeof(double) * 3 * (size_t)s->n);
    memcpy(st->base, s->v, sizeof(double) * 3 * (size_t)s->n);
    int32_t moved = piola_obstacles_collide(w->obstacles, w->obstacle_count, t1, dt, s->n, s->x,
                                            s->v, st->hit, st->cg[0]);
    if (moved < 0) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "implicit step: out of memory");
    if (moved == 0) continue;
    for (int32_t i = 0; i < s->n; ++i)
      if (st->hit[i] && s->flags[i] != NODE_FREE) /* prescribed nodes stay where they are */
        for (int k = 0; k < 3; ++k)
          s->x[3 * i + k] = st->scratch_v[3 * i + k], s->v[3 * i + k] = st->base[3 * i + k];
    PIOLA_TRY(piola__body_update_forces(s, t1));
  }
  return PIOLA_OK;
}

piola_status piola__implicit_world_step(piola_world *w, double dt_limit, piola_step_stats *stats) {
  piola_step_stats local = {0};
  double dt = w->def.implicit_dt;
  /* a limit a rounding error above the step is the caller's target: land on it */
  if (dt_limit > 0 && dt_limit <= dt * (1 + 1e-9)) dt = dt_limit;
  if (!(dt > 0)) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "step: dt must be > 0, got %g", dt);
  piola__step_profile_start(&w->profile);
  /* a solid started past its yield point (initial.matrix, initial.scramble) flows before the
   * first step, from its state at t = 0, as after a Newmark run's first short step: a
   * frame-sized first step relaxed the stretch before the update after it saw any (a bar
   * started 30% stretched past a 5% yield kept a 2% set instead of 24%) */
  if (w->time == 0)
    for (int32_t i = 0; i < w->body_count; ++i) piola__body_plastic_after_step(&w->bodies[i], 0.0);
  double left;
  PIOLA_TRY(piola__world_collision_open(w, &left));
  /* the last try is never shorter than the user's step halved MAX_HALVINGS times (or what
   * is left of the target, when that is less): halving what is left of a frame each time
   * instead made a frame whose steps all fail take steps shrinking geometrically, and it
   * never ended once they fell below the rounding of the time */
  const double shortest = fmin(dt, last_try_length(w));
  for (int halvings = 0;; ++halvings) {
    if (halvings == MAX_HALVINGS) {
      dt = fmax(dt, shortest);
      /* and a remainder a rounding error long is not left for a step of its own */
      if (dt_limit > 0 && dt_limit > dt && dt_limit <= dt * (1 + 1e-9)) dt = dt_limit;
    }
    piola_status st = PIOLA_OK;
    int32_t done = 0;
    for (int32_t b = 0; b < w->body_count; ++b) w->bodies[b].solid_contacts = 0;
    for (; done < w->body_count && st == PIOLA_OK; ++done)
      st = newton_body(w, &w->bodies[done], w->time, dt, halvings, &local);
    if (st == PIOLA_OK) {
      if (halvings > MAX_HALVINGS && w->deeper_steps_left > 0) w->deeper_steps_left--;
      break;
    }
    for (int32_t j = 0; j < done; ++j) piola__body_restore_step(&w->bodies[j], w->time);
    if (st != PIOLA_ERROR_NOT_CONVERGED) {
      if (stats) *stats = local;
      return st;
    }
    /* a try halved on instead of keeping its start (only the body that failed, the last
     * one solved, can be one) was counted where it was kept */
    const struct implicit_state *failed = w->bodies[done - 1].implicit;
    const int went_deeper = failed && failed->went_deeper;
    if (!went_deeper) local.newton_failures++;
    if (halvings >= MAX_HALVINGS && !went_deeper) {
      /* the last try keeps any finite iterate, so its failure is a non-finite residual:
       * halving on would loop for ever (a scene scrambled by 1e300 m did) */
      if (stats) *stats = local;
      const world_body *s = &w->bodies[done - 1];
      return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE,
                        "%s '%s': the implicit step's residual became non-finite at t = %g s "
                        "(after %d halvings of the step, to %g s)",
                        piola__body_kind_name(s->kind), s->name, w->time + dt, halvings, dt);
    }
    dt *= 0.5;
  }
  keep_solid_contact_momentum(w, w->time + dt, dt);
  const int closes = dt >= left || dt == w->collision_deadline - w->time;
  piola_status contact = self_collide_and_resolve(w, dt, closes, &local);
  if (contact != PIOLA_OK) {
    for (int32_t j = 0; j < w->body_count; ++j) piola__body_restore_step(&w->bodies[j], w->time);
    if (stats) *stats = local;
    return contact;
  }
  PIOLA_TRY(obstacles_at_step_end(w, w->time + dt, dt));
  /* shells' plastic flow, from the update at the step's end (solids': in finish_step) */
  for (int32_t i = 0; i < w->body_count; ++i) piola__body_plastic_in_step(&w->bodies[i], dt);
  return piola__world_finish_step(w, dt, &local, stats);
}
