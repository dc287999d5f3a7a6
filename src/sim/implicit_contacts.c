/* Obstacle contacts and friction of a body's implicit step (docs/time-stepping.md,
 * "Implicit integrators", Constraints, and "Friction after the solve"): the active set of
 * nodes held along an obstacle's normal, their release, and friction once the solve has
 * converged, node by node or, for a body that may slide as a whole, as kinetic friction on
 * every contact solved again in rounds. Newton's method (implicit_step.c) calls these
 * between its solves. */
#include <math.h>
#include <string.h>

#include "force/elastic_body_internal.h"
#include "force/stable_step.h"
#include "piola/shell_body.h"
#include "shell/shell_stable_step.h"
#include "sim/implicit_problem.h"
#include "sim/implicit_split.h"
#include "sim/obstacle_friction.h"
#include "sim/obstacle_internal.h"
#include "sim/solid_contacts.h"

/* Friction's move of a node after the solve, as a fraction of the rest altitude of a tet
 * around it, above which the step is solved again (piola__newton_friction_moves_deform). Measured
 * on bunny.msh's slivers at the contact: 1.8-12, and elements there stayed inverted; on the
 * generated tori of BENCHMARKS.md at most 0.27, where the split is harmless. */
#define FRICTION_RESOLVE_MOVE 0.5
/* A friction round changes less than this fraction of the total friction force: no more */
#define FRICTION_ROUND_CHANGE 0.01

/* A shell's one-way coupling to the solids (collide_with_solids; the solids have stepped
 * already): free nodes inside a solid's surface are projected onto it and held along its
 * normal like obstacle contacts, the surface's velocity kept for friction. A solid with
 * self_collision, under backward Euler: the same against the other such solids' surfaces,
 * kept the pair's thickness apart (solid_contacts.c). Returns 1 when it moved a node,
 * else 0. */
static int32_t coupling_contacts(newton_problem *pb) {
  world_body *s = pb->s;
  struct implicit_state *st = pb->st;
  /* backward Euler only: in quasistatics solids resting on each other through
   * self_collision were erratic with these holds and without (time-stepping.md) */
  const int solid = s->kind == PIOLA_BODY_SOLID && !pb->quasistatic;
  if (!s->collide_with_solids && !solid) return 0;
  const size_t v3 = sizeof(double) * 3 * (size_t)s->n;
  memcpy(st->scratch_v, s->x, v3);
  if (solid)
    (void)piola__solid_contacts_with_solids(pb->w, s, HELD_BY_SOLID, st->surface_v, st->surface_mu);
  else
    (void)piola__body_collide_in_step(pb->w, s, pb->t1, pb->dt, HELD_BY_SOLID, st->surface_v);
  return memcmp(st->scratch_v, s->x, v3) != 0;
}

/* Projects free nodes that are inside an obstacle (or, for a coupled shell, a solid) onto
 * its surface and holds their normal from then on. Returns the number of nodes newly held
 * (at least 1 when any node moved; -1 on error). */
int32_t piola__newton_contacts(newton_problem *pb) {
  piola_world *w = pb->w;
  world_body *s = pb->s;
  struct implicit_state *st = pb->st;
  if (s->n == 0) return 0;
  const int32_t coupled = coupling_contacts(pb);
  if (w->obstacle_count == 0) return coupled;
  memset(st->scratch_v, 0, sizeof(double) * 3 * (size_t)s->n);
  double *normals = st->cg[0]; /* free between solves */
  int32_t moved = piola_obstacles_collide(w->obstacles, w->obstacle_count, pb->t1, 0.0, s->n, s->x,
                                          st->scratch_v, st->hit, normals);
  if (moved < 0) return -1;
  int32_t added = 0;
  for (int32_t i = 0; i < s->n; ++i) {
    if (!st->hit[i]) continue;
    if (s->flags[i] != NODE_FREE) {
      /* prescribed nodes are never projected: put them back */
      double xp[3], vp[3];
      piola__body_constrained_state(s, i, pb->t1, xp, vp);
      for (int k = 0; k < 3; ++k) s->x[3 * i + k] = xp[k];
      continue;
    }
    if (!s->colliding[i]) added++;
    if (s->colliding[i] != HELD_BY_FRICTION) s->colliding[i] = HELD_BY_OBSTACLE;
    st->surface_mu[i] = NAN; /* an obstacle's contact now */
    for (int k = 0; k < 3; ++k) s->normals[3 * i + k] = normals[3 * i + k];
  }
  const int32_t changed = moved > 0 ? (added > 0 ? added : 1) : coupled;
  if (changed > 0) pb->contacts_moved = 1;
  return changed;
}

