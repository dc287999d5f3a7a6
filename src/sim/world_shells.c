/* Shells in the world: adding them, the body-kind dispatch of the step loop (forces,
 * damping, step bound) and the shell accessors. A shell is a world_solid whose body is a
 * piola_shell_body, so it is stepped by the very same code as a solid (integrator.c):
 * constraints, collisions, the two damping solves and the trapezoidal velocity. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_internal.h"
#include "sim/world_internal.h"

piola_shell_def piola_default_shell_def(void) {
  piola_shell_def def;
  memset(&def, 0, sizeof def);
  piola_shell_body_def body = piola_default_shell_body_def();
  def.material = piola_default_material_def();
  def.thickness = body.thickness;
  def.density = body.density;
  def.bending = body.bending;
  def.plasticity = body.plasticity;
  def.stiffness_scale.value = 1.0;
  return def;
}

static int track_ok(const piola_track *t) {
  if (t->key_count < 0 || t->key_count > PIOLA_MAX_KEYS) return 0;
  if (t->key_count == 0) return isfinite(t->value) && t->value >= 0;
  for (int32_t k = 0; k < t->key_count; ++k)
    if (!isfinite(t->values[k]) || t->values[k] < 0) return 0;
  return 1;
}

void piola__solid_damping_forces(const world_solid *s, const double *v, double beta,
                                 double alpha, double *out) {
  if (s->shell)
    piola_shell_body_damping_forces(s->shell, v, beta, alpha, out);
  else
    piola_elastic_body_damping_forces(s->body, v, beta, alpha, out);
}

/* A shell with bending damping is damped even with zero in-plane viscosities. */
int piola__solid_undamped(const world_solid *s, double beta, double alpha) {
  if (beta != 0 || alpha != 0) return 0;
  return !s->shell || piola_shell_body_bending_damping(s->shell) == 0;
}

piola_status piola__shell_update_forces(world_solid *s, double t) {
  double scale = piola_track_eval(&s->stiffness_scale, t);
  return piola_shell_body_update(s->shell, s->x, scale, s->force, &s->shell_stats);
}

double piola__shell_stable_dt(const piola_world *w, const world_solid *s, double scale) {
  double dt = INFINITY;
  double speed = piola_shell_body_max_wave_speed(s->shell) * sqrt(scale);
  double h = piola_shell_body_min_rest_altitude(s->shell);
  if (speed > 0 && h > 0) dt = w->def.cfl * h / speed;
  /* bending: explicit, stable up to ~2 sqrt(m/k); cfl in (0, 2] scales it the same way */
  double bending = piola_shell_body_bending_time_scale(s->shell);
  if (scale > 0 && isfinite(bending)) dt = fmin(dt, w->def.cfl * bending / sqrt(scale));
  return dt;
}

