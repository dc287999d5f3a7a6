/* The world: creation, solids and obstacles, initial state, accessors and statistics.
 * The time stepping lives in integrator.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "force/elastic_body_internal.h"
#include "math/mat3.h"
#include "sim/world_internal.h"

static int track_ok(const piola_track *t, double lo) {
  if (t->key_count < 0 || t->key_count > PIOLA_MAX_KEYS) return 0;
  if (t->key_count == 0) return isfinite(t->value) && t->value >= lo;
  for (int32_t k = 0; k < t->key_count; ++k)
    if (!isfinite(t->values[k]) || t->values[k] < lo) return 0;
  return 1;
}

/* Every value of a track (checked by track_ok) is at most hi. */
static int track_at_most(const piola_track *t, double hi) {
  if (t->key_count == 0) return t->value <= hi;
  for (int32_t k = 0; k < t->key_count; ++k)
    if (t->values[k] > hi) return 0;
  return 1;
}

piola_status piola_world_create(const piola_world_def *def, piola_world **out) {
  if (!def || !out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "world: NULL argument");
  *out = NULL;
  for (int k = 0; k < 3; ++k)
    if (!track_ok(&def->gravity[k], -INFINITY))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "gravity[%d] must be finite m/s^2", k);
  if (!(def->max_dt > 0) || !isfinite(def->max_dt))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "max_dt must be > 0 s, got %g", def->max_dt);
  if (!(def->cfl > 0 && def->cfl <= 2))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "cfl must be in (0, 2], got %g", def->cfl);
  if (!(def->cg_tolerance > 0) || !isfinite(def->cg_tolerance))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "cg_tolerance must be > 0, got %g",
                      def->cg_tolerance);
  if (def->cg_max_iterations < 1)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "cg_max_iterations must be >= 1, got %d",
                      (int)def->cg_max_iterations);
  if (!(def->collision_interval >= 0) || !isfinite(def->collision_interval))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "collision_interval must be >= 0 s, got %g",
                      def->collision_interval);
  piola_world *w = calloc(1, sizeof *w);
  if (!w) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "world: out of memory");
  w->def = *def;
  w->collision_deadline = NAN;
  *out = w;
  return PIOLA_OK;
}

void piola__solid_free(world_solid *s) {
  free(s->name);
  piola_plastic_state_destroy(s->plastic);
  piola_elastic_body_destroy(s->body);
  piola_shell_body_destroy(s->shell);
  if (s->boundary) piola_tri_mesh_free(s->boundary);
  free(s->boundary);
  free(s->x), free(s->v), free(s->mass), free(s->inverse_mass), free(s->force), free(s->start), free(s->flags);
  free(s->motion_of), free(s->motions);
  free(s->x_old), free(s->v_old), free(s->force_old), free(s->rhs), free(s->work), free(s->tmp);
  free(s->av_product), free(s->v_product);
  free(s->colliding), free(s->normals);
  memset(s, 0, sizeof *s);
}

void piola_world_destroy(piola_world *world) {
  if (!world) return;
  for (int32_t i = 0; i < world->solid_count; ++i) piola__solid_free(&world->solids[i]);
  for (int32_t i = 0; i < world->shell_count; ++i) piola__solid_free(&world->shells[i]);
  free(world->shells);
  for (int32_t i = 0; i < world->obstacle_count; ++i) piola_obstacle_destroy(world->obstacles[i]);
  piola__world_contact_free(world);
  free(world->solids);
  free(world->obstacles);
  free(world);
}

/* Without stats: the energy goes through the scalar material function per tet, which cost
 * more than the whole vectorized force loop (measured 10 ms against 8.5 ms per update on
 * the 97,878-tet torus, one thread) and stepping does not need it. piola_world_solid_stats
 * computes it from the update's per-tet state when asked (once per frame in `piola run`). */
piola_status piola__solid_update_forces(world_solid *s, double t) {
  if (s->shell) return piola__shell_update_forces(s, t);
  double scale = piola_track_eval(&s->stiffness_scale, t);
  piola_elastic_body_set_activation(s->body, piola_track_eval(&s->activation, t));
  s->elastic_stale = 1;
  return piola_elastic_body_update(s->body, s->x, scale, s->force, NULL);
}

/* The elastic statistics of the last update, from its per-tet state (energy density lazily
 * by the body), summed serially in tet order. */
