/* The step loop: the Newmark scheme of paper section 9 (see docs/time-stepping.md).
 *
 * From (x^n, v^n), with the elastic force f^n = f_e(x^n) and the rotations of x^n already
 * held by the body:
 *  1. (M - dt/2 D_n) v~ = M v^n + dt/2 (f^n + f_ext(t^n))            damping implicit (CG)
 *  2. x~ = x^n + dt v~
 *  3. collisions with x~ and v^n give x^n+1 and v'; colliding nodes are flagged
 *  4. (M - dt/2 D_n+1) v^n+1 = M v' + dt/2 (f^n + D_n v' + f_ext(t^n))
 *                                   + dt/2 (f^n+1 + f_ext(t^n+1))   with normal velocity of
 *     colliding nodes held at v' (filtered CG)
 * F, its diagonalization and f^n+1 are computed once, between steps 3 and 4, and reused by
 * the next step's step 1. Constrained nodes follow their prescribed positions exactly:
 * their v~ is the secant velocity to the prescribed position and v^n+1 the prescribed
 * velocity. Once every solid has stepped, plastic solids run their return mapping from the
 * diagonalization at x^n+1 (world_plasticity.c); the new Fp acts from the next force
 * evaluation. */
#include <math.h>
#include <string.h>

#include "common/status_report.h"
#include "force/elastic_body_internal.h"
#include "force/stable_step.h"
#include "math/mat3.h"
#include "sim/conjugate_gradient.h"
#include "sim/obstacle_friction.h"
#include "sim/world_internal.h"

int piola__step_reuse_first_product = 1;
int piola__step_energy_check = 1;

typedef struct damping_system {
  const world_body *s;
  double h;              /* dt / 2 */
  double beta, alpha;    /* shear and bulk viscosity, Pa s */
  int hold_normals;      /* filter the normal components of colliding nodes too */
  double *scratch;       /* 3n */
  step_profile *profile; /* the world's timers (the applies are counted apart) */
} damping_system;

static void damping_apply(void *ctx, const double *p, double *out) {
  const damping_system *d = ctx;
  piola__step_profile_apply(d->profile, 1);
  piola__body_damping_apply(d->s, p, d->beta, d->alpha, d->h, d->scratch, out);
  piola__step_profile_apply(d->profile, 0);
}

static void damping_filter(void *ctx, double *r, int32_t begin, int32_t end) {
  const damping_system *d = ctx;
  const world_body *s = d->s;
  for (int32_t i = begin; i < end; ++i) {
    double *ri = r + 3 * i;
    if (s->flags[i] != NODE_FREE) {
      ri[0] = ri[1] = ri[2] = 0;
    } else if (d->hold_normals && s->colliding[i]) {
      const double *nrm = s->normals + 3 * i;
      double dn = ri[0] * nrm[0] + ri[1] * nrm[1] + ri[2] * nrm[2];
      for (int k = 0; k < 3; ++k) ri[k] -= dn * nrm[k];
    }
  }
}

/* Solves (M - h D) v = rhs, keeping the filtered components of the guess in v. av (3n, may
 * be NULL) receives (M - h D) v at the solution, to rounding.
 *
 * The guess v is first moved by the uniform velocity change `uniform` (h g per gravity term
 * of rhs) on free nodes, tangentially on held ones: D is zero on uniform fields, so this is
 * exactly the part of the answer that gravity contributes, and the residual CG starts from
 * has no net force. CG's updates keep it so (1^T A p = 1^T M p = 1^T r for its directions),
 * so a free body's linear momentum comes out exact whatever the tolerance, instead of being
 * off by the net force left in the final residual. */
