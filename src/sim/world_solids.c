/* Solids in the world: adding them, the solid kind's operations (forces, step bound, stats;
 * dispatched by body.c) and the solid accessors of piola/world.h. A solid is a world_body of
 * kind PIOLA_BODY_SOLID whose object is a piola_elastic_body. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "contact/bvh.h"
#include "force/elastic_body_internal.h"
#include "force/stable_step.h"
#include "math/mat3.h"
#include "sim/world_internal.h"

/* Without stats: the energy goes through the scalar material function per tet, which cost
 * more than the whole vectorized force loop (measured 10 ms against 8.5 ms per update on
 * the 97,878-tet torus, one thread) and stepping does not need it. piola_world_solid_stats
 * computes it from the update's per-tet state when asked (once per frame in `piola run`). */
piola_status piola__solid_update_forces(world_body *b, double t) {
  double scale = piola_track_eval(&b->stiffness_scale, t);
  piola_elastic_body_set_activation(b->solid, piola_track_eval(&b->activation, t));
  b->elastic_stale = 1;
  b->state_rate_valid = 0;
  return piola_elastic_body_update(b->solid, b->x, scale, b->force, NULL);
}

/* The state-aware bound of solid b (stable_step.h), computed once per update. */
static double solid_state_rate2(const world_body *b) {
  world_body *cache = (world_body *)b; /* a cache of a function of the const state */
  if (!cache->state_rate_valid) {
    cache->state_rate2 = piola__elastic_body_state_rate2(b->solid, &cache->state_worst_tet);
    cache->state_rate_valid = 1;
  }
  return b->state_rate2;
}

/* The step of solid b: its rest bound cfl h_min / c, or the state-aware bound cfl /
 * sqrt(max_e s k_e / (rho h_e^2)) where that is smaller (docs/time-stepping.md, "Step size").
 * At rest the two agree up to rounding, so the state bound takes over only when it is
 * smaller by more than rounding: a state at rest keeps the rest step's bits. */
double piola__solid_stable_dt(const piola_world *w, const world_body *b, double scale) {
  const double stiffening = piola__solid_plastic_stiffening(b);
  double speed = piola_elastic_body_max_wave_speed(b->solid) * sqrt(scale);
  double h = piola_elastic_body_min_rest_altitude(b->solid) / stiffening;
  if (!(speed > 0 && h > 0)) return INFINITY;
  const double rate2 = solid_state_rate2(b) * scale * stiffening * stiffening;
  return piola__state_or_rest_step(w->def.cfl * h / speed, w->def.cfl, rate2);
}

/* The elastic statistics of the last update, from its per-tet state (energy density lazily
 * by the body), summed serially in tet order. */
static void refresh_elastic_stats(world_body *s) {
  if (!s->elastic_stale) return;
  const piola_elastic_body *b = s->solid;
  const double *psi = piola_elastic_body_energy_density(b), *det = piola_elastic_body_det_f(b);
  double energy = 0, min_det = INFINITY;
  int32_t inverted = 0;
  for (int32_t t = 0; t < b->tet_count; ++t) {
    energy += b->rest_volume[t] * psi[t];
    inverted += det[t] < 0;
    min_det = fmin(min_det, det[t]);
  }
  s->elastic.elastic_energy = energy;
  s->elastic.inverted_count = inverted;
  s->elastic.min_det_f = min_det;
  s->elastic_stale = 0;
}

/* 1/2 sum m |v|^2 and sum m v over the nodes, in node order. */
static void kinetic(const world_body *b, double *energy, double momentum[3]) {
  double ke = 0, p[3] = {0, 0, 0};
  for (int32_t i = 0; i < b->n; ++i) {
    const double *v = b->v + 3 * i;
    ke += 0.5 * b->mass[i] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; ++k) p[k] += b->mass[i] * v[k];
  }
  *energy = ke;
  for (int k = 0; k < 3; ++k) momentum[k] = p[k];
}

piola_body_stats piola__solid_stats(world_body *b) {
  piola_body_stats st;
  memset(&st, 0, sizeof st);
  refresh_elastic_stats(b);
  kinetic(b, &st.kinetic_energy, st.momentum);
  st.elastic_energy = b->elastic.elastic_energy;
  st.inverted_count = b->elastic.inverted_count;
  return st;
}

