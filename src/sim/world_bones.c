/* Bones: an obstacle plus driven constraints that share its motion (piola/world_bones.h,
 * docs/bones.md). No new stepping code: the step loop already keeps free nodes out of
 * obstacles and moves driven nodes along their motion, and a driven node is never projected
 * by an obstacle, so attached nodes are naturally left out of their own bone's collisions.
 *
 * Adding is done in two passes so that a bad attachment leaves the world untouched: the
 * first validates every attachment and counts its nodes, the second (after every
 * allocation has succeeded) marks the nodes and moves them onto the bone. */
#include "piola/world_bones.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "math/mat3.h"
#include "sim/obstacle_internal.h"
#include "sim/world_internal.h"

piola_attachment_def piola_default_attachment_def(void) {
  piola_attachment_def def;
  memset(&def, 0, sizeof def);
  def.selector.type = PIOLA_SELECT_INDICES;
  return def;
}

piola_bone_def piola_default_bone_def(void) {
  piola_bone_def def;
  memset(&def, 0, sizeof def);
  def.shape = piola_default_obstacle_def();
  return def;
}

/* Whether node i (rest position p) of the solid is picked by attachment a of bone o. */
static int attachment_picks(const piola_attachment_def *a, const piola_obstacle *o,
                            const piola__rigid_state *rest_pose, const double *p) {
  if (a->near_surface)
    return piola__obstacle_distance_posed(o, rest_pose, vec3_load(p), NULL, NULL) <= a->distance;
  return piola__selector_contains(&a->selector, p);
}

/* Validates attachment k and counts the nodes it picks. */
static piola_status check_attachment(const piola_world *w, const piola_attachment_def *a, int32_t k,
                                     const piola_obstacle *o, const piola__rigid_state *rest_pose,
                                     int32_t *count) {
  const world_body *s = piola__world_body_of(w, PIOLA_BODY_SOLID, a->solid);
  if (!s)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "attachments[%d]: solid %d does not exist (the world has %d solids)", (int)k,
                      (int)a->solid, (int)w->kind_count[PIOLA_BODY_SOLID]);
  const piola_selector *sel = &a->selector;
  int32_t n = 0;
  if (a->near_surface) {
    if (!(a->distance >= 0) || !isfinite(a->distance))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "attachments[%d]: distance must be finite and >= 0 m, got %g", (int)k,
                        a->distance);
  } else if (sel->type == PIOLA_SELECT_INDICES) {
    if (sel->index_count < 0 || (sel->index_count > 0 && !sel->indices))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "attachments[%d]: indices missing", (int)k);
    for (int32_t j = 0; j < sel->index_count; ++j)
      if (sel->indices[j] < 0 || sel->indices[j] >= s->n)
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                          "attachments[%d].indices[%d]: vertex %d is out of range [0, %d) of solid '%s'",
                          (int)k, (int)j, (int)sel->indices[j], (int)s->n, s->name);
    n = sel->index_count;
  } else if (sel->type == PIOLA_SELECT_SPHERE) {
    if (!(sel->radius >= 0) || !isfinite(sel->radius))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "attachments[%d]: sphere radius must be finite and >= 0 m, got %g", (int)k,
                        sel->radius);
  } else if (sel->type != PIOLA_SELECT_BOX) {
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "attachments[%d]: unknown selector type %d",
                      (int)k, (int)sel->type);
  }
  if (a->near_surface || sel->type != PIOLA_SELECT_INDICES)
    for (int32_t i = 0; i < s->n; ++i) n += attachment_picks(a, o, rest_pose, s->start + 3 * i);
  if (n == 0)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "attachments[%d]: selects no node of solid '%s'%s", (int)k, s->name,
                      a->near_surface ? " (no rest position is within the distance of the bone)"
                                      : "");
  *count = n;
  return PIOLA_OK;
}

static void drive(world_body *s, int32_t i, int32_t motion, double t) {
  s->flags[i] = NODE_DRIVEN;
  s->motion_of[i] = motion;
  piola__body_constrained_state(s, i, t, s->x + 3 * i, s->v + 3 * i);
}

