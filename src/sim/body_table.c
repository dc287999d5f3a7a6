/* The world's body table: one array of bodies ordered by kind (every solid, then every
 * shell; each kind in the order added), the slots behind the public ids, and the public
 * accessors of piola/world_bodies.h.
 *
 * Why ordered by kind. The order of the table is the order bodies step in and enter the
 * collision surface, and a shell's one-way coupling reads the solids' positions after they
 * stepped. Keeping solids first makes a scene's result independent of the order of its add
 * calls, as it was when solids and shells had arrays of their own.
 *
 * Why ids. Inserting a solid moves the shells one place on, so a position is not a name
 * for a body. An id is a slot (which records the body's current position) and the slot's
 * generation: a slot freed by a body that is taken out is reused with the next generation,
 * so an old id is refused instead of naming the slot's new body. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "sim/world_internal.h"

static piola_body_id make_id(uint32_t slot, uint32_t generation) {
  return (piola_body_id)generation << 32 | slot;
}

int32_t piola__world_kind_start(const piola_world *w, piola_body_kind kind) {
  int32_t start = 0;
  for (int k = 0; k < (int)kind; ++k) start += w->kind_count[k];
  return start;
}

/* A free slot (position -1, generation kept) or a new one; its index, or -1. */
static int32_t take_slot(piola_world *w) {
  for (int32_t s = 0; s < w->slot_count; ++s)
    if (w->slots[s].position < 0) {
      w->slots[s].generation++;
      return s;
    }
  if (w->slot_count == w->slot_capacity) {
    int32_t cap = w->slot_capacity ? 2 * w->slot_capacity : 8;
    body_slot *grown = realloc(w->slots, (size_t)cap * sizeof *grown);
    if (!grown) return -1;
    w->slots = grown;
    w->slot_capacity = cap;
  }
  w->slots[w->slot_count] = (body_slot){-1, 1};
  return w->slot_count++;
}

/* Tells the slots of bodies [from, body_count) where their bodies are now. */
static void renumber(piola_world *w, int32_t from) {
  for (int32_t p = from; p < w->body_count; ++p) w->slots[w->bodies[p].slot].position = p;
}

world_body *piola__world_insert_body(piola_world *w, piola_body_kind kind, int32_t *index) {
  if (w->body_count == w->body_capacity) {
    int32_t cap = w->body_capacity ? 2 * w->body_capacity : 4;
    world_body *grown = realloc(w->bodies, (size_t)cap * sizeof *grown);
    if (!grown) return NULL;
    w->bodies = grown;
    w->body_capacity = cap;
  }
  int32_t slot = take_slot(w);
  if (slot < 0) return NULL;
  const int32_t at = piola__world_kind_start(w, kind) + w->kind_count[kind];
  memmove(&w->bodies[at + 1], &w->bodies[at], (size_t)(w->body_count - at) * sizeof *w->bodies);
  world_body *b = &w->bodies[at];
  memset(b, 0, sizeof *b);
  b->kind = kind;
  b->slot = (uint32_t)slot;
  *index = w->kind_count[kind];
  w->kind_count[kind]++;
  w->body_count++;
  w->bodies_version++;
  renumber(w, at);
  return b;
}

void piola__world_drop_body(piola_world *w, world_body *b) {
  const int32_t at = (int32_t)(b - w->bodies);
  w->slots[b->slot].position = -1;
  w->kind_count[b->kind]--;
  piola__body_free(b);
  memmove(&w->bodies[at], &w->bodies[at + 1], (size_t)(w->body_count - at - 1) * sizeof *w->bodies);
  w->body_count--;
  w->bodies_version++;
  renumber(w, at);
}

world_body *piola__world_body_of(const piola_world *w, piola_body_kind kind, int32_t index) {
  if (!w || (int)kind < 0 || (int)kind >= PIOLA_BODY_KIND_COUNT || index < 0 ||
      index >= w->kind_count[kind])
    return NULL;
  return &w->bodies[piola__world_kind_start(w, kind) + index];
}