/* Within this fraction of its body's size outside an obstacle's surface a node rests on it
 * at a quasistatic step's start. Held nodes slide along a curved surface and end a step up
 * to slide^2 / (2 R) outside it: cloth draped on a 0.25 m sphere (cloth_on_sphere.json run
 * quasistatically) ended steps 2e-10 to 1.4e-6 m off it, at most 1e-6 of its 1.4 m size. */
#define RESTING_GAP 1e-6

/* Quasistatics: holds the free nodes that rest on an obstacle's surface at the step's start
 * (outside it by at most RESTING_GAP of the body's size), put onto it. Backward Euler's
 * first guess takes a step of gravity, which finds them; the quasistatic guess is the last
 * equilibrium, where they lie on or just off the surface, so they were found only after the
 * first iteration had pushed them in, and a body at rest on an obstacle took 20-25 Newton
 * iterations every step to find its equilibrium again. From the state alone, so that a
 * resumed run holds the same nodes. Returns how many. */
int32_t piola__newton_resting_contacts(newton_problem *pb) {
  piola_world *w = pb->w;
  world_body *s = pb->s;
  if (!pb->quasistatic || w->obstacle_count == 0 || s->n == 0) return 0;
  const double gap = RESTING_GAP * piola__bounding_diagonal(s->n, s->x);
  int32_t held = 0;
  for (int32_t o = 0; o < w->obstacle_count; ++o) {
    const piola_obstacle *ob = w->obstacles[o];
    if (!ob) continue;
    piola__rigid_state pose;
    piola__rigid_motion_state(&ob->motion, pb->t1, &pose);
    for (int32_t i = 0; i < s->n; ++i) {
      if (s->flags[i] != NODE_FREE || s->colliding[i] || !(s->mass[i] > 0)) continue;
      const vec3 p = {s->x[3 * i], s->x[3 * i + 1], s->x[3 * i + 2]};
      if (!piola__obstacle_within_bound(ob, &pose, p, gap, NULL)) continue;
      vec3 normal;
      const double d = piola__obstacle_distance_posed(ob, &pose, p, &normal, NULL);
      if (!(d >= 0 && d <= gap)) continue;
      s->colliding[i] = HELD_BY_OBSTACLE;
      pb->st->surface_mu[i] = NAN; /* an obstacle's contact */
      const double n3[3] = {normal.x, normal.y, normal.z};
      for (int k = 0; k < 3; ++k) s->normals[3 * i + k] = n3[k], s->x[3 * i + k] -= d * n3[k];
      held++;
    }
  }
  if (held > 0) pb->contacts_moved = 1;
  return held;
}

/* Releases held nodes whose contact force would pull them into the obstacle (g . n < 0 means
 * the constraint force g / dt^2 points along -n). Nodes friction holds only with
 * `friction_held_too` (at convergence): while the iterate is far from it their residual is no
 * contact force yet (47 of a sliding block's 57 holds went in the first iterations of a
 * step), and which of them let go then depended on the path Newton took (the block of
 * tests/test_incomplete_cholesky.c, solved three ways, ended 3-5 um apart). Returns how
 * many. */
int32_t piola__newton_release_contacts(newton_problem *pb, int friction_held_too) {
  world_body *s = pb->s;
  int32_t released = 0;
  for (int32_t i = 0; i < s->n; ++i) {
    if (!s->colliding[i] || s->flags[i] != NODE_FREE) continue;
    if (s->colliding[i] == HELD_BY_FRICTION && !friction_held_too) continue;
    const double *g = pb->st->residual + 3 * i, *nrm = s->normals + 3 * i;
    if (g[0] * nrm[0] + g[1] * nrm[1] + g[2] * nrm[2] < 0) {
      s->colliding[i] = 0;
      /* its friction goes with the contact, and does not come back with it in this solve:
       * a force that came and went with the contact made the contact set cycle (nodes of a
       * block sliding down an incline, lifted by the friction's moment) */
      if (pb->kinetic)
        for (int k = 0; k < 3; ++k) pb->st->friction[3 * i + k] = 0;
      released++;
    }
  }
  if (released > 0) pb->contacts_moved = 1;
  return released;
}