static int32_t damping_solve(piola_world *w, world_body *s, double h, double t,
                             int hold_normals, const double *rhs, double *v, const double uniform[3],
                             double *av, double *guess_copy, double *initial_av, int from_product) {
  double beta = piola_track_eval(&s->shear_viscosity, t);
  double alpha = piola_track_eval(&s->bulk_viscosity, t);
  damping_system d = {s, h, beta, alpha, hold_normals, s->tmp, &w->profile};
  if (piola__body_undamped(s, beta, alpha)) {
    /* M is diagonal: the filtered solve is exact in one pass */
    for (int32_t i = 0; i < s->n; ++i) {
      if (s->flags[i] != NODE_FREE) continue;
      double *vi = v + 3 * i;
      double old[3] = {vi[0], vi[1], vi[2]};
      for (int k = 0; k < 3; ++k) vi[k] = rhs[3 * i + k] / s->mass[i];
      if (hold_normals && s->colliding[i]) {
        const double *nrm = s->normals + 3 * i;
        double dn = (vi[0] - old[0]) * nrm[0] + (vi[1] - old[1]) * nrm[1] + (vi[2] - old[2]) * nrm[2];
        for (int k = 0; k < 3; ++k) vi[k] -= dn * nrm[k];
      }
    }
    if (av)
      for (int32_t i = 0; i < s->n; ++i)
        for (int k = 0; k < 3; ++k) av[3 * i + k] = s->mass[i] * v[3 * i + k];
    return 0;
  }
  if (from_product) {
    /* A x0 from the last final solve (first solve only, so no held normals): x0 = v + u on
     * free nodes (u = uniform) and D ignores uniform fields, so D x0 = D v_p + D e with
     * e = v - v_p, less u on constrained nodes (which get no shift). e is zero but where
     * collisions, friction, contact or constraints changed the velocity since, and
     * h_p D v_p = M v_p - A_p v_p. One pass forms e, the shifted guess and all of A x0 but
     * h D e, which a sparse pass over the changed nodes' edges adds. */
    const double ratio = h / s->product_h;
    double *e = s->work;
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) \
    if (s->n >= PIOLA_PARALLEL_MIN_VERTICES)
    for (int32_t i = 0; i < s->n; ++i) {
      const int free_node = s->flags[i] == NODE_FREE;
      for (int k = 0; k < 3; ++k) {
        const int64_t j = 3 * (int64_t)i + k;
        e[j] = v[j] - s->v_product[j] - (free_node ? 0.0 : uniform[k]);
        if (free_node) v[j] += uniform[k];
        if (guess_copy) guess_copy[j] = v[j];
        initial_av[j] =
            s->mass[i] * v[j] - ratio * (s->mass[i] * s->v_product[j] - s->av_product[j]);
      }
    }
    piola__body_damping_add_sparse(s, e, beta, alpha, -h, initial_av);
  } else {
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) \
    if (s->n >= PIOLA_PARALLEL_MIN_VERTICES)
    for (int32_t i = 0; i < s->n; ++i) {
      if (s->flags[i] != NODE_FREE) continue;
      double du[3] = {uniform[0], uniform[1], uniform[2]};
      if (hold_normals && s->colliding[i]) {
        const double *nrm = s->normals + 3 * i;
        double dn = du[0] * nrm[0] + du[1] * nrm[1] + du[2] * nrm[2];
        for (int k = 0; k < 3; ++k) du[k] -= dn * nrm[k];
      }
      for (int k = 0; k < 3; ++k) v[3 * i + k] += du[k];
    }
    if (guess_copy) memcpy(guess_copy, v, 3 * (size_t)s->n * sizeof(double));
  }
  cg_problem pb;
  pb.n = s->n;
  pb.apply = damping_apply;
  pb.filter = damping_filter;
  pb.ctx = &d;
  pb.inverse_mass = s->inverse_mass;
  pb.tolerance = w->def.cg_tolerance;
  pb.max_iterations = w->def.cg_max_iterations;
  pb.initial_ax = initial_av;
  pb.given_ax = from_product ? initial_av : NULL;
  const int32_t iterations = piola__cg_solve(&pb, rhs, v, s->work, av);
  if (iterations >= pb.max_iterations)
    piola__world_warn(w, PIOLA_WARNING_CG_MAX_ITERATIONS,
                      "%s '%s': a damping solve stopped at cg_max_iterations = %d at t = %g s "
                      "before reaching cg_tolerance = %g: raise integrator.cg_max_iterations or "
                      "lower max_dt (docs/time-stepping.md)",
                      s->shell ? "shell" : "solid", s->name, (int)pb.max_iterations, t,
                      pb.tolerance);
  return iterations;
}

/* Friction of the first half of the step's contact impulse (step 3), on the step's motion.
 *
 * The paper limits the tangential velocity v^n that step 4 starts from, with the impulse
 * dvN + dxN/dt, while the position x^n+1 keeps the tangential motion of v~, half a step of
 * the node's whole acceleration. On a block resting on an incline that acceleration is the
 * share of the block's weight its neighbours push down the slope onto the node, and the block
 * crept down a slope whose friction should hold it (0.1 m cube, mu = 0.8 on 28.6 degrees,
 * 2 cm/s); in steady contact the friction spent on v^n (which the last step's second half
 * already stopped) is lost. So the obstacles project with dvN alone (dt 0 there), and here
 * the projection's part, dxN/dt, limits the step's average velocity u = (x^n+1 - x^n) / dt
 * relative to the obstacle, uT <- max(0, 1 - mu (dxN/dt) / |uT|) uT: the node moves by dt u,
 * and v' takes the same change. A node held still by friction then stays where it is, and a
 * sliding one gets the same velocity as before with a position that agrees with it. The move
 * is tangential, so on a curved obstacle it can end a rounding of the curvature inside; it is
 * projected out again (positions only). */