/* splitmix64: a small, well-mixed, seedable generator so scrambles reproduce. */
static uint64_t splitmix(uint64_t *state) {
  uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

static double uniform(uint64_t *state) { return (double)(splitmix(state) >> 11) * 0x1.0p-53; }

static vec3 random_in_ball(uint64_t *state, double radius) {
  for (;;) {
    vec3 p = {2 * uniform(state) - 1, 2 * uniform(state) - 1, 2 * uniform(state) - 1};
    if (vec3_norm2(p) <= 1) return vec3_scale(p, radius);
  }
}

/* Every value of a track (checked by piola__track_ok) is at most hi. */
static int track_at_most(const piola_track *t, double hi) {
  if (t->key_count == 0) return t->value <= hi;
  for (int32_t k = 0; k < t->key_count; ++k)
    if (t->values[k] > hi) return 0;
  return 1;
}

static piola_status check_solid_def(const piola_solid_def *def, int32_t id) {
  if (!def->mesh) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "solid %d: mesh is required", (int)id);
  if (!(def->density > 0) || !isfinite(def->density))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "solid %d: density must be > 0 kg/m^3, got %g",
                      (int)id, def->density);
  if (!piola__track_ok(&def->stiffness_scale, 0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "solid %d: stiffness_scale must be >= 0", (int)id);
  PIOLA_TRY(piola__check_viscosities("solid", id, &def->shear_viscosity, &def->bulk_viscosity));
  if (!(def->scramble_radius >= 0) || !isfinite(def->scramble_radius))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "solid %d: scramble radius must be >= 0 m",
                      (int)id);
  if (!mat3_is_finite(def->initial_matrix))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "solid %d: initial matrix must be finite", (int)id);
  if (def->self_collision.enabled &&
      (!(def->self_collision.thickness > 0) || !isfinite(def->self_collision.thickness) ||
       !(def->self_collision.friction >= 0) || !isfinite(def->self_collision.friction)))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "solid %d: self_collision needs thickness > 0 m and friction >= 0, got %g, %g",
                      (int)id, def->self_collision.thickness, def->self_collision.friction);
  if (!isfinite(def->velocity.x) || !isfinite(def->velocity.y) || !isfinite(def->velocity.z))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "solid %d: velocity must be finite", (int)id);
  if (!piola__track_ok(&def->activation, 0) || !track_at_most(&def->activation, 1))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "solid %d: activation must be in [0, 1]", (int)id);
  if (def->fiber_directions && def->plasticity)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "solid %d: fiber directions cannot be combined with plasticity (not supported)",
                      (int)id);
  return PIOLA_OK;
}

/* The initial state may stretch a solid far past its rest size (a scramble of twice its
 * diagonal is a test case), but not so far that its positions cannot hold its shape: at
 * 1e16 times its size a node's rounding is its size. A scramble of 1e100 m froze the body (no
 * step changed a position), 1e300 m made its energy NaN in frame 0. */
#define INITIAL_EXTENT_LIMIT 1e6

static piola_status check_initial_extent(const world_body *s, const double *rest, vec3 c,
                                         int32_t id) {
  double farthest = 0;
  for (int32_t i = 0; i < s->n; ++i)
    farthest = fmax(farthest, vec3_norm(vec3_sub(vec3_load(s->x + 3 * i), c)));
  const double size = piola__bounding_diagonal(s->n, rest);
  if (farthest <= INITIAL_EXTENT_LIMIT * size) return PIOLA_OK;
  return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                    "solid %d ('%s'): its initial state (initial.matrix, initial.scramble) puts "
                    "a node %g m from the rest centroid, more than %g times the solid's rest "
                    "size (bounding-box diagonal %g m), where positions cannot hold its shape",
                    (int)id, s->name, farthest, INITIAL_EXTENT_LIMIT, size);
}

/* Everything of a new solid after its slot in the table: the elastic body, the per-node
 * state, constraints, plasticity, the initial state and its forces. */