piola_status piola_world_add_shell(piola_world *world, const piola_shell_def *def, int32_t *index) {
  if (!world || !def) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "add_shell: NULL argument");
  int32_t id = world->shell_count;
  if (!def->mesh) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "shell %d: mesh is required", (int)id);
  if (!track_ok(&def->stiffness_scale))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "shell %d: stiffness_scale must be >= 0", (int)id);
  if (!track_ok(&def->shear_viscosity) || !track_ok(&def->bulk_viscosity))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "shell %d: viscosities must be >= 0 Pa s", (int)id);
  if (!isfinite(def->velocity.x) || !isfinite(def->velocity.y) || !isfinite(def->velocity.z))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "shell %d: velocity must be finite", (int)id);
  piola_material material;
  PIOLA_TRY(piola_material_init(&def->material, &material));
  piola_shell_body_def bdef = piola_default_shell_body_def();
  bdef.rest_mesh = def->mesh;
  bdef.materials = &material;
  bdef.material_count = 1;
  bdef.thickness = def->thickness;
  bdef.density = def->density;
  bdef.bending = def->bending;
  bdef.plasticity = def->plasticity;
  bdef.use_reference_normals = def->use_reference_normals;

  if (world->shell_count == world->shell_capacity) {
    int32_t cap = world->shell_capacity ? 2 * world->shell_capacity : 4;
    world_solid *grown = realloc(world->shells, (size_t)cap * sizeof *grown);
    if (!grown) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "add_shell: out of memory");
    world->shells = grown;
    world->shell_capacity = cap;
  }
  world_solid *s = &world->shells[id];
  memset(s, 0, sizeof *s);
  piola_status st = piola_shell_body_create(&bdef, &s->shell);
  if (st != PIOLA_OK) {
    s->shell = NULL;
    return st;
  }
  int32_t n = s->n = piola_shell_body_vertex_count(s->shell);
  size_t v3 = 3 * (size_t)n * sizeof(double);
  char fallback[32];
  snprintf(fallback, sizeof fallback, "shell%d", (int)id);
  const char *name = def->name ? def->name : fallback;
  s->name = malloc(strlen(name) + 1);
  s->x = malloc(v3), s->v = malloc(v3), s->force = malloc(v3), s->start = malloc(v3);
  s->mass = malloc((size_t)n * sizeof(double));
  s->inverse_mass = malloc((size_t)n * sizeof(double));
  s->flags = calloc((size_t)n, 1);
  s->motion_of = malloc((size_t)n * sizeof(int32_t));
  s->x_old = malloc(v3), s->v_old = malloc(v3), s->force_old = malloc(v3), s->rhs = malloc(v3);
  s->tmp = malloc(v3), s->work = malloc(4 * v3), s->normals = malloc(v3);
  s->colliding = calloc((size_t)n, 1);
  if (!s->name || !s->x || !s->v || !s->force || !s->start || !s->mass || !s->inverse_mass ||
      !s->flags || !s->motion_of || !s->x_old || !s->v_old || !s->force_old || !s->rhs ||
      !s->tmp || !s->work || !s->normals || !s->colliding) {
    piola__solid_free(s);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "shell %d: out of memory", (int)id);
  }
  strcpy(s->name, name);
  const double *rest = piola_shell_body_rest_positions(s->shell);
  memcpy(s->mass, piola_shell_body_masses(s->shell), (size_t)n * sizeof(double));
  memcpy(s->start, rest, v3);
  for (int32_t i = 0; i < n; ++i) s->motion_of[i] = -1;
  s->stiffness_scale = def->stiffness_scale;
  s->shear_viscosity = def->shear_viscosity;
  s->bulk_viscosity = def->bulk_viscosity;
  st = piola__solid_apply_constraints(s, rest, def->constraints, def->constraint_count);
  if (st != PIOLA_OK) {
    piola__solid_free(s);
    return st;
  }
  for (int32_t i = 0; i < n; ++i) {
    s->inverse_mass[i] = s->mass[i] > 0 ? 1.0 / s->mass[i] : 0.0;
    if (!(s->mass[i] > 0)) s->flags[i] = SOLID_FIXED; /* a vertex in no triangle cannot move */
  }
  for (int32_t i = 0; i < n; ++i) {
    if (s->flags[i] != SOLID_FREE) {
      piola__solid_constrained_state(s, i, world->time, s->x + 3 * i, s->v + 3 * i);
      continue;
    }
    memcpy(s->x + 3 * i, rest + 3 * i, 3 * sizeof(double));
    s->v[3 * i] = def->velocity.x, s->v[3 * i + 1] = def->velocity.y, s->v[3 * i + 2] = def->velocity.z;
  }
  st = piola__solid_update_forces(s, world->time);
  if (st != PIOLA_OK) {
    piola__solid_free(s);
    return st;
  }
  world->shell_count++;
  if (index) *index = id;
  return PIOLA_OK;
}

static const world_solid *shell_at(const piola_world *w, int32_t i) {
  return (w && i >= 0 && i < w->shell_count) ? &w->shells[i] : NULL;
}

int32_t piola_world_shell_count(const piola_world *world) { return world ? world->shell_count : 0; }
const char *piola_world_shell_name(const piola_world *world, int32_t shell) {
  const world_solid *s = shell_at(world, shell);
  return s ? s->name : NULL;
}
const piola_shell_body *piola_world_shell_body(const piola_world *world, int32_t shell) {
  const world_solid *s = shell_at(world, shell);
  return s ? s->shell : NULL;
}
const double *piola_world_shell_positions(const piola_world *world, int32_t shell) {
  const world_solid *s = shell_at(world, shell);
  return s ? s->x : NULL;
}
const double *piola_world_shell_velocities(const piola_world *world, int32_t shell) {
  const world_solid *s = shell_at(world, shell);
  return s ? s->v : NULL;
}
const uint8_t *piola_world_shell_constraint_flags(const piola_world *world, int32_t shell) {
  const world_solid *s = shell_at(world, shell);
  return s ? s->flags : NULL;
}

piola_world_shell_stats piola_world_shell_get_stats(const piola_world *world, int32_t shell) {
  piola_world_shell_stats st;
  memset(&st, 0, sizeof st);
  const world_solid *s = shell_at(world, shell);
  if (!s) return st;
  for (int32_t i = 0; i < s->n; ++i) {
    const double *v = s->v + 3 * i;
    st.kinetic_energy += 0.5 * s->mass[i] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  }
  st.membrane_energy = s->shell_stats.membrane_energy;
  st.bending_energy = s->shell_stats.bending_energy;
  st.inverted_count = s->shell_stats.inverted_count;
  st.degenerate_count = s->shell_stats.degenerate_count;
  return st;
}
