/* Shells in the world: adding them, the shell kind's operations (forces, step bound, stats,
 * the one-way coupling to solids; dispatched by body.c) and the shell accessors. A shell is
 * a world_body of kind PIOLA_BODY_SHELL whose object is a piola_shell_body, so it is stepped
 * by the very same code as a solid (integrator.c): constraints, collisions, the two damping
 * solves and the trapezoidal velocity. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "contact/bvh.h"
#include "contact/proximity.h"
#include "math/mat3.h"
#include "shell/shell_stable_step.h"
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
  def.solid_friction = 0.3;
  def.self_collision = piola_default_solid_def().self_collision;
  return def;
}

piola_status piola__shell_update_forces(world_body *s, double t) {
  double scale = piola_track_eval(&s->stiffness_scale, t);
  s->state_rate_valid = 0;
  return piola_shell_body_update(s->shell, s->x, scale, s->force, &s->shell_stats);
}

/* The state-aware terms of shell s (shell_stable_step.h), computed once per update. */
static void shell_state_rates(const world_body *s) {
  world_body *cache = (world_body *)s; /* a cache of a function of the const state */
  if (cache->state_rate_valid) return;
  cache->state_rate2 = piola__shell_body_membrane_rate2(s->shell, &cache->state_worst_tet);
  cache->state_bending_rate2 = piola__shell_body_bending_rate2(s->shell);
  cache->state_rate_valid = 1;
}

/* The step of shell s: its membrane and bending bounds, each the rest bound or the
 * state-aware one where that is smaller (docs/time-stepping.md, "Step size"). */
double piola__shell_stable_dt(const piola_world *w, const world_body *s, double scale) {
  double dt = INFINITY;
  if (!(scale > 0)) return dt;
  shell_state_rates(s);
  double speed = piola_shell_body_max_wave_speed(s->shell) * sqrt(scale);
  double h = piola_shell_body_min_rest_altitude(s->shell);
  if (speed > 0 && h > 0)
    dt = piola__state_or_rest_step(w->def.cfl * h / speed, w->def.cfl, s->state_rate2 * scale);
  /* bending: explicit, stable up to ~2 sqrt(m/k); cfl in (0, 2] scales it the same way */
  double bending = piola_shell_body_bending_time_scale(s->shell);
  if (isfinite(bending))
    dt = fmin(dt, piola__state_or_rest_step(w->def.cfl * bending / sqrt(scale), w->def.cfl,
                                            s->state_bending_rate2 * scale));
  return dt;
}

static piola_status check_shell_def(const piola_shell_def *def, int32_t id) {
  if (!def->mesh) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "shell %d: mesh is required", (int)id);
  if (!piola__track_ok(&def->stiffness_scale, 0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "shell %d: stiffness_scale must be >= 0", (int)id);
  PIOLA_TRY(piola__check_viscosities("shell", id, &def->shear_viscosity, &def->bulk_viscosity));
  if (!isfinite(def->velocity.x) || !isfinite(def->velocity.y) || !isfinite(def->velocity.z))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "shell %d: velocity must be finite", (int)id);
  if (!(def->solid_friction >= 0) || !isfinite(def->solid_friction))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "shell %d: solid_friction must be >= 0, got %g",
                      (int)id, def->solid_friction);
  const piola_self_collision_def *sc = &def->self_collision;
  if (sc->enabled && (!(sc->thickness > 0) || !isfinite(sc->thickness) || !(sc->friction >= 0) ||
                      !isfinite(sc->friction)))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "shell %d: self_collision needs thickness > 0 m and friction >= 0, got %g, %g",
                      (int)id, sc->thickness, sc->friction);
  return PIOLA_OK;
}

/* Everything of a new shell after its slot in the table: the shell body, the per-node
 * state, constraints, the initial state and its forces. */
