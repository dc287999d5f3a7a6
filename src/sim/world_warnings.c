/* The warning channel: conditions a run survives but a user should hear about once
 * (piola_world_warning; `piola run` prints each on stderr and appends it to
 * DIR/warnings.txt, docs/cli.md). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "force/elastic_body_internal.h"
#include "force/stable_step.h"
#include "piola/mesh_quality.h"
#include "sim/obstacle_internal.h"
#include "sim/world_internal.h"

/* A tet whose rest step is this many times below the median tet's is a sliver that sets
 * the step of the whole solid: the run costs about that factor more steps than on a mesh of
 * the same size without it. Of the real meshes in ../shared/data only bunny.msh (192x,
 * a 0.23 degree dihedral angle) and armadillo_10k (28x) pass it; armadillo_4k (20x) and
 * bar-2523 (22x) do not. */
#define SLIVER_STEP_RATIO 25.0
#define SLIVER_NAMED 3

void piola__world_warn(piola_world *w, piola_warning_kind kind, const char *format, ...) {
  if (kind < 0 || kind >= PIOLA_WARNING_KIND_COUNT || w->warnings[kind]) return;
  char text[1024];
  va_list ap;
  va_start(ap, format);
  vsnprintf(text, sizeof text, format, ap);
  va_end(ap);
  size_t n = strlen(text) + 1;
  char *copy = malloc(n);
  if (!copy) return; /* a warning is advisory: out of memory drops it, never the run */
  memcpy(copy, text, n);
  w->warnings[kind] = copy;
  if (w->warning_handler) w->warning_handler(w->warning_context, kind, copy);
}

void piola_world_raise_warning(piola_world *world, piola_warning_kind kind, const char *message) {
  if (world && message) piola__world_warn(world, kind, "%s", message);
}

void piola_world_set_warning_handler(piola_world *world, piola_warning_handler *handler,
                                     void *context) {
  if (!world) return;
  world->warning_handler = handler;
  world->warning_context = context;
}

const char *piola_world_warning(const piola_world *world, piola_warning_kind kind) {
  if (!world || kind < 0 || kind >= PIOLA_WARNING_KIND_COUNT) return NULL;
  return world->warnings[kind];
}

void piola__world_warnings_free(piola_world *w) {
  for (int k = 0; k < PIOLA_WARNING_KIND_COUNT; ++k) free(w->warnings[k]), w->warnings[k] = NULL;
}

static int compare_doubles(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

void piola__world_check_slivers(piola_world *w, const world_body *s) {
  const piola_elastic_body *b = s->solid;
  const int32_t nt = b ? b->tet_count : 0;
  if (nt < 2 || w->warnings[PIOLA_WARNING_SLIVER]) return;
  double *step = malloc(2 * (size_t)nt * sizeof *step);
  if (!step) return;
  const double one[3] = {1, 1, 1};
  /* the rest step each tet alone would allow: cfl h_e / c_e */
  for (int32_t t = 0; t < nt; ++t) {
    const double h = piola__elastic_body_tet_rest_altitude(b, t);
    const double k = piola__elastic_body_tet_modulus(b, t, one);
    step[t] = k > 0 ? w->def.cfl * h / sqrt(k / b->density) : INFINITY;
  }
  memcpy(step + nt, step, (size_t)nt * sizeof *step);
  qsort(step + nt, (size_t)nt, sizeof *step, compare_doubles);
  const double median = step[nt + nt / 2];
  if (!(step[nt] * SLIVER_STEP_RATIO < median)) {
    free(step);
    return;
  }
  /* the worst few, each with its dihedral angles */
  int32_t worst[SLIVER_NAMED];
  int named = 0;
  for (int r = 0; r < SLIVER_NAMED; ++r) {
    int32_t best = -1;
    for (int32_t t = 0; t < nt; ++t) {
      int taken = 0;
      for (int q = 0; q < named; ++q) taken |= worst[q] == t;
      if (!taken && (best < 0 || step[t] < step[best])) best = t;
    }
    if (best < 0 || !(step[best] * SLIVER_STEP_RATIO < median)) break;
    worst[named++] = best;
  }
  char list[768];
  size_t len = 0;
  list[0] = 0;
  for (int q = 0; q < named && len < sizeof list; ++q) {
    const int32_t *v = b->tets + 4 * worst[q];
    const double *x = b->rest_positions;
    double angles[6], lo = INFINITY, hi = -INFINITY;
    piola_tet_dihedral_angles(x + 3 * v[0], x + 3 * v[1], x + 3 * v[2], x + 3 * v[3], angles);
    for (int a = 0; a < 6; ++a) lo = fmin(lo, angles[a]), hi = fmax(hi, angles[a]);
    len += (size_t)snprintf(list + len, sizeof list - len,
                            "%stet %d (dihedral angles %.2f to %.2f degrees) forces %.3g s",
                            q ? "; " : "", (int)worst[q], lo, hi, step[worst[q]]);
  }
  if (w->def.integrator == PIOLA_INTEGRATOR_NEWMARK) {
    /* at a max_dt below the slivers' step they set nothing */
    if (step[worst[0]] < w->def.max_dt)
      piola__world_warn(w, PIOLA_WARNING_SLIVER,
                        "solid '%s': sliver elements set the step: %s, %.0f times below the "
                        "median tet's %.3g s (tets numbered from 0 in file order); remesh with "
                        "`piola mesh generate MESH_FILE -o NEW_MESH_FILE` (inside the mesh's "
                        "boundary, mesher.md) for a step near the median",
                        s->name, list, median / step[worst[0]], median);
  } else /* the implicit step is integrator.dt: slivers slow its linear solves instead */
    piola__world_warn(w, PIOLA_WARNING_SLIVER,
                      "solid '%s': sliver elements would set a \"newmark\" step: %s, %.0f times "
                      "below the median tet's %.3g s (tets numbered from 0 in file order); "
                      "\"%s\" steps integrator.dt whatever they force, but its conjugate "
                      "gradient converges more slowly on them (integrator.preconditioner "
                      "\"incomplete_cholesky\" or \"multigrid\" helps); remesh with `piola mesh "
                      "generate MESH_FILE -o NEW_MESH_FILE` to avoid both",
                      s->name, list, median / step[worst[0]], median,
                      piola_integrator_type_name(w->def.integrator));
  free(step);
}

/* A node deeper inside an obstacle than this fraction of its body's bounding-box diagonal at
 * the first step is a placement mistake more likely than a contact: the step projects it to
 * the surface at once, crushing the elements between (an upright torus started 27 cm into a
 * plane inverted 1,295 of its tets in its first frame). Resting contact, deep a rounding
 * error, is far below it. */
#define STARTS_INSIDE_DEPTH 0.01

double piola__bounding_diagonal(int32_t n, const double *x) {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int32_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k)
      lo[k] = fmin(lo[k], x[3 * i + k]), hi[k] = fmax(hi[k], x[3 * i + k]);
  double d2 = 0;
  for (int k = 0; k < 3; ++k) d2 += n > 0 ? (hi[k] - lo[k]) * (hi[k] - lo[k]) : 0.0;
  return sqrt(d2);
}