/* Coulomb friction with the converged contact force: the normal impulse dt (g . n) / dt^2
 * per unit mass limits the tangential velocity relative to the nearest obstacle. Changes
 * x and v of sliding nodes; returns how many. Notes for a second solve, per node: in
 * st->hit what piola__coulomb_limit did (2 stopped it, 1 slowed it, 0 nothing); in
 * st->friction the force m dv / dt; in st->scratch_v (n) how far it moved. */
int32_t piola__newton_contact_friction(newton_problem *pb) {
  piola_world *w = pb->w;
  world_body *s = pb->s;
  struct implicit_state *st = pb->st;
  double *moved = st->scratch_v;
  memset(st->hit, 0, (size_t)s->n);
  memset(moved, 0, sizeof(double) * (size_t)s->n);
  memset(st->friction, 0, sizeof(double) * 3 * (size_t)s->n);
  int32_t changed = 0;
  for (int32_t i = 0; i < s->n; ++i) {
    const int on_solid = s->colliding[i] == HELD_BY_SOLID;
    if ((s->colliding[i] != HELD_BY_OBSTACLE && !on_solid) || s->flags[i] != NODE_FREE) continue;
    const double *g = pb->st->residual + 3 * i, *nrm = s->normals + 3 * i;
    double dvn = (g[0] * nrm[0] + g[1] * nrm[1] + g[2] * nrm[2]) / (pb->dt * s->mass[i]);
    if (!(dvn > 0)) continue;
    piola_vec3 p = {s->x[3 * i], s->x[3 * i + 1], s->x[3 * i + 2]}, vo;
    double mu, *vi = s->v + 3 * i;
    if (on_solid) {
      /* against a solid's surface: a shell's solid_friction or a solid pair's, the
       * surface's velocity */
      const double *vs = pb->st->surface_v + 3 * i;
      mu = s->kind == PIOLA_BODY_SOLID ? pb->st->surface_mu[i] : s->solid_friction;
      vo = (piola_vec3){vs[0], vs[1], vs[2]};
    } else {
      piola__nearest_obstacle_motion(w->obstacles, w->obstacle_count, pb->t1, p, &mu, &vo);
    }
    const double before[3] = {vi[0], vi[1], vi[2]};
    const int limited = piola__coulomb_limit(vi, vo, nrm, mu, dvn);
    if (!limited) continue;
    double move2 = 0;
    for (int k = 0; k < 3; ++k) {
      const double x = s->x_old[3 * i + k] + pb->dt * vi[k];
      move2 += (x - s->x[3 * i + k]) * (x - s->x[3 * i + k]);
      s->x[3 * i + k] = x;
      st->friction[3 * i + k] = s->mass[i] * (vi[k] - before[k]) / pb->dt;
    }
    moved[i] = sqrt(move2);
    st->hit[i] = (uint8_t)limited;
    changed++;
  }
  return changed;
}

/* Whether friction's moves (piola__newton_contact_friction, just run) are large against the
 * elements they touch: a move above FRICTION_RESOLVE_MOVE times a tet's (a shell triangle's)
 * rest altitude can flatten or invert it, or lock a strain the solve never saw (a cloth on a
 * sphere with friction kept 0.14 J of stretch with the move alone, 0.07 J solved again, where
 * Newmark settles at 0.02 J). Not a split solid (its ranks hold different tets, and its PETSc
 * filter holds normals only): there friction stays a move after the solve. */