static void refresh_elastic_stats(world_solid *s) {
  if (!s->body || !s->elastic_stale) return;
  const piola_elastic_body *b = s->body;
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

/* One more zeroed slot at the end of a world_solid array (solids or shells), growing it. */
world_solid *piola__world_new_slot(world_solid **items, int32_t count, int32_t *capacity) {
  if (count == *capacity) {
    int32_t cap = *capacity ? 2 * *capacity : 4;
    world_solid *grown = realloc(*items, (size_t)cap * sizeof *grown);
    if (!grown) return NULL;
    *items = grown;
    *capacity = cap;
  }
  world_solid *s = &(*items)[count];
  memset(s, 0, sizeof *s);
  return s;
}

piola_status piola__solid_allocate(world_solid *s, int32_t n, const char *name, const char *kind,
                                   int32_t id, const double *rest, const double *mass) {
  s->n = n;
  size_t v3 = 3 * (size_t)n * sizeof(double);
  char fallback[32];
  snprintf(fallback, sizeof fallback, "%s%d", kind, (int)id);
  if (!name) name = fallback;
  s->name = malloc(strlen(name) + 1);
  s->x = malloc(v3), s->v = malloc(v3), s->force = malloc(v3), s->start = malloc(v3);
  s->mass = malloc((size_t)n * sizeof(double));
  s->inverse_mass = malloc((size_t)n * sizeof(double));
  s->flags = calloc((size_t)n, 1);
  s->motion_of = malloc((size_t)n * sizeof(int32_t));
  s->x_old = malloc(v3), s->v_old = malloc(v3), s->force_old = malloc(v3), s->rhs = malloc(v3);
  s->tmp = malloc(v3), s->work = malloc(4 * v3) /* CG's 3 vectors + the first solve's A x0 */, s->normals = malloc(v3);
  s->av_product = malloc(v3), s->v_product = malloc(v3);
  s->colliding = calloc((size_t)n, 1);
  if (!s->av_product || !s->v_product || !s->name || !s->x || !s->v || !s->force || !s->start || !s->mass || !s->inverse_mass || !s->flags ||
      !s->motion_of || !s->x_old || !s->v_old || !s->force_old || !s->rhs || !s->tmp || !s->work ||
      !s->normals || !s->colliding)
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s %d: out of memory", kind, (int)id);
  strcpy(s->name, name);
  memcpy(s->mass, mass, (size_t)n * sizeof(double));
  memcpy(s->start, rest, v3);
  for (int32_t i = 0; i < n; ++i) s->motion_of[i] = -1;
  return PIOLA_OK;
}

void piola__solid_finish_masses(world_solid *s) {
  for (int32_t i = 0; i < s->n; ++i) {
    s->inverse_mass[i] = s->mass[i] > 0 ? 1.0 / s->mass[i] : 0.0;
    if (!(s->mass[i] > 0)) s->flags[i] = SOLID_FIXED; /* a vertex in no element cannot move */
  }
}

piola_status piola_world_add_solid(piola_world *world, const piola_solid_def *def, int32_t *index) {
  if (!world || !def) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "add_solid: NULL argument");
  int32_t id = world->solid_count;
  if (!def->mesh) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "solid %d: mesh is required", (int)id);
  if (!(def->density > 0) || !isfinite(def->density))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "solid %d: density must be > 0 kg/m^3, got %g",
                      (int)id, def->density);
  if (!track_ok(&def->stiffness_scale, 0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "solid %d: stiffness_scale must be >= 0", (int)id);
  if (!track_ok(&def->shear_viscosity, 0) || !track_ok(&def->bulk_viscosity, 0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "solid %d: viscosities must be >= 0 Pa s", (int)id);
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
  if (!track_ok(&def->activation, 0) || !track_at_most(&def->activation, 1))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "solid %d: activation must be in [0, 1]", (int)id);
  if (def->fiber_directions && def->plasticity)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "solid %d: fiber directions cannot be combined with plasticity (not supported)",
                      (int)id);

  piola_material material;
  PIOLA_TRY(piola_material_init(&def->material, &material));
  piola_elastic_body_def bdef = piola_default_elastic_body_def();
  bdef.rest_mesh = def->mesh;
  bdef.materials = &material;
  bdef.material_count = 1;
  bdef.density = def->density;
  bdef.fiber_directions = def->fiber_directions;

  world_solid *s = piola__world_new_slot(&world->solids, world->solid_count, &world->solid_capacity);
  if (!s) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "add_solid: out of memory");
  piola_status st = piola_elastic_body_create(&bdef, &s->body);
  if (st != PIOLA_OK) {
    s->body = NULL;
    return st;
  }
  int32_t n = piola_elastic_body_vertex_count(s->body);
  const double *rest = piola_elastic_body_rest_positions(s->body);
  st = piola__solid_allocate(s, n, def->name, "solid", id, rest, piola_elastic_body_masses(s->body));
  if (st != PIOLA_OK) {
    piola__solid_free(s);
    return st;
  }
  s->stiffness_scale = def->stiffness_scale;
  s->shear_viscosity = def->shear_viscosity;
  s->bulk_viscosity = def->bulk_viscosity;
  s->activation = def->activation;
  s->self_collision = def->self_collision;
  st = piola__solid_apply_constraints(s, rest, def->constraints, def->constraint_count);
  if (st == PIOLA_OK) st = piola__solid_plastic_create(s, def);
  if (st != PIOLA_OK) {
    piola__solid_free(s);
    return st;
  }
  piola__solid_finish_masses(s);
  /* initial state: free nodes deformed about the rest centroid, constrained ones at rest */
  vec3 c = {0, 0, 0};
  for (int32_t i = 0; i < n; ++i) c = vec3_add(c, vec3_load(rest + 3 * i));
  if (n > 0) c = vec3_scale(c, 1.0 / n);
  uint64_t rng = def->scramble_seed;
  for (int32_t i = 0; i < n; ++i) {
    if (s->flags[i] != SOLID_FREE) {
      piola__solid_constrained_state(s, i, world->time, s->x + 3 * i, s->v + 3 * i);
      continue;
    }
    vec3 p = vec3_add(c, mat3_mul_vec(def->initial_matrix, vec3_sub(vec3_load(rest + 3 * i), c)));
    if (def->scramble_radius > 0) p = vec3_add(p, random_in_ball(&rng, def->scramble_radius));
    vec3_store(s->x + 3 * i, p);
    vec3_store(s->v + 3 * i, def->velocity);
  }
  st = piola__solid_update_forces(s, world->time);
  if (st != PIOLA_OK) {
    piola__solid_free(s);
    return st;
  }
  world->solid_count++;
  if (index) *index = id;
  return PIOLA_OK;
}