static piola_status fill_solid(piola_world *world, world_body *s, const piola_solid_def *def,
                               int32_t id) {
  piola_material material;
  if (piola_material_init(&def->material, &material) != PIOLA_OK)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "solid %d: material: %s", (int)id,
                      piola_last_error());
  piola_elastic_body_def bdef = piola_default_elastic_body_def();
  bdef.rest_mesh = def->mesh;
  bdef.materials = &material;
  bdef.material_count = 1;
  bdef.density = def->density;
  bdef.fiber_directions = def->fiber_directions;
  /* a split known now keeps every process to its own blocks' per-tet state (work_split.h) */
  const piola_work_split *split = NULL;
  if (world->split_planner.plan && !def->plasticity && world->def.integrator == PIOLA_INTEGRATOR_NEWMARK)
    PIOLA_TRY(world->split_planner.plan(world->split_planner.context, id, def->mesh, &split));
  piola_status st = split ? piola__elastic_body_create_split(&bdef, split, &s->solid)
                          : piola_elastic_body_create(&bdef, &s->solid);
  if (split && split->reduce) { /* the processes go on together, or not at all */
    double bad = st != PIOLA_OK;
    split->reduce(split->context, &bad, 1, PIOLA_WORK_SPLIT_MAX);
    if (bad > 0 && st == PIOLA_OK) {
      piola_elastic_body_destroy(s->solid);
      st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "solid %d: another process failed to build it", (int)id);
    }
  }
  if (st != PIOLA_OK) {
    s->solid = NULL;
    return st;
  }
  if (world->def.integrator != PIOLA_INTEGRATOR_NEWMARK) piola__elastic_body_drop_step_caches(s->solid);
  int32_t n = piola_elastic_body_vertex_count(s->solid);
  const double *rest = piola_elastic_body_rest_positions(s->solid);
  PIOLA_TRY(piola__body_allocate(s, n, def->name, id, rest, piola_elastic_body_masses(s->solid)));
  s->stiffness_scale = def->stiffness_scale;
  s->shear_viscosity = def->shear_viscosity;
  s->bulk_viscosity = def->bulk_viscosity;
  s->activation = def->activation;
  s->self_collision = def->self_collision;
  PIOLA_TRY(piola__body_apply_constraints(s, rest, def->constraints, def->constraint_count));
  piola__world_check_selections(world, s, rest, def->constraints, def->constraint_count, id);
  PIOLA_TRY(piola__solid_plastic_create(s, def));
  piola__body_finish_masses(s);
  /* initial state: free nodes deformed about the rest centroid, constrained ones at rest */
  vec3 c = {0, 0, 0};
  for (int32_t i = 0; i < n; ++i) c = vec3_add(c, vec3_load(rest + 3 * i));
  if (n > 0) c = vec3_scale(c, 1.0 / n);
  uint64_t rng = def->scramble_seed;
  for (int32_t i = 0; i < n; ++i) {
    if (s->flags[i] != NODE_FREE) {
      piola__body_constrained_state(s, i, world->time, s->x + 3 * i, s->v + 3 * i);
      continue;
    }
    vec3 p = vec3_add(c, mat3_mul_vec(def->initial_matrix, vec3_sub(vec3_load(rest + 3 * i), c)));
    if (def->scramble_radius > 0) p = vec3_add(p, random_in_ball(&rng, def->scramble_radius));
    vec3_store(s->x + 3 * i, p);
    vec3_store(s->v + 3 * i, def->velocity);
  }
  PIOLA_TRY(check_initial_extent(s, rest, c, id));
  PIOLA_TRY(piola__body_update_forces(s, world->time));
  /* the step bound's per-tet weights come from the rest Dm^-1: built now, before plasticity
   * or a checkpoint's restored state changes Dm^-1, so a resumed run uses the same ones */
  (void)solid_state_rate2(s);
  return PIOLA_OK;
}

piola_status piola_world_add_solid(piola_world *world, const piola_solid_def *def, int32_t *index) {
  if (!world || !def) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "add_solid: NULL argument");
  PIOLA_TRY(check_solid_def(def, world->kind_count[PIOLA_BODY_SOLID]));
  int32_t id;
  world_body *s = piola__world_insert_body(world, PIOLA_BODY_SOLID, &id);
  if (!s) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "add_solid: out of memory");
  piola_status st = fill_solid(world, s, def, id);
  if (st != PIOLA_OK) {
    piola__world_drop_body(world, s);
    return st;
  }
  piola__world_check_slivers(world, s);
  /* the setup that reads every tet's Dm^-1 is done: a split solid drops the others' */
  st = piola__elastic_body_split_localize_rest(s->solid);
  if (st != PIOLA_OK) {
    piola__world_drop_body(world, s);
    return st;
  }
  if (index) *index = id;
  return PIOLA_OK;
}

/* ------------------------------------------------------------------ accessors */

int32_t piola_world_solid_count(const piola_world *world) {
  return world ? world->kind_count[PIOLA_BODY_SOLID] : 0;
}

static const world_body *solid_at(const piola_world *w, int32_t i) {
  return piola__world_body_of(w, PIOLA_BODY_SOLID, i);
}

const char *piola_world_solid_name(const piola_world *world, int32_t solid) {
  const world_body *s = solid_at(world, solid);
  return s ? s->name : NULL;
}
const piola_elastic_body *piola_world_solid_body(const piola_world *world, int32_t solid) {
  const world_body *s = solid_at(world, solid);
  return s ? s->solid : NULL;
}
const double *piola_world_solid_positions(const piola_world *world, int32_t solid) {
  const world_body *s = solid_at(world, solid);
  return s ? s->x : NULL;
}
const double *piola_world_solid_velocities(const piola_world *world, int32_t solid) {
  const world_body *s = solid_at(world, solid);
  return s ? s->v : NULL;
}
const uint8_t *piola_world_solid_constraint_flags(const piola_world *world, int32_t solid) {
  const world_body *s = solid_at(world, solid);
  return s ? s->flags : NULL;
}