static piola_status fill_shell(piola_world *world, world_body *s, const piola_shell_def *def,
                               int32_t id) {
  /* The per-model inversion defaults (piola_material_default_inversion) were chosen from
   * measurements on solids; a shell's membrane keeps LINEAR at 0.3 where its def leaves them
   * unset (docs/shells.md). */
  piola_material_def mdef = def->material;
  if (mdef.inversion_mode == PIOLA_INVERSION_MODEL_DEFAULT) mdef.inversion_mode = PIOLA_INVERSION_LINEAR;
  if (mdef.inversion_threshold == 0.0) mdef.inversion_threshold = 0.3;
  piola_material material;
  if (piola_material_init(&mdef, &material) != PIOLA_OK)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "shell %d: material: %s", (int)id,
                      piola_last_error());
  piola_shell_body_def bdef = piola_default_shell_body_def();
  bdef.rest_mesh = def->mesh;
  bdef.materials = &material;
  bdef.material_count = 1;
  bdef.thickness = def->thickness;
  bdef.density = def->density;
  bdef.bending = def->bending;
  bdef.plasticity = def->plasticity;
  bdef.use_reference_normals = def->use_reference_normals;
  piola_status st = piola_shell_body_create(&bdef, &s->shell);
  if (st != PIOLA_OK) {
    s->shell = NULL;
    return st;
  }
  int32_t n = piola_shell_body_vertex_count(s->shell);
  const double *rest = piola_shell_body_rest_positions(s->shell);
  PIOLA_TRY(piola__body_allocate(s, n, def->name, id, rest, piola_shell_body_masses(s->shell)));
  s->stiffness_scale = def->stiffness_scale;
  s->shear_viscosity = def->shear_viscosity;
  s->bulk_viscosity = def->bulk_viscosity;
  s->collide_with_solids = def->collide_with_solids;
  s->solid_friction = def->solid_friction;
  if (s->collide_with_solids && !(s->solid_surface_v = malloc(3 * (size_t)n * sizeof(double))))
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "shell %d: out of memory", (int)id);
  s->self_collision = def->self_collision;
  PIOLA_TRY(piola__body_apply_constraints(s, rest, def->constraints, def->constraint_count));
  piola__world_check_selections(world, s, rest, def->constraints, def->constraint_count, id);
  piola__body_finish_masses(s);
  for (int32_t i = 0; i < n; ++i) {
    if (s->flags[i] != NODE_FREE) {
      piola__body_constrained_state(s, i, world->time, s->x + 3 * i, s->v + 3 * i);
      continue;
    }
    memcpy(s->x + 3 * i, rest + 3 * i, 3 * sizeof(double));
    s->v[3 * i] = def->velocity.x, s->v[3 * i + 1] = def->velocity.y, s->v[3 * i + 2] = def->velocity.z;
  }
  return piola__body_update_forces(s, world->time);
}

piola_status piola_world_add_shell(piola_world *world, const piola_shell_def *def, int32_t *index) {
  if (!world || !def) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "add_shell: NULL argument");
  PIOLA_TRY(check_shell_def(def, world->kind_count[PIOLA_BODY_SHELL]));
  int32_t id;
  world_body *s = piola__world_insert_body(world, PIOLA_BODY_SHELL, &id);
  if (!s) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "add_shell: out of memory");
  piola_status st = fill_shell(world, s, def, id);
  if (st != PIOLA_OK) {
    piola__world_drop_body(world, s);
    return st;
  }
  if (index) *index = id;
  return PIOLA_OK;
}

static const world_body *shell_at(const piola_world *w, int32_t i) {
  return piola__world_body_of(w, PIOLA_BODY_SHELL, i);
}

int32_t piola_world_shell_count(const piola_world *world) {
  return world ? world->kind_count[PIOLA_BODY_SHELL] : 0;
}
const char *piola_world_shell_name(const piola_world *world, int32_t shell) {
  const world_body *s = shell_at(world, shell);
  return s ? s->name : NULL;
}
const piola_shell_body *piola_world_shell_body(const piola_world *world, int32_t shell) {
  const world_body *s = shell_at(world, shell);
  return s ? s->shell : NULL;
}
const double *piola_world_shell_positions(const piola_world *world, int32_t shell) {
  const world_body *s = shell_at(world, shell);
  return s ? s->x : NULL;
}
const double *piola_world_shell_velocities(const piola_world *world, int32_t shell) {
  const world_body *s = shell_at(world, shell);
  return s ? s->v : NULL;
}
const uint8_t *piola_world_shell_constraint_flags(const piola_world *world, int32_t shell) {
  const world_body *s = shell_at(world, shell);
  return s ? s->flags : NULL;
}

piola_body_stats piola__shell_stats(const world_body *b) {
  piola_body_stats st;
  memset(&st, 0, sizeof st);
  for (int32_t i = 0; i < b->n; ++i) {
    const double *v = b->v + 3 * i;
    st.kinetic_energy += 0.5 * b->mass[i] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; ++k) st.momentum[k] += b->mass[i] * v[k];
  }
  st.elastic_energy = b->shell_stats.membrane_energy + b->shell_stats.bending_energy;
  st.inverted_count = b->shell_stats.inverted_count;
  return st;
}