static void friction_on_step_motion(const piola_world *w, world_body *s, double t1, double dt,
                                    const double *x_tilde) {
  for (int32_t i = 0; i < s->n; ++i) {
    if (!s->colliding[i] || s->flags[i] != NODE_FREE || !(s->mass[i] > 0)) continue;
    const double *nrm = s->normals + 3 * i;
    double *xi = s->x + 3 * i, *vi = s->v + 3 * i;
    const double *xo = s->x_old + 3 * i, *xt = x_tilde + 3 * i;
    const double dxn =
        (xi[0] - xt[0]) * nrm[0] + (xi[1] - xt[1]) * nrm[1] + (xi[2] - xt[2]) * nrm[2];
    s->friction_spent[i] = dxn > 0 ? dxn / dt : 0.0;
    if (!(dxn > 0)) continue;
    piola_vec3 p = {xi[0], xi[1], xi[2]}, vo;
    double mu;
    piola__nearest_obstacle_motion(w->obstacles, w->obstacle_count, t1, p, &mu, &vo);
    const double u0[3] = {(xi[0] - xo[0]) / dt, (xi[1] - xo[1]) / dt, (xi[2] - xo[2]) / dt};
    double u[3] = {u0[0], u0[1], u0[2]};
    if (!piola__coulomb_limit(u, vo, nrm, mu, dxn / dt)) continue;
    for (int k = 0; k < 3; ++k) {
      xi[k] = xo[k] + dt * u[k];
      vi[k] += u[k] - u0[k];
    }
    for (int32_t o = 0; o < w->obstacle_count; ++o) {
      piola_vec3 q = {xi[0], xi[1], xi[2]}, normal;
      const double phi = piola_obstacle_signed_distance(w->obstacles[o], t1, q, &normal, NULL);
      if (phi < 0) xi[0] -= phi * normal.x, xi[1] -= phi * normal.y, xi[2] -= phi * normal.z;
    }
  }
}

/* Friction for the rest of the step's contact impulse.
 *
 * Collision processing (step 3) applies friction with the normal velocity change it causes,
 * dvN + dxN/dt; in resting contact that is the half-step of normal acceleration that
 * carried the node into the obstacle through v~. The final solve then holds the normal
 * velocity, which removes the normal impulse of both halves, dt/2 (a^n + a^n+1) . n; without
 * friction for the second a block on an incline would feel half its Coulomb friction. Here
 * that impulse, dt/2 (f^n+1 + f_ext + D v^n+1) . n / m when it presses into the obstacle,
 * limits the relative tangential velocity the same way: vT <- max(0, 1 - mu dvN / |vT|) vT.
 *
 * The first half's impulse as the solve held it, dt/2 (f^n + f_ext + D v') . n / m, is not
 * the dxN/dt step 3 spent: v~ carried the node in with its damping solved implicitly, which
 * pulls a pressed node back towards the nodes above it, so dxN/dt fell short by about h c / m
 * (c the node's damping coefficient) and a damped block on an incline slid as if mu were
 * 3.5% smaller (docs/time-stepping.md, "Friction of the held normal impulse"). On an
 * obstacle contact of step 3 (friction_spent known) the difference joins this half's
 * impulse, so the velocity gets the friction of the whole held impulse.
 *
 * A shell node the coupling to solids held (HELD_BY_SOLID) takes the shell's
 * solid_friction against the solid surface's velocity it touched: with the nearest
 * obstacle's instead (zero friction where there was none), cloth on a tilted solid slid at
 * g (sin - mu/2 cos), half its Coulomb friction. */
static void contact_friction(const piola_world *w, world_body *s, double t1, double h,
                             const double *g1, const double *av) {
  for (int32_t i = 0; i < s->n; ++i) {
    if (!s->colliding[i] || s->flags[i] != NODE_FREE) continue;
    const double *nrm = s->normals + 3 * i;
    double *vi = s->v + 3 * i;
    /* normal impulse per unit mass of the n+1 half: h (f + m g).n + (h D v).n, where
     * h D v = M v - A v; and of the first half, from the right-hand side M v' + h (f^n +
     * D v' + m g0) + h (f + m g1), whose normal part of M v' the hold kept in v */
    double push = 0, first = 0;
    for (int k = 0; k < 3; ++k) {
      const double second = h * (s->force[3 * i + k] + s->mass[i] * g1[k]);
      push += nrm[k] * (second + s->mass[i] * vi[k] - av[3 * i + k]);
      first += nrm[k] * (s->rhs[3 * i + k] - s->mass[i] * vi[k] - second);
    }
    double dvn = fmax(-push / s->mass[i], 0.0);
    if (isfinite(s->friction_spent[i]))
      dvn += fmax(-first / s->mass[i], 0.0) - s->friction_spent[i];
    if (!(dvn > 0)) continue;
    piola_vec3 vo;
    double mu;
    if (s->colliding[i] == HELD_BY_SOLID && s->solid_surface_v) {
      const double *sv = s->solid_surface_v + 3 * i;
      mu = s->solid_friction, vo = (piola_vec3){sv[0], sv[1], sv[2]};
    } else { /* the obstacle the node touches: the one nearest to it */
      piola_vec3 p = {s->x[3 * i], s->x[3 * i + 1], s->x[3 * i + 2]};
      piola__nearest_obstacle_motion(w->obstacles, w->obstacle_count, t1, p, &mu, &vo);
    }
    (void)piola__coulomb_limit(vi, vo, nrm, mu, dvn);
  }
}