int piola__newton_friction_moves_deform(const newton_problem *pb) {
  const world_body *s = pb->s;
  if (piola__implicit_split_of(s)) return 0;
  if (s->kind == PIOLA_BODY_SHELL) {
    const int32_t *tris = piola_shell_body_triangles(s->shell);
    const double *moved = pb->st->scratch_v;
    for (int32_t t = 0; t < piola_shell_body_triangle_count(s->shell); ++t) {
      double most = 0;
      for (int c = 0; c < 3; ++c) most = fmax(most, moved[tris[3 * t + c]]);
      if (most > FRICTION_RESOLVE_MOVE * piola__shell_body_triangle_altitude(s->shell, t)) return 1;
    }
    return 0;
  }
  if (s->kind != PIOLA_BODY_SOLID) return 0;
  const piola_elastic_body *b = s->solid;
  const int32_t *tets = piola_elastic_body_tets(b);
  const double *moved = pb->st->scratch_v;
  for (int32_t t = 0; t < piola_elastic_body_tet_count(b); ++t) {
    double most = 0;
    for (int c = 0; c < 4; ++c) most = fmax(most, moved[tets[4 * t + c]]);
    if (most > FRICTION_RESOLVE_MOVE * piola__elastic_body_tet_rest_altitude(b, t)) return 1;
  }
  return 0;
}

/* g . n at node i, positive where its hold pushes: the normal contact force is
 * g . n / dt^2 (g, the residual, carries dt^2). */
static double normal_residual(const newton_problem *pb, int32_t i) {
  const double *g = pb->st->residual + 3 * i, *nrm = pb->s->normals + 3 * i;
  return g[0] * nrm[0] + g[1] * nrm[1] + g[2] * nrm[2];
}

/* The obstacle nearest node i: its friction coefficient (returned) and surface velocity vo. */
static double node_obstacle(const newton_problem *pb, int32_t i, piola_vec3 *vo) {
  const double *x = pb->s->x + 3 * i;
  double mu;
  piola__nearest_obstacle_motion(pb->w->obstacles, pb->w->obstacle_count, pb->t1,
                                 (piola_vec3){x[0], x[1], x[2]}, &mu, vo);
  return mu;
}

/* Where friction stopped a solid's node on another solid's surface (solid_contacts.c set its
 * surface_mu): that pair's coefficient and the surface's velocity, as for node_obstacle; -1
 * for a node on an obstacle. */
static double node_solid_surface(const newton_problem *pb, int32_t i, piola_vec3 *vo) {
  if (pb->s->kind != PIOLA_BODY_SOLID || !isfinite(pb->st->surface_mu[i])) return -1;
  const double *vs = pb->st->surface_v + 3 * i;
  *vo = (piola_vec3){vs[0], vs[1], vs[2]};
  return pb->st->surface_mu[i];
}

/* The tangential part of node i's velocity relative to vo, about its normal, into vt; returns
 * its size. */
static double relative_slip(const world_body *s, int32_t i, piola_vec3 vo, double vt[3]) {
  const double *v = s->v + 3 * i, *nrm = s->normals + 3 * i;
  const double rel[3] = {v[0] - vo.x, v[1] - vo.y, v[2] - vo.z};
  const double rn = rel[0] * nrm[0] + rel[1] * nrm[1] + rel[2] * nrm[2];
  for (int k = 0; k < 3; ++k) vt[k] = rel[k] - rn * nrm[k];
  return sqrt(vt[0] * vt[0] + vt[1] * vt[1] + vt[2] * vt[2]);
}

/* Whether the body may slide as a whole on its contacts, after a solve without friction:
 * its mass times its contacts' mean slip (their tangential velocity relative to the nearest
 * obstacle, weighted by their normal impulses) is above the friction impulse those contacts
 * can give, the sum of mu dt (g . n) / dt^2. Friction node by node (piola__newton_contact_friction)
 * misleads there at large steps: it stops a contact node whose own momentum is below its
 * share of that impulse, the rest of the body, which the solve moved on, drags it along in
 * the next steps through the elastic forces, and friction never sees those. Measured: a block
 * on a 0.5 rad incline stuck for good at one step per 1/30 s frame for every mu from 0.1 to
 * 0.8, its contact nodes holding a tenth of its mass (docs/time-stepping.md, "Friction after
 * the solve"). Solids on one process, as piola__newton_friction_moves_deform, without
 * self-collision: examples/solids_stack.json as backward Euler, the ball under the landing torus,
 * failed 2 Newton tries with it (0 without) and took 9% more iterations. */