piola_world_shell_stats piola_world_shell_get_stats(const piola_world *world, int32_t shell) {
  piola_world_shell_stats st;
  memset(&st, 0, sizeof st);
  const world_body *s = shell_at(world, shell);
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

/* ------------------------------------------------------------------ one-way coupling */

int32_t piola__shell_collide_with_solids(piola_world *w, world_body *s, double t1, double dt,
                                         uint8_t mark, double *surface_velocity) {
  (void)t1;
  int32_t moved = 0;
  piola__index_list candidates = {0};
  for (int32_t k = 0; k < w->kind_count[PIOLA_BODY_SOLID]; ++k) {
    world_body *solid = piola__world_body_of(w, PIOLA_BODY_SOLID, k);
    /* both in the collision surface: the two-way contact after the step handles the pair */
    if (s->self_collision.enabled && solid->self_collision.enabled) continue;
    if (piola__solid_boundary(solid) != PIOLA_OK) break;
    const piola__bvh *tree = piola__solid_boundary_tree(solid, 0);
    if (!tree) break;
    if (tree->node_count == 0) continue;
    const piola_tri_mesh *surface = solid->boundary;
    const double *sx = solid->x, *sv = solid->v;
    const double reach = solid->boundary_reach;
    const piola__box *whole = &tree->nodes[0].box;
    for (int32_t i = 0; i < s->n; ++i) {
      if (s->flags[i] != NODE_FREE) continue;
      vec3 x = vec3_load(s->x + 3 * i);
      const piola__box near = piola__box_around(s->x + 3 * i, reach);
      if (!piola__boxes_overlap(&near, whole)) continue;
      candidates.count = 0;
      if (piola__bvh_query(tree, &near, &candidates) != 0) break;
      double best = reach * reach, weights[3] = {0, 0, 0};
      int32_t best_t = -1;
      vec3 best_p = x;
      for (int64_t c = 0; c < candidates.count; ++c) {
        const int32_t t = candidates.items[c], *tri = surface->triangles + 3 * t;
        const vec3 a = vec3_load(sx + 3 * tri[0]), b = vec3_load(sx + 3 * tri[1]),
                   cc = vec3_load(sx + 3 * tri[2]);
        double wt[3];
        const double d2 = piola__point_triangle_closest(x, a, b, cc, wt);
        /* of equally near triangles the first wins, whatever order the tree gives them in */
        if (d2 < best || (d2 == best && t < best_t)) {
          best = d2, best_t = t, weights[0] = wt[0], weights[1] = wt[1], weights[2] = wt[2];
          best_p =
              vec3_add(vec3_add(vec3_scale(a, wt[0]), vec3_scale(b, wt[1])), vec3_scale(cc, wt[2]));
        }
      }
      if (best_t < 0) continue;
      const int32_t *tri = surface->triangles + 3 * best_t;
      vec3 a = vec3_load(sx + 3 * tri[0]), b = vec3_load(sx + 3 * tri[1]), c = vec3_load(sx + 3 * tri[2]);
      vec3 face = vec3_cross(vec3_sub(b, a), vec3_sub(c, a)); /* outward: boundary faces wind outward */
      vec3 d = vec3_sub(x, best_p);
      double side = vec3_dot(d, face);
      /* Inside only when the offset clearly points into the solid. Where the closest point is
       * on an edge or a corner, the offset can be perpendicular to the chosen face's normal
       * (a node right above a vertical side face); side is then a rounding residue of either
       * sign, and reading it as "inside" would drag an outside node onto the edge. */
      if (side >= -1e-9 * vec3_norm(d) * vec3_norm(face)) continue; /* outside (or on) */
      /* the normal: along the node-to-surface direction, pointing outward */
      double dn = vec3_norm(d);
      vec3 normal = dn > 1e-14 * reach ? vec3_scale(d, -1.0 / dn) : vec3_scale(face, 1.0 / vec3_norm(face));
      vec3 vs = vec3_add(vec3_add(vec3_scale(vec3_load(sv + 3 * tri[0]), weights[0]),
                                  vec3_scale(vec3_load(sv + 3 * tri[1]), weights[1])),
                         vec3_scale(vec3_load(sv + 3 * tri[2]), weights[2]));
      vec3 v = vec3_load(s->v + 3 * i);
      vec3 rel = vec3_sub(v, vs);
      double rn = vec3_dot(rel, normal);
      double dvn = rn < 0 ? -rn : 0; /* normal velocity change: take the surface's */
      vec3 vt = vec3_sub(rel, vec3_scale(normal, rn));
      double vtn = vec3_norm(vt), push = dvn + (dt > 0 ? dn / dt : 0);
      double keep = vtn > 0 ? fmax(0.0, 1.0 - s->solid_friction * push / vtn) : 0.0;
      vec3 rel_new = vec3_add(vec3_scale(normal, rn < 0 ? 0.0 : rn), vec3_scale(vt, keep));
      vec3_store(s->v + 3 * i, vec3_add(vs, rel_new));
      vec3_store(s->x + 3 * i, best_p);
      vec3_store(s->normals + 3 * i, normal);
      /* the projection's share of the friction just applied, as obstacles' (integrator.c) */
      s->friction_spent[i] = dt > 0 ? dn / dt : 0.0;
      if (surface_velocity) vec3_store(surface_velocity + 3 * i, vs);
      if (!s->colliding[i]) ++moved;
      s->colliding[i] = mark;
    }
  }
  free(candidates.items);
  return moved;
}