static double stiffness_bound(const world_body *s, double t0, double t1) {
  /* the largest stiffness scale over [t0, t1]: the tracks are piecewise linear, so the
   * maximum is at an end or at a key inside */
  double m = fmax(piola_track_eval(&s->stiffness_scale, t0), piola_track_eval(&s->stiffness_scale, t1));
  for (int32_t k = 0; k < s->stiffness_scale.key_count; ++k)
    if (s->stiffness_scale.times[k] > t0 && s->stiffness_scale.times[k] < t1)
      m = fmax(m, s->stiffness_scale.values[k]);
  return m;
}

/* min(max_dt, every body's CFL bound) at the current state (collective in a split run). */
static double current_bound(const piola_world *w) {
  double dt = w->def.max_dt;
  for (int32_t i = 0; i < w->body_count; ++i) {
    const world_body *b = &w->bodies[i];
    dt = fmin(dt, piola__body_stable_dt(w, b, stiffness_bound(b, w->time, w->time + w->def.max_dt)));
  }
  return dt;
}

/* The smallest of the recent steps' bounds (INFINITY before the first step). */
static double recent_bound_min(const piola_world *w) {
  double dt = INFINITY;
  for (int32_t i = 0; i < w->recent_bound_count; ++i) dt = fmin(dt, w->recent_bounds[i]);
  return dt;
}

static void remember_bound(piola_world *w, double bound) {
  w->recent_bounds[w->recent_bound_next] = bound;
  w->recent_bound_next = (w->recent_bound_next + 1) % STEP_BOUND_WINDOW;
  if (w->recent_bound_count < STEP_BOUND_WINDOW) w->recent_bound_count++;
}

/* The explicit step follows the stiffest of the recent states, not the current one alone:
 * where the stiffest tets oscillate between soft and stiff states (a strongly stretched
 * body), a step sized from the soft state alone carries them into the stiff one at several
 * times its bound, and a step size that rises and falls with their oscillation pumps energy
 * into it (docs/time-stepping.md, "The recent bounds"). */
double piola_world_stable_dt(const piola_world *w) {
  if (!w) return NAN;
  if (w->def.integrator != PIOLA_INTEGRATOR_NEWMARK) return w->def.implicit_dt;
  return fmin(current_bound(w), recent_bound_min(w));
}

static void gravity_at(const piola_world *w, double t, double g[3]) {
  for (int k = 0; k < 3; ++k) g[k] = piola_track_eval(&w->def.gravity[k], t);
}