static void attach(world_body *s, const piola_attachment_def *a, const piola_obstacle *o,
                   const piola__rigid_state *rest_pose, double t) {
  int32_t m = s->motion_count++;
  s->motions[m] = o->motion; /* validated: the bone's surface and its nodes share one pose */
  const piola_selector *sel = &a->selector;
  if (!a->near_surface && sel->type == PIOLA_SELECT_INDICES) {
    for (int32_t j = 0; j < sel->index_count; ++j) drive(s, sel->indices[j], m, t);
    return;
  }
  for (int32_t i = 0; i < s->n; ++i)
    if (attachment_picks(a, o, rest_pose, s->start + 3 * i)) drive(s, i, m, t);
}

piola_status piola_world_add_bone(piola_world *world, const piola_bone_def *def,
                                  int32_t *obstacle_index, int32_t *attached_counts) {
  if (!world || !def) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "add_bone: NULL argument");
  if (def->attachment_count < 0 || (def->attachment_count > 0 && !def->attachments))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "add_bone: bad attachment count %d",
                      (int)def->attachment_count);
  piola_obstacle *o = NULL;
  PIOLA_TRY(piola_obstacle_create(&def->shape, &o));
  /* the shape as given, before its motion: attachments by distance are measured there */
  piola__rigid_state rest_pose;
  memset(&rest_pose, 0, sizeof rest_pose);
  rest_pose.rotation = mat3_identity();
  piola_status st = PIOLA_OK;
  for (int32_t k = 0; k < def->attachment_count && st == PIOLA_OK; ++k) {
    int32_t count = 0;
    st = check_attachment(world, &def->attachments[k], k, o, &rest_pose, &count);
    if (st == PIOLA_OK && attached_counts) attached_counts[k] = count;
  }
  /* room for the obstacle and for one more motion per attachment */
  if (st == PIOLA_OK && world->obstacle_count == world->obstacle_capacity) {
    int32_t cap = world->obstacle_capacity ? 2 * world->obstacle_capacity : 4;
    piola_obstacle **grown = realloc(world->obstacles, (size_t)cap * sizeof *grown);
    if (grown) {
      world->obstacles = grown;
      world->obstacle_capacity = cap;
    } else {
      st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "add_bone: out of memory");
    }
  }
  for (int32_t k = 0; k < def->attachment_count && st == PIOLA_OK; ++k) {
    world_body *s = piola__world_body_of(world, PIOLA_BODY_SOLID, def->attachments[k].solid);
    int32_t more = 0;
    for (int32_t j = 0; j < def->attachment_count; ++j)
      more += def->attachments[j].solid == def->attachments[k].solid;
    /* grown once per solid, by every attachment to it; extra room is harmless */
    piola_rigid_motion_def *grown =
        realloc(s->motions, (size_t)(s->motion_count + more) * sizeof *grown);
    if (grown)
      s->motions = grown;
    else
      st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "add_bone: out of memory");
  }
  if (st != PIOLA_OK) {
    piola_obstacle_destroy(o);
    return st;
  }
  for (int32_t k = 0; k < def->attachment_count; ++k)
    attach(piola__world_body_of(world, PIOLA_BODY_SOLID, def->attachments[k].solid), &def->attachments[k], o, &rest_pose,
           world->time);
  world->obstacles[world->obstacle_count] = o;
  if (obstacle_index) *obstacle_index = world->obstacle_count;
  world->obstacle_count++;
  /* the attached nodes moved onto the bone: the forces must belong to the new positions */
  for (int32_t k = 0; k < def->attachment_count; ++k) {
    int32_t solid = def->attachments[k].solid;
    int done = 0;
    for (int32_t j = 0; j < k; ++j) done |= def->attachments[j].solid == solid;
    if (!done) PIOLA_TRY(piola__body_update_forces(piola__world_body_of(world, PIOLA_BODY_SOLID, solid), world->time));
  }
  return PIOLA_OK;
}