int piola__newton_body_may_slide(const newton_problem *pb) {
  const world_body *s = pb->s;
  if (s->kind != PIOLA_BODY_SOLID || piola__implicit_split_of(s) || s->self_collision.enabled)
    return 0;
  double capacity = 0, impulse = 0, slip[3] = {0, 0, 0};
  for (int32_t i = 0; i < s->n; ++i) {
    if (s->colliding[i] != HELD_BY_OBSTACLE || s->flags[i] != NODE_FREE) continue;
    const double jn = normal_residual(pb, i) / pb->dt;
    if (!(jn > 0)) continue;
    piola_vec3 vo;
    double vt[3];
    const double mu = node_obstacle(pb, i, &vo);
    (void)relative_slip(s, i, vo, vt);
    capacity += mu * jn, impulse += jn;
    for (int k = 0; k < 3; ++k) slip[k] += jn * vt[k];
  }
  if (!(impulse > 0)) return 0;
  /* a body held by fixed, driven or bone nodes does not slide as a whole (examples/arm_flex
   * as backward Euler, its flesh on its bones, took 2.4 times the Newton iterations) */
  for (int32_t i = 0; i < s->n; ++i)
    if (s->flags[i] != NODE_FREE && s->mass[i] > 0) return 0;
  /* the body's momentum at the contacts' mean slip: a body rolling without slipping has
   * none, whatever its speed */
  const double scale = pb->total_mass / impulse;
  const double momentum2 =
      scale * scale * (slip[0] * slip[0] + slip[1] * slip[1] + slip[2] * slip[2]);
  return momentum2 > capacity * capacity;
}

/* After a solve with friction-held nodes: each held node whose holding impulse g / dt has a
 * tangential part above mu times its normal part slips instead: it keeps its normal hold and
 * feels the kinetic friction force mu (g . n) / dt^2 along that tangential part (the way the
 * hold pushed). Returns how many. */
static int32_t release_slipping_holds(newton_problem *pb) {
  world_body *s = pb->s;
  struct implicit_state *st = pb->st;
  int32_t released = 0;
  for (int32_t i = 0; i < s->n; ++i) {
    if (s->colliding[i] != HELD_BY_FRICTION || s->flags[i] != NODE_FREE) continue;
    const double *g = st->residual + 3 * i, *nrm = s->normals + 3 * i;
    const double gn = normal_residual(pb, i);
    const double gt[3] = {g[0] - gn * nrm[0], g[1] - gn * nrm[1], g[2] - gn * nrm[2]};
    const double gt_size = sqrt(gt[0] * gt[0] + gt[1] * gt[1] + gt[2] * gt[2]);
    piola_vec3 vo;
    const double on_solid = node_solid_surface(pb, i, &vo);
    const double mu = on_solid >= 0 ? on_solid : node_obstacle(pb, i, &vo);
    if (!(gn > 0) || !(gt_size > mu * gn)) continue;
    s->colliding[i] = on_solid >= 0 ? HELD_BY_SOLID : HELD_BY_OBSTACLE;
    const double scale = mu * gn / gt_size / (pb->dt * pb->dt);
    for (int k = 0; k < 3; ++k) st->friction[3 * i + k] = scale * gt[k];
    released++;
  }
  if (released > 0) pb->contacts_moved = 1;
  return released;
}

/* Kinetic friction on every obstacle contact of a body that may slide as a whole
 * (piola__newton_body_may_slide), from the solve just done: the force mu (g . n) / dt^2 against
 * each node's tangential velocity relative to the nearest obstacle, into st->friction for the next
 * solve (the nodes friction holds keep none: their hold is their friction). Returns how many
 * nodes feel it. */
int32_t piola__newton_kinetic_friction(newton_problem *pb) {
  world_body *s = pb->s;
  struct implicit_state *st = pb->st;
  int32_t count = 0;
  for (int32_t i = 0; i < s->n; ++i) {
    if (s->colliding[i] == HELD_BY_FRICTION) continue; /* the hold is its friction */
    for (int k = 0; k < 3; ++k) st->friction[3 * i + k] = 0;
    if (s->colliding[i] != HELD_BY_OBSTACLE || s->flags[i] != NODE_FREE) continue;
    const double gn = normal_residual(pb, i);
    piola_vec3 vo;
    double vt[3];
    const double mu = node_obstacle(pb, i, &vo);
    const double slip = relative_slip(s, i, vo, vt);
    if (!(gn > 0) || !(mu > 0) || !(slip > 0)) continue;
    const double scale = -mu * gn / (pb->dt * pb->dt) / slip;
    for (int k = 0; k < 3; ++k) st->friction[3 * i + k] = scale * vt[k];
    count++;
  }
  return count;
}