static piola_status step_body(piola_world *w, world_body *s, double t, double dt,
                               piola_step_stats *stats, int *energy_rose) {
  const int32_t n = s->n > 0 ? s->n : 0;
  const int64_t m = 3 * (int64_t)n;
  const double h = 0.5 * dt, t1 = t + dt;
  size_t v3 = (size_t)m * sizeof(double);
  double g0[3], g1[3];
  gravity_at(w, t, g0);
  gravity_at(w, t1, g1);
  /* 1. v~ (with the copies of the old state, in the same pass) */
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) \
    if (n >= PIOLA_PARALLEL_MIN_VERTICES)
  for (int32_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      const int64_t j = 3 * (int64_t)i + k;
      s->x_old[j] = s->x[j];
      s->v_old[j] = s->v[j];
      s->force_old[j] = s->force[j];
      s->rhs[j] = s->mass[i] * s->v[j] + h * (s->force[j] + s->mass[i] * g0[k]);
    }
  if (n > 0) memset(s->colliding, 0, (size_t)n);
  for (int32_t i = 0; i < n; ++i) {
    if (s->flags[i] == NODE_FREE) continue;
    double xp[3], vp[3];
    piola__body_constrained_state(s, i, t1, xp, vp);
    for (int k = 0; k < 3; ++k) s->v[3 * i + k] = (xp[k] - s->x[3 * i + k]) / dt;
  }
  piola__step_profile_mark(&w->profile, STEP_PHASE_SETUP);
  double beta0 = piola_track_eval(&s->shear_viscosity, t);
  double alpha0 = piola_track_eval(&s->bulk_viscosity, t);
  const int damped = !piola__body_undamped(s, beta0, alpha0);
  const int reusable = piola__body_damping_reusable(s);
  if (reusable && damped) piola__body_damping_prepare(s, beta0, alpha0);
  piola__step_profile_mark(&w->profile, STEP_PHASE_PREPARE);
  const double gravity1[3] = {h * g0[0], h * g0[1], h * g0[2]};
  /* for a damped body, keep the guess x0 (in tmp) and A x0 (in the fourth work vector, which
   * CG does not use): the second right-hand side's D_n v' is h D_n x0 = M x0 - A x0 plus a
   * correction on the few nodes where v' differs from the guess (see there) */
  double *initial_av = s->work + 3 * m;
  const int reuse = damped && reusable && piola__step_reuse_first_product;
  /* the last final solve ran with the same operator (same assembly) unless the body or the
   * viscosities changed since: start from its product instead of a fresh apply */
  const int from_product =
      reuse && s->product_valid && s->product_generation == piola__body_damping_generation(s);
  stats->cg_iterations += damping_solve(w, s, h, t, 0, s->rhs, s->v, gravity1, NULL,
                                        reuse ? s->tmp : NULL, reuse ? initial_av : NULL, from_product);
  s->product_valid = 0;
  piola__step_profile_mark(&w->profile, STEP_PHASE_SOLVE1);

  /* 2. x~, and v back to v^n for 3. */
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) \
    if (n >= PIOLA_PARALLEL_MIN_VERTICES)
  for (int32_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      const int64_t j = 3 * (int64_t)i + k;
      s->x[j] += dt * s->v[j];
      s->v[j] = s->v_old[j];
    }

  /* 3. collisions with x~ and v^n */
  int32_t colliding = 0;
  for (int32_t i = 0; i < n; ++i) s->friction_spent[i] = NAN;
  if (w->obstacle_count > 0) {
    double *x_tilde = s->rhs; /* free until step 4's right-hand side is formed */
    memcpy(x_tilde, s->x, v3);
    colliding = piola_obstacles_collide(w->obstacles, w->obstacle_count, t1, 0.0, n, s->x, s->v,
                                        s->colliding, s->normals);
    if (colliding > 0) friction_on_step_motion(w, s, t1, dt, x_tilde);
  }
  colliding += piola__body_collide_in_step(w, s, t1, dt, HELD_BY_SOLID, s->solid_surface_v);
  for (int32_t i = 0; i < n; ++i) {
    if (s->flags[i] == NODE_FREE) continue;
    if (s->colliding[i]) colliding--;
    s->colliding[i] = 0;
    piola__body_constrained_state(s, i, t1, s->x + 3 * i, s->v + 3 * i);
  }
  stats->colliding += colliding;
  piola__step_profile_mark(&w->profile, STEP_PHASE_COLLIDE);
  /* damping at (x^n, v') while the body still holds the rotations of x^n */
  if (reuse) {
    /* h D_n v' without a full pass: v' = x0 - h g0 - e, where the uniform h g0 is invisible
     * to D and e is zero except on nodes the collisions or constraints moved (v' != v^n) or
     * that are constrained (x0 was their secant velocity). So h D_n v' = (M x0 - A x0) -
     * h D_n e, with D_n e evaluated only on the tets touching those nodes. M x0 - A x0 holds
     * h D_n x0 to the rounding of M x0, the size of the rounding of M v' in the sum. */
    double *hd = initial_av;
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) \
    if (n >= PIOLA_PARALLEL_MIN_VERTICES)
    for (int32_t i = 0; i < n; ++i) {
      double *x0 = s->tmp + 3 * i;
      const double *vi = s->v + 3 * i, *vo = s->v_old + 3 * i;
      int moved = s->flags[i] != NODE_FREE || vi[0] != vo[0] || vi[1] != vo[1] || vi[2] != vo[2];
      for (int k = 0; k < 3; ++k) {
        hd[3 * i + k] = s->mass[i] * x0[k] - hd[3 * i + k];
        x0[k] = moved ? x0[k] - vi[k] - gravity1[k] : 0.0;
      }
    }
    piola__body_damping_add_sparse(s, s->tmp, beta0, alpha0, -h, hd);
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) \
    if (n >= PIOLA_PARALLEL_MIN_VERTICES)
    for (int32_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k)
        s->rhs[3 * i + k] = s->mass[i] * s->v[3 * i + k] + hd[3 * i + k] +
                            h * (s->force_old[3 * i + k] + s->mass[i] * g0[k]);
  } else {
    if (damped)
      piola__body_damping_forces(s, s->v, beta0, alpha0, s->tmp);
    else
      memset(s->tmp, 0, v3);
    for (int32_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k)
        s->rhs[3 * i + k] = s->mass[i] * s->v[3 * i + k] +
                            h * (s->force_old[3 * i + k] + s->tmp[3 * i + k] + s->mass[i] * g0[k]);
  }

  piola__step_profile_mark(&w->profile, STEP_PHASE_RHS2);
  /* F, diagonalization and elastic force at x^n+1, once per step */
  piola_status st = piola__body_update_forces(s, t1);
  if (st != PIOLA_OK) {
    piola__body_restore_step(s, t);
    return st;
  }
  piola__body_plastic_in_step(s, dt);
  piola__step_profile_mark(&w->profile, STEP_PHASE_UPDATE);
  int damped1 = 0;
  if (reusable) {
    double beta1 = piola_track_eval(&s->shear_viscosity, t1);
    double alpha1 = piola_track_eval(&s->bulk_viscosity, t1);
    damped1 = !piola__body_undamped(s, beta1, alpha1);
    if (damped1) piola__body_damping_prepare(s, beta1, alpha1);
  }
  piola__step_profile_mark(&w->profile, STEP_PHASE_PREPARE);

  /* 4. trapezoidal velocity, damping at n+1 implicit, normal velocity of contacts held */
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) \
    if (n >= PIOLA_PARALLEL_MIN_VERTICES)
  for (int32_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k)
      s->rhs[3 * i + k] += h * (s->force[3 * i + k] + s->mass[i] * g1[k]);
  /* the solve also gives A v^n+1, which the friction of the held normal impulse needs and
   * the next step's first solve starts from */
  double *av = s->av_product;
  const int keep_product = damped1 && piola__step_reuse_first_product;
  const double gravity2[3] = {h * (g0[0] + g1[0]), h * (g0[1] + g1[1]), h * (g0[2] + g1[2])};
  stats->cg_iterations += damping_solve(w, s, h, t1, 1, s->rhs, s->v, gravity2,
                                        colliding > 0 || keep_product ? av : NULL, NULL, NULL, 0);
  if (keep_product) {
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) \
    if (n >= PIOLA_PARALLEL_MIN_VERTICES)
    for (int64_t j = 0; j < m; ++j) s->v_product[j] = s->v[j];
    s->product_h = h;
    s->product_generation = piola__body_damping_generation(s);
    s->product_valid = 1;
  }
  piola__step_profile_mark(&w->profile, STEP_PHASE_SOLVE2);
  if (colliding > 0) contact_friction(w, s, t1, h, g1, av);
  piola__step_profile_mark(&w->profile, STEP_PHASE_FRICTION);
  /* a state whose energies overflow has blown up even if each coordinate is still finite.
   * The elastic energy is not computed per step (world.c); the squared norm of the elastic
   * force overflows with it (both grow as |F|^2), and costs one pass over 3n numbers.
   * The same pass sums the step's energy balance over the free nodes that did not collide
   * (docs/time-stepping.md, "Energy check"): the kinetic energy gained minus the work of the
   * elastic force and gravity by the trapezoidal rule, and the terms of what a stable step
   * allows. Summed by fixed node ranges, so the sums do not depend on the thread count. */
  enum { CHECK_RANGES = 16 };
  double kinetic_part[CHECK_RANGES], force2_part[CHECK_RANGES], gain_part[CHECK_RANGES];
  double fm_part[CHECK_RANGES], mdx_part[CHECK_RANGES], mv_part[CHECK_RANGES], mdv_part[CHECK_RANGES];
  double mass_part[CHECK_RANGES];
  int64_t bad_part[CHECK_RANGES];
  int driven_part[CHECK_RANGES];
  const double gmid[3] = {0.5 * (g0[0] + g1[0]), 0.5 * (g0[1] + g1[1]), 0.5 * (g0[2] + g1[2])};
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) \
    if (n >= PIOLA_PARALLEL_MIN_VERTICES)
  for (int r = 0; r < CHECK_RANGES; ++r) {
    double ke = 0, f2 = 0, gain = 0, fm = 0, mdx = 0, mv = 0, mdv = 0, mass = 0;
    int64_t bad = -1;
    int driven = 0;
    for (int32_t i = (int32_t)((int64_t)n * r / CHECK_RANGES); i < (int32_t)((int64_t)n * (r + 1) / CHECK_RANGES); ++i) {
      const double mi = s->mass[i];
      mass += mi;
      driven |= s->flags[i] == NODE_DRIVEN;
      const int balanced = s->flags[i] == NODE_FREE && !s->colliding[i] && mi > 0;
      for (int k = 0; k < 3; ++k) {
        const int64_t j = 3 * (int64_t)i + k;
        if (bad < 0 && !isfinite(s->v[j])) bad = j;
        ke += mi * s->v[j] * s->v[j];
        f2 += s->force[j] * s->force[j];
        if (!balanced) continue;
        const double fbar = 0.5 * (s->force_old[j] + s->force[j]) + mi * gmid[k];
        const double dx = s->x[j] - s->x_old[j], dv = s->v[j] - s->v_old[j];
        const double vbar = 0.5 * (s->v[j] + s->v_old[j]);
        gain += mi * vbar * dv - fbar * dx;
        fm += fbar * fbar / mi;
        mdx += mi * dx * dx;
        mv += mi * vbar * vbar;
        mdv += mi * dv * dv;
      }
    }
    kinetic_part[r] = ke, force2_part[r] = f2, bad_part[r] = bad, driven_part[r] = driven;
    gain_part[r] = gain, fm_part[r] = fm, mdx_part[r] = mdx, mv_part[r] = mv, mdv_part[r] = mdv;
    mass_part[r] = mass;
  }
  double kinetic = 0, force2 = 0, gain = 0, fm = 0, mdx = 0, mv = 0, mdv = 0, total_mass = 0;
  int driven = 0;
  for (int r = 0; r < CHECK_RANGES; ++r) {
    driven |= driven_part[r];
    gain += gain_part[r], fm += fm_part[r], mdx += mdx_part[r], mv += mv_part[r], mdv += mdv_part[r];
    total_mass += mass_part[r];
    if (bad_part[r] >= 0) {
      piola__body_restore_step(s, t);
      return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE,
                        "%s '%s': velocity of vertex %lld became non-finite at t = %g s",
                        piola__body_kind_name(s->kind), s->name,
                        (long long)(bad_part[r] / 3), t1);
    }
    kinetic += kinetic_part[r];
    force2 += force2_part[r];
  }
  if (!isfinite(kinetic) || !isfinite(force2)) {
    piola__body_restore_step(s, t);
    return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE,
                      "%s '%s': the %s became non-finite at t = %g s (the state blew up)",
                      piola__body_kind_name(s->kind), s->name, isfinite(kinetic) ? "elastic force's squared norm" : "kinetic energy", t1);
  }
  /* for a stable step of a linear system the gain is at most |fbar|_M^-1 |dx|_M (equal
   * only at the stability limit); the damping solves' tolerance adds up to 2 tol
   * |vbar|_M |dv|_M (their velocity error is at most tol |dv|_M in the M norm). Not checked
   * with driven nodes or in a step where a node collided: the damping couples the free
   * nodes to those nodes' imposed motion, work the balance does not see. Gains below the
   * energy of a uniform strain of 1e-9 at the rest modulus, (lambda + 2 mu) V 1e-18 / 2 =
   * M c^2 1e-18 / 2, are rounding (a body at rest has forces of ~1e-16 of its stresses).
   * Shells the same way, with the membrane's wave speed: their membrane and bending forces are
   * in s->force and derive from energies, and their damping is in the solves. */
  *energy_rose = 0;
  if (!driven && colliding == 0) {
    const double tol = w->def.cg_tolerance, c = piola__body_max_wave_speed(s);
    const double floor = 0.5e-18 * total_mass * c * c;
    const double allowed = (1 + tol) * sqrt(fm * mdx) + 2 * tol * sqrt(mv * mdv);
    *energy_rose = gain > allowed * (1 + 1e-9) + floor;
  }
  piola__step_profile_mark(&w->profile, STEP_PHASE_CHECK);
  return PIOLA_OK;
}