world_body *piola__world_body(const piola_world *w, piola_body_id id) {
  if (!w) return NULL;
  const uint32_t slot = (uint32_t)(id & 0xffffffffu), generation = (uint32_t)(id >> 32);
  if (slot >= (uint32_t)w->slot_count || w->slots[slot].generation != generation ||
      w->slots[slot].position < 0)
    return NULL;
  return &w->bodies[w->slots[slot].position];
}

void piola__world_free_bodies(piola_world *w) {
  for (int32_t i = 0; i < w->body_count; ++i) piola__body_free(&w->bodies[i]);
  free(w->bodies), free(w->slots);
  w->bodies = NULL, w->slots = NULL;
  w->body_count = w->slot_count = 0;
}

/* ------------------------------------------------------------------ public accessors */

int32_t piola_world_body_count(const piola_world *world) { return world ? world->body_count : 0; }

static piola_body_id id_of(const piola_world *w, const world_body *b) {
  return b ? make_id(b->slot, w->slots[b->slot].generation) : PIOLA_NO_BODY;
}

piola_body_id piola_world_body_at(const piola_world *world, int32_t position) {
  if (!world || position < 0 || position >= world->body_count) return PIOLA_NO_BODY;
  return id_of(world, &world->bodies[position]);
}

piola_body_id piola_world_body_of(const piola_world *world, piola_body_kind kind, int32_t index) {
  return id_of(world, piola__world_body_of(world, kind, index));
}

piola_body_kind piola_world_body_kind(const piola_world *world, piola_body_id body) {
  const world_body *b = piola__world_body(world, body);
  return b ? b->kind : PIOLA_BODY_NONE;
}

int32_t piola_world_body_index(const piola_world *world, piola_body_id body) {
  const world_body *b = piola__world_body(world, body);
  if (!b) return -1;
  return (int32_t)(b - world->bodies) - piola__world_kind_start(world, b->kind);
}

const char *piola_world_body_name(const piola_world *world, piola_body_id body) {
  const world_body *b = piola__world_body(world, body);
  return b ? b->name : NULL;
}

int32_t piola_world_body_node_count(const piola_world *world, piola_body_id body) {
  const world_body *b = piola__world_body(world, body);
  return b ? b->n : -1;
}

int32_t piola_world_body_element_count(const piola_world *world, piola_body_id body) {
  const world_body *b = piola__world_body(world, body);
  return b ? piola__body_element_count(b) : -1;
}

const double *piola_world_body_positions(const piola_world *world, piola_body_id body) {
  const world_body *b = piola__world_body(world, body);
  return b ? b->x : NULL;
}

const double *piola_world_body_velocities(const piola_world *world, piola_body_id body) {
  const world_body *b = piola__world_body(world, body);
  return b ? b->v : NULL;
}

const double *piola_world_body_masses(const piola_world *world, piola_body_id body) {
  const world_body *b = piola__world_body(world, body);
  return b ? b->mass : NULL;
}

const uint8_t *piola_world_body_constraint_flags(const piola_world *world, piola_body_id body) {
  const world_body *b = piola__world_body(world, body);
  return b ? b->flags : NULL;
}

piola_status piola_world_body_set_state(piola_world *world, piola_body_id body,
                                        const double *positions, const double *velocities) {
  world_body *b = piola__world_body(world, body);
  if (!b)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "set_state: id %llu names no body",
                      (unsigned long long)body);
  size_t v3 = 3 * (size_t)b->n * sizeof(double);
  if (positions) {
    for (int64_t i = 0; i < 3 * (int64_t)b->n; ++i)
      if (!isfinite(positions[i]))
        return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "set_state: position %lld is not finite",
                          (long long)i);
    memcpy(b->x, positions, v3);
  }
  if (velocities) memcpy(b->v, velocities, v3);
  piola__world_collision_reset(world); /* the open interval's start no longer leads here */
  return piola__body_update_forces(b, world->time);
}

piola_body_stats piola_world_body_stats(const piola_world *world, piola_body_id body) {
  world_body *b = piola__world_body(world, body);
  if (!b) {
    piola_body_stats none;
    memset(&none, 0, sizeof none);
    return none;
  }
  return piola__body_stats(b); /* refreshes a cache, like the body's lazy energy */
}