piola_status piola_world_add_obstacle(piola_world *world, const piola_obstacle_def *def,
                                      int32_t *index) {
  if (!world || !def) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "add_obstacle: NULL argument");
  if (world->obstacle_count == world->obstacle_capacity) {
    int32_t cap = world->obstacle_capacity ? 2 * world->obstacle_capacity : 4;
    piola_obstacle **grown = realloc(world->obstacles, (size_t)cap * sizeof *grown);
    if (!grown) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "add_obstacle: out of memory");
    world->obstacles = grown;
    world->obstacle_capacity = cap;
  }
  piola_obstacle *o = NULL;
  PIOLA_TRY(piola_obstacle_create(def, &o));
  world->obstacles[world->obstacle_count] = o;
  if (index) *index = world->obstacle_count;
  world->obstacle_count++;
  return PIOLA_OK;
}

double piola_world_time(const piola_world *world) { return world->time; }
int32_t piola_world_solid_count(const piola_world *world) { return world->solid_count; }
int32_t piola_world_obstacle_count(const piola_world *world) { return world->obstacle_count; }

static const world_solid *solid_at(const piola_world *w, int32_t i) {
  return (i >= 0 && i < w->solid_count) ? &w->solids[i] : NULL;
}

const char *piola_world_solid_name(const piola_world *world, int32_t solid) {
  const world_solid *s = solid_at(world, solid);
  return s ? s->name : NULL;
}
const piola_elastic_body *piola_world_solid_body(const piola_world *world, int32_t solid) {
  const world_solid *s = solid_at(world, solid);
  return s ? s->body : NULL;
}
const double *piola_world_solid_positions(const piola_world *world, int32_t solid) {
  const world_solid *s = solid_at(world, solid);
  return s ? s->x : NULL;
}
const double *piola_world_solid_velocities(const piola_world *world, int32_t solid) {
  const world_solid *s = solid_at(world, solid);
  return s ? s->v : NULL;
}
const uint8_t *piola_world_solid_constraint_flags(const piola_world *world, int32_t solid) {
  const world_solid *s = solid_at(world, solid);
  return s ? s->flags : NULL;
}

piola_status piola_world_solid_set_state(piola_world *world, int32_t solid, const double *positions,
                                         const double *velocities) {
  if (!world || solid < 0 || solid >= world->solid_count)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "set_state: no solid %d", (int)solid);
  world_solid *s = &world->solids[solid];
  size_t v3 = 3 * (size_t)s->n * sizeof(double);
  if (positions) {
    for (int64_t i = 0; i < 3 * (int64_t)s->n; ++i)
      if (!isfinite(positions[i]))
        return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "set_state: position %lld is not finite",
                          (long long)i);
    memcpy(s->x, positions, v3);
  }
  if (velocities) memcpy(s->v, velocities, v3);
  piola__world_collision_reset(world); /* the open interval's start no longer leads here */
  return piola__solid_update_forces(s, world->time);
}

piola_solid_stats piola_world_solid_stats(const piola_world *world, int32_t solid) {
  piola_solid_stats st = {0, 0, 0, 1};
  const world_solid *s = solid_at(world, solid);
  if (!s) return st;
  refresh_elastic_stats((world_solid *)s); /* a cache, like the body's lazy energy */
  double ke = 0;
  for (int32_t i = 0; i < s->n; ++i) {
    const double *v = s->v + 3 * i;
    ke += 0.5 * s->mass[i] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  }
  st.kinetic_energy = ke;
  st.elastic_energy = s->elastic.elastic_energy;
  st.inverted_count = s->elastic.inverted_count;
  st.min_det_f = s->elastic.min_det_f;
  return st;
}