/* Raises PIOLA_WARNING_SMALL_STEP when a solid's state-aware step (of the last
 * piola_world_stable_dt) is below a tenth of its rest CFL step, naming the tet that sets it. */
static void note_small_step(piola_world *w) {
  if (w->warnings[PIOLA_WARNING_SMALL_STEP]) return;
  for (int32_t i = 0; i < w->body_count; ++i) {
    const world_body *s = &w->bodies[i];
    if (s->kind != PIOLA_BODY_SOLID) continue;
    if (!s->state_rate_valid || !(s->state_rate2 > 0) || s->state_worst_tet < 0) continue;
    const double speed = piola_elastic_body_max_wave_speed(s->solid);
    const double h = piola_elastic_body_min_rest_altitude(s->solid);
    const double rest = w->def.cfl * h / speed, state = w->def.cfl / sqrt(s->state_rate2);
    if (!(speed > 0 && h > 0) || !(state < 0.1 * rest)) continue;
    const double *f = piola_elastic_body_fhat(s->solid) + 3 * s->state_worst_tet;
    piola__world_warn(w, PIOLA_WARNING_SMALL_STEP,
                      "solid '%s': at t = %g s the stable step is %.3g s, %.0f times below the "
                      "CFL estimate of the rest state (%.3g s): tet %d is deformed to Fhat = "
                      "(%.3g, %.3g, %.3g), where the material is that much stiffer "
                      "(docs/time-stepping.md, \"Step size\"); at this step a simulated "
                      "second takes %.3g steps: \"integrator\": {\"type\": "
                      "\"backward_euler\"} steps through such states at integrator.dt",
                      s->name, w->time, state, rest / state, rest, (int)s->state_worst_tet, f[0],
                      f[1], f[2], 1.0 / state);
    return;
  }
}