/* 1 when track is zero at every time (a constant 0, or keys all 0). */
static int track_always_zero(const piola_track *track) {
  if (track->key_count == 0) return track->value == 0.0;
  for (int32_t k = 0; k < track->key_count; ++k)
    if (track->values[k] != 0.0) return 0;
  return 1;
}

/* An explicit step of an undamped elastic solid keeps its energy (the energy mode, up to the
 * integrator's drift) or, with LINEAR and CLAMP, whose stress past the threshold is not a
 * gradient, can add to it: Medit's unit ball collapsed to a point kept 510-560 tets inverted
 * for 30 s with no damping, and corotated went from 2.1e4 J to 8.6e9 J by 4.4 s, where its
 * state-aware steps fell to 7.6e-7 s (time-stepping.md, "What is not physics"). Plastic flow
 * dissipates, so plastic solids are left out. */
static void check_undamped_tangles(piola_world *w) {
  if (w->def.integrator != PIOLA_INTEGRATOR_NEWMARK) return;
  for (int32_t bi = 0; bi < w->body_count; ++bi) {
    const world_body *s = &w->bodies[bi];
    if (s->kind != PIOLA_BODY_SOLID || s->plastic || !track_always_zero(&s->shear_viscosity) ||
        !track_always_zero(&s->bulk_viscosity))
      continue;
    double det = 0;
    const int32_t tet = piola__solid_flat_or_inverted_tet(s, s->x, &det, 0.0);
    if (tet < 0) continue;
    const piola_elastic_body *e = s->solid;
    int conservative = 1;
    for (int32_t m = 0; m < e->material_count; ++m)
      if (e->materials[m].inversion_mode != PIOLA_INVERSION_ENERGY) conservative = 0;
    piola__world_warn(
        w, PIOLA_WARNING_UNDAMPED_TANGLE,
        "solid '%s' starts tangled (tet %d, numbered from 0 in file order, has det F = %.3g) "
        "with no damping under \"newmark\": nothing dissipates the tangle's energy, so it "
        "will not settle%s. Give it damping (\"damping\": {\"shear\": ..., \"bulk\": ...}, "
        "Pa s; time-stepping.md, \"Recovery\", predicts the settling time) or use "
        "\"integrator\": {\"type\": \"backward_euler\"} (time-stepping.md, \"What is not "
        "physics\")",
        s->name, (int)tet, det,
        conservative ? ""
                     : ", and its inversion extension, whose stress past the threshold is not "
                       "the gradient of an energy, can add energy until the steps become "
                       "tiny (\"inversion\": {\"mode\": \"energy\"} keeps it bounded)");
    return;
  }
}