/* After a solve with kinetic friction: a node that its friction force now pushes along its
 * slip (the force would have stopped it within the step) is held where it stops, its
 * tangential velocity relative to the obstacle gone (x = x^n + dt v), and its friction left
 * to the hold. Returns how many. */
static int32_t hold_reversed_slips(newton_problem *pb) {
  world_body *s = pb->s;
  struct implicit_state *st = pb->st;
  int32_t held = 0;
  for (int32_t i = 0; i < s->n; ++i) {
    if (s->colliding[i] != HELD_BY_OBSTACLE || s->flags[i] != NODE_FREE) continue;
    double *f = st->friction + 3 * i;
    if (f[0] == 0 && f[1] == 0 && f[2] == 0) continue;
    piola_vec3 vo;
    double vt[3];
    (void)node_obstacle(pb, i, &vo);
    (void)relative_slip(s, i, vo, vt);
    if (!(vt[0] * f[0] + vt[1] * f[1] + vt[2] * f[2] > 0)) continue;
    for (int k = 0; k < 3; ++k) {
      s->v[3 * i + k] -= vt[k];
      s->x[3 * i + k] = s->x_old[3 * i + k] + pb->dt * s->v[3 * i + k];
      f[k] = 0;
    }
    s->colliding[i] = HELD_BY_FRICTION;
    held++;
  }
  if (held > 0) pb->contacts_moved = 1;
  return held;
}

/* Sum of |friction force| over the nodes (N). */
static double friction_total(const newton_problem *pb) {
  const double *f = pb->st->friction;
  double total = 0;
  for (int32_t i = 0; i < pb->s->n; ++i)
    total += sqrt(f[3 * i] * f[3 * i] + f[3 * i + 1] * f[3 * i + 1] + f[3 * i + 2] * f[3 * i + 2]);
  return total;
}

/* After a converged solve with friction (pb->friction_held): holds beyond Coulomb's cone slip
 * (release_slipping_holds), and where the step began with kinetic friction
 * (pb->kinetic), slips the friction reversed are held (hold_reversed_slips) and every slip's
 * friction follows its contact's normal force at this solve, which the friction's own moment
 * shifts (piola__newton_kinetic_friction). Returns whether any of this moved the friction by more
 * than FRICTION_ROUND_CHANGE of its total, so that the step is to be solved again. */
int piola__newton_next_friction_round(newton_problem *pb) {
  const double before = friction_total(pb);
  int32_t changed = release_slipping_holds(pb);
  if (pb->kinetic) {
    changed += hold_reversed_slips(pb);
    (void)piola__newton_kinetic_friction(pb);
  }
  return changed > 0 || fabs(friction_total(pb) - before) > FRICTION_ROUND_CHANGE * before;
}

/* Whether the step of gravity alone, x = prediction + dt^2 g, would take a free node into an
 * obstacle (1, else 0; -1 on error). Moves nothing: the obstacles project those positions in
 * a scratch copy. */
int piola__newton_gravity_step_enters_obstacle(newton_problem *pb) {
  world_body *s = pb->s;
  struct implicit_state *st = pb->st;
  if (pb->w->obstacle_count == 0 || s->n == 0) return 0;
  const double dt2 = pb->dt * pb->dt;
  for (int32_t i = 0; i < s->n; ++i)
    for (int k = 0; k < 3; ++k)
      st->base[3 * (int64_t)i + k] = st->prediction[3 * (int64_t)i + k] + dt2 * pb->g1[k];
  memset(st->scratch_v, 0, sizeof(double) * 3 * (size_t)s->n);
  if (piola_obstacles_collide(pb->w->obstacles, pb->w->obstacle_count, pb->t1, 0.0, s->n, st->base,
                              st->scratch_v, st->hit, st->cg[0]) < 0)
    return -1;
  for (int32_t i = 0; i < s->n; ++i)
    if (st->hit[i] && s->flags[i] == NODE_FREE) return 1;
  return 0;
}