piola_status piola_world_solid_set_state(piola_world *world, int32_t solid, const double *positions,
                                         const double *velocities) {
  if (!world) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "set_state: NULL world");
  if (!solid_at(world, solid))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "set_state: no solid %d", (int)solid);
  return piola_world_body_set_state(world, piola_world_body_of(world, PIOLA_BODY_SOLID, solid),
                                    positions, velocities);
}

piola_solid_stats piola_world_solid_stats(const piola_world *world, int32_t solid) {
  piola_solid_stats st = {0, 0, 0, 1};
  world_body *s = (world_body *)solid_at(world, solid); /* the stats are a cache */
  if (!s) return st;
  piola_body_stats b = piola__solid_stats(s);
  st.kinetic_energy = b.kinetic_energy;
  st.elastic_energy = b.elastic_energy;
  st.inverted_count = b.inverted_count;
  st.min_det_f = s->elastic.min_det_f;
  return st;
}

piola_status piola_world_solid_set_work_split(piola_world *world, int32_t solid,
                                              const piola_work_split *split) {
  world_body *s = (world_body *)solid_at(world, solid);
  if (!s) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "work split: no solid %d", (int)solid);
  s->product_valid = 0;
  if (split && split->part_count > 1 && world->def.integrator != PIOLA_INTEGRATOR_NEWMARK &&
      !split->solve_newton)
    return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED,
                      "work split: the implicit integrators need a split with solve_newton "
                      "(libpiola_mpi built with PETSc)");
  /* plasticity's return mapping and fracture's criteria read every tet's Fhat (and U) on
   * every process: replicated mode */
  return piola__elastic_body_set_work_split(s->solid, split, s->plastic == NULL && s->fracture == NULL);
}

/* The boundary surface of a solid, built once (rest topology; positions are read live). */
piola_status piola__solid_boundary(world_body *solid) {
  if (solid->boundary) return PIOLA_OK;
  const piola_elastic_body *b = solid->solid;
  piola_tet_mesh tets = {piola_elastic_body_vertex_count(b),
                         (double *)piola_elastic_body_rest_positions(b),
                         piola_elastic_body_tet_count(b),
                         (int32_t *)piola_elastic_body_tets(b),
                         NULL,
                         NULL};
  piola_tri_mesh *surface = calloc(1, sizeof *surface);
  if (!surface) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "solid boundary: out of memory");
  piola_status st = piola_tet_mesh_boundary(&tets, surface);
  if (st != PIOLA_OK) {
    free(surface);
    return st;
  }
  double reach = 0;
  for (int32_t t = 0; t < surface->triangle_count; ++t)
    for (int k = 0; k < 3; ++k) {
      vec3 p = vec3_load(tets.positions + 3 * surface->triangles[3 * t + k]);
      vec3 q = vec3_load(tets.positions + 3 * surface->triangles[3 * t + (k + 1) % 3]);
      reach = fmax(reach, vec3_norm(vec3_sub(p, q)));
    }
  solid->boundary = surface;
  solid->boundary_reach = reach;
  return PIOLA_OK;
}

const piola__bvh *piola__solid_boundary_tree(world_body *solid, int rebuild) {
  const piola_tri_mesh *surface = solid->boundary;
  const int32_t triangles = surface->triangle_count;
  if (!solid->boundary_boxes &&
      !(solid->boundary_boxes =
            malloc(sizeof *solid->boundary_boxes * (size_t)(triangles > 0 ? triangles : 1))))
    return NULL;
  if (!solid->boundary_tree) {
    if (!(solid->boundary_tree = calloc(1, sizeof *solid->boundary_tree))) return NULL;
    rebuild = 1;
  }
  for (int32_t t = 0; t < triangles; ++t) {
    piola__box *box = solid->boundary_boxes + t;
    const double *a = solid->x + 3 * surface->triangles[3 * t],
                 *b = solid->x + 3 * surface->triangles[3 * t + 1],
                 *c = solid->x + 3 * surface->triangles[3 * t + 2];
    for (int k = 0; k < 3; ++k) { /* comparisons, not fmin: a call each without -ffast-math */
      const double lo = a[k] < b[k] ? a[k] : b[k], hi = a[k] < b[k] ? b[k] : a[k];
      box->lo[k] = c[k] < lo ? c[k] : lo;
      box->hi[k] = c[k] > hi ? c[k] : hi;
    }
  }
  if (rebuild) {
    if (piola__bvh_build(solid->boundary_tree, solid->boundary_boxes, triangles) != 0) {
      piola__bvh_free(solid->boundary_tree); /* built again next time */
      free(solid->boundary_tree), solid->boundary_tree = NULL;
      return NULL;
    }
  } else {
    piola__bvh_refit(solid->boundary_tree, solid->boundary_boxes);
  }
  return solid->boundary_tree;
}