static void restore_all(piola_world *w, int32_t count) {
  for (int32_t j = 0; j < count; ++j) piola__body_restore_step(&w->bodies[j], w->time);
}

/* One try at a step of dt from the current state; on failure every body is back at the
 * state before it. With check_energy, a body whose energy check fails (step_body) undoes
 * the try as well and sets *energy_rose. */
static piola_status try_step(piola_world *w, double dt, piola_step_stats *local, int check_energy,
                             int *energy_rose) {
  *energy_rose = 0;
  /* a collision interval (world_contact.c) ends with the first step that reaches its end
   * (steps are not shortened for it), or on advance_to's target */
  double left;
  PIOLA_TRY(piola__world_collision_open(w, &left));
  const int closes = dt >= left || dt == w->collision_deadline - w->time;
  piola__step_profile_mark(&w->profile, STEP_PHASE_WORLD);
  for (int32_t i = 0; i < w->body_count; ++i) {
    int rose = 0;
    piola_status st = step_body(w, &w->bodies[i], w->time, dt, local, &rose);
    if (st != PIOLA_OK) {
      restore_all(w, i);
      return st;
    }
    if (rose && check_energy) {
      restore_all(w, i + 1);
      *energy_rose = 1;
      return PIOLA_OK;
    }
  }
  piola_status contact = piola__world_self_collide(w, dt, w->time + dt, closes, local);
  if (contact != PIOLA_OK) restore_all(w, w->body_count);
  return contact;
}