/* The implicit integrators solve a body again after the collision pass only with the
 * per-step pass: with an interval two balls meeting at 4 m/s at one step per frame inverted
 * 761 of their 2,220 tets (time-stepping.md, "Implicit integrators"). */
static void check_implicit_interval(piola_world *w) {
  if (w->def.integrator == PIOLA_INTEGRATOR_NEWMARK || !(w->def.collision_interval > 0)) return;
  for (int32_t bi = 0; bi < w->body_count; ++bi) {
    const world_body *b = &w->bodies[bi];
    if (!b->self_collision.enabled) continue;
    piola__world_warn(w, PIOLA_WARNING_IMPLICIT_INTERVAL,
                      "integrator.collision_interval is %g s with \"%s\" and %s '%s' has "
                      "self_collision: the bodies are solved again after the collision pass "
                      "only with the per-step pass, so at frame-sized steps colliding bodies "
                      "pass into each other (surfaces cross, tets invert); keep "
                      "collision_interval at 0 with "
                      "the implicit integrators (time-stepping.md, \"Implicit integrators\")",
                      w->def.collision_interval, piola_integrator_type_name(w->def.integrator),
                      piola__body_kind_name(b->kind), b->name);
    return;
  }
}

/* Quasistatics keeps bodies apart by the collision pass alone, after each body's solve:
 * bodies resting on or pressing into each other through self-collision are not solved
 * (a box dropped on another went 1.2 m along the ground; cloth_on_jelly.json run
 * quasistatically crushed its block; time-stepping.md, "Solids against each other inside the
 * solve"). One body's own folds are, so it takes two. */
static void check_quasistatic_contact(piola_world *w) {
  if (w->def.integrator != PIOLA_INTEGRATOR_QUASISTATIC) return;
  const world_body *first = NULL;
  for (int32_t bi = 0; bi < w->body_count; ++bi) {
    const world_body *b = &w->bodies[bi];
    if (!b->self_collision.enabled) continue;
    if (!first) {
      first = b;
      continue;
    }
    piola__world_warn(w, PIOLA_WARNING_QUASISTATIC_CONTACT,
                      "%s '%s' and %s '%s' have self_collision under \"quasistatic\": its "
                      "collision pass alone keeps bodies apart there, so bodies that rest on "
                      "or press into each other through it are not solved (they jump and "
                      "crush); use \"backward_euler\", or fixed or driven nodes and obstacles "
                      "for quasistatic contact (time-stepping.md, \"Solids against each other "
                      "inside the solve\")",
                      piola__body_kind_name(first->kind), first->name,
                      piola__body_kind_name(b->kind), b->name);
    return;
  }
}

void piola__world_check_start(piola_world *w) {
  if (w->start_checked) return;
  w->start_checked = 1;
  /* a resumed run continues one that was checked: its contacts are the run's own */
  if (w->time != 0.0) return;
  check_undamped_tangles(w);
  check_implicit_interval(w);
  check_quasistatic_contact(w);
  for (int32_t bi = 0; bi < w->body_count; ++bi) {
    const world_body *b = &w->bodies[bi];
    const double size = piola__bounding_diagonal(b->n, b->x), limit = STARTS_INSIDE_DEPTH * size;
    for (int32_t o = 0; o < w->obstacle_count; ++o) {
      const piola_obstacle *ob = w->obstacles[o];
      piola__rigid_state pose;
      piola__rigid_motion_state(&ob->motion, w->time, &pose);
      int32_t inside = 0, deepest = -1;
      double depth = 0;
      for (int32_t i = 0; i < b->n; ++i) {
        if (b->flags[i] != NODE_FREE) continue; /* prescribed: never projected */
        const vec3 p = {b->x[3 * i], b->x[3 * i + 1], b->x[3 * i + 2]};
        if (!piola__obstacle_may_contain(ob, &pose, p)) continue;
        const double d = -piola__obstacle_distance_posed(ob, &pose, p, NULL, NULL);
        if (!(d > limit)) continue;
        ++inside;
        if (d > depth) depth = d, deepest = i;
      }
      if (inside == 0) continue;
      /* a body collapsed to a point (initial.matrix zero) has no size to compare with */
      char share[64] = "";
      if (size > 0)
        snprintf(share, sizeof share, " (%.0f%% of the %s's size)", 100.0 * depth / size,
                 piola__body_kind_name(b->kind));
      piola__world_warn(w, PIOLA_WARNING_STARTS_INSIDE,
                        "%s '%s': %d of its %d nodes start inside obstacle %d (obstacles and "
                        "bones counted from 0 in the order added), node %d deepest at %.3g m%s; "
                        "the first step pushes them to its surface at once, crushing the "
                        "elements between: move the %s out (its transform) or the obstacle away",
                        piola__body_kind_name(b->kind), b->name, (int)inside, (int)b->n, (int)o,
                        (int)deepest, depth, share, piola__body_kind_name(b->kind));
      return;
    }
  }
}