piola_status piola_world_step(piola_world *w, double dt_limit, piola_step_stats *stats) {
  if (!w) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "step: NULL world");
  if (isnan(dt_limit))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "step: dt_limit is NaN (a limit in s, or <= 0 for none)");
  piola__world_check_start(w);
  PIOLA_TRY(piola__world_fracture_step(w));
  if (w->def.integrator != PIOLA_INTEGRATOR_NEWMARK)
    return piola__implicit_world_step(w, dt_limit, stats);
  piola_step_stats local = {0};
  piola__step_profile_start(&w->profile);
  const double bound = current_bound(w);
  double dt = fmin(bound, recent_bound_min(w));
  if (dt_limit > 0 && dt_limit < dt) dt = dt_limit;
  if (!(dt > 0)) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "step: dt must be > 0, got %g", dt);
  note_small_step(w);
  /* a step that blows up, or whose energy rises beyond what a stable step allows, is redone
   * from the restored state at a quarter of its size: the bound is a bound on the fastest
   * wave, not a proof, and the paper's promise is that the run goes on. Only after the last
   * retry does a blow-up reach the caller; a step still failing the energy check after the
   * last redo is kept (its state is finite). */
  int energy_rose = 0;
  piola_status st = try_step(w, dt, &local, piola__step_energy_check, &energy_rose);
  for (;;) {
    if (st == PIOLA_OK && energy_rose) {
      local.energy_redos++;
      dt *= 0.25;
    } else if (st == PIOLA_ERROR_NOT_FINITE && local.step_retries < PIOLA_STEP_MAX_RETRIES) {
      local.step_retries++;
      dt *= 0.25;
    } else {
      break;
    }
    st = try_step(w, dt, &local, piola__step_energy_check && local.energy_redos < PIOLA_STEP_MAX_RETRIES,
                  &energy_rose);
  }
  if (st != PIOLA_OK) {
    if (stats) *stats = local;
    return st;
  }
  remember_bound(w, bound);
  return piola__world_finish_step(w, dt, &local, stats);
}

piola_status piola__world_finish_step(piola_world *w, double dt, piola_step_stats *local,
                                      piola_step_stats *stats) {
  for (int32_t i = 0; i < w->body_count; ++i) piola__body_plastic_after_step(&w->bodies[i], dt);
  piola__step_profile_mark(&w->profile, STEP_PHASE_WORLD);
  if (w->profile.enabled) w->profile.steps++;
  w->time += dt;
  local->substeps = 1;
  local->last_dt = dt;
  if (stats) *stats = *local;
  return PIOLA_OK;
}

piola_status piola_world_advance_to(piola_world *w, double t_end, piola_step_stats *stats) {
  if (!w) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "advance_to: NULL world");
  if (!isfinite(t_end))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "advance_to: t_end must be finite");
  if (t_end < w->time)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "advance_to: t_end = %.17g s is before the world's time %.17g s (a world "
                      "does not step back)",
                      t_end, w->time);
  w->deeper_steps_left = IMPLICIT_DEEPER_STEPS;
  piola_status st = PIOLA_OK;
  while (w->time < t_end && st == PIOLA_OK) {
    double left = t_end - w->time;
    /* avoid a sliver step after a full one: split the last two evenly */
    double dt = piola_world_stable_dt(w);
    double limit = left;
    if (left > dt && left < 2 * dt) limit = 0.5 * left;
    /* the implicit step is the user's, usually a frame: a target a rounding error past it
     * is reached in one step */
    if (w->def.integrator != PIOLA_INTEGRATOR_NEWMARK && left <= dt * (1 + 1e-9)) limit = left;
    piola_step_stats one;
    w->collision_deadline = t_end;
    st = piola_world_step(w, limit, &one);
    w->collision_deadline = NAN;
    if (stats) {
      stats->substeps += one.substeps;
      stats->cg_iterations += one.cg_iterations;
      stats->colliding = one.colliding;
      stats->contacts += one.contacts;
      stats->impacts += one.impacts;
      stats->impact_zones += one.impact_zones;
      stats->collision_steps += one.collision_steps;
      stats->newton_iterations += one.newton_iterations;
      stats->linear_iterations += one.linear_iterations;
      stats->newton_failures += one.newton_failures;
      stats->step_retries += one.step_retries;
      stats->energy_redos += one.energy_redos;
      if (one.substeps) stats->last_dt = one.last_dt;
    }
    /* land exactly on the target, no rounding drift */
    if (st == PIOLA_OK && one.last_dt == left) w->time = t_end;
  }
  w->deeper_steps_left = -1;
  return st;
}
