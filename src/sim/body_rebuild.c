/* Bodies that change between steps: the one path that gives a body a new mesh (other node
 * and element counts) and rebuilds everything that was sized or derived from the old one.
 *
 * What depends on a body's mesh, and where it is rebuilt here:
 *  - the kind's object: for a solid the elastic body (its padded SoA layout, incidence,
 *    masses, damping pattern and matrix, which are assembled lazily from it) is created
 *    anew from the new rest mesh, with the old one's materials and fibres per element;
 *  - the plastic state: created from the old one, each new tet inheriting Fp, accumulated
 *    strain and control goal of its parent tet (piola_plastic_state_create_from);
 *  - the per-node state and scratch (body.h): allocated for the new node count; positions
 *    and velocities from the caller, constraint flags and driving motions from each new
 *    node's parent node, start positions = the new rest positions, masses from the new
 *    elastic body; the damping product kept between steps is dropped;
 *  - the collision surfaces: the solid's cached boundary (one-way coupling of shells) is
 *    dropped and rebuilt on use, the world's collision surface is rebuilt before the next
 *    contact processing (bodies_version), and an open collision interval restarts;
 *  - the elastic force at the new positions, as after any change of state.
 * The new body is built aside and swapped in only when everything succeeded, so a failure
 * leaves the world as it was. The body keeps its id, name, position in the table and its
 * per-body parameters (stiffness scale, viscosities, activation, self-collision). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "force/elastic_body_internal.h"
#include "sim/world_internal.h"

static piola_status check_change(const world_body *b, const body_change *c, int32_t n,
                                 int32_t elements, int32_t old_elements) {
  if (!c->x || !c->v)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "rebuild of '%s': positions and velocities are required",
                      b->name);
  for (int64_t i = 0; i < 3 * (int64_t)n; ++i)
    if (!isfinite(c->x[i]) || !isfinite(c->v[i]))
      return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "rebuild of '%s': node %lld's state is not finite",
                        b->name, (long long)(i / 3));
  if (c->node_parent)
    for (int32_t i = 0; i < n; ++i)
      if (c->node_parent[i] < -1 || c->node_parent[i] >= b->n)
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                          "rebuild of '%s': node %d has parent %d, outside [-1, %d)", b->name, (int)i,
                          (int)c->node_parent[i], (int)b->n);
  if (c->element_parent)
    for (int32_t e = 0; e < elements; ++e)
      if (c->element_parent[e] < -1 || c->element_parent[e] >= old_elements)
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                          "rebuild of '%s': element %d has parent %d, outside [-1, %d)", b->name,
                          (int)e, (int)c->element_parent[e], (int)old_elements);
  return PIOLA_OK;
}

/* The new elastic body and plastic state of solid b, from the new rest mesh and the
 * element parents (materials, fibres, plastic state per tet). */
static piola_status rebuild_solid_object(const world_body *b, const body_change *c, world_body *nb) {
  const piola_elastic_body *old = b->solid;
  const int32_t nt = c->solid_rest->tet_count;
  const int32_t *parent = c->element_parent;
  const double *old_fibers = piola_elastic_body_fiber_directions(old);
  if (old_fibers && !parent)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "rebuild of '%s': a solid with fibres needs element parents", b->name);
  int32_t *materials = malloc(sizeof(int32_t) * (size_t)(nt > 0 ? nt : 1));
  double *fibers = old_fibers ? malloc(3 * sizeof(double) * (size_t)(nt > 0 ? nt : 1)) : NULL;
  if (!materials || (old_fibers && !fibers)) {
    free(materials), free(fibers);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "rebuild of '%s': out of memory", b->name);
  }
  piola_status st = PIOLA_OK;
  for (int32_t t = 0; t < nt && st == PIOLA_OK; ++t) {
    const int32_t p = parent ? parent[t] : -1;
    materials[t] = p >= 0 ? old->tet_material[p] : 0;
    if (fibers && p < 0)
      st = PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "rebuild of '%s': tet %d has no parent to take its fibre direction from",
                      b->name, (int)t);
    else if (fibers)
      memcpy(fibers + 3 * t, old_fibers + 3 * (size_t)p, 3 * sizeof(double));
  }
  if (st == PIOLA_OK) {
    piola_elastic_body_def def = piola_default_elastic_body_def();
    def.rest_mesh = c->solid_rest;
    def.materials = old->materials;
    def.material_count = old->material_count;
    def.tet_materials = materials;
    def.density = old->density;
    def.fiber_directions = fibers;
    def.material_fractions = c->element_fraction;
    st = piola_elastic_body_create(&def, &nb->solid);
    if (st != PIOLA_OK) nb->solid = NULL;
  }
  free(materials), free(fibers);
  if (st != PIOLA_OK || !b->plastic) return st;
  int32_t *fresh = NULL;
  if (!parent) {
    fresh = malloc(sizeof(int32_t) * (size_t)(nt > 0 ? nt : 1));
    if (!fresh) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "rebuild of '%s': out of memory", b->name);
    for (int32_t t = 0; t < nt; ++t) fresh[t] = -1;
  }
  st = piola_plastic_state_create_from(nb->solid, b->plastic, parent ? parent : fresh, &nb->plastic);
  free(fresh);
  if (st != PIOLA_OK) return PIOLA_FAIL(st, "rebuild of '%s': %s", b->name, piola_last_error());
  nb->plastic_stats = b->plastic_stats; /* its bound on Fp^-1 still holds: Fp were copied */
  return PIOLA_OK;
}

/* Builds the whole new body in nb (zeroed, kind set). */
static piola_status build_new(piola_world *w, const world_body *b, const body_change *c,
                              world_body *nb) {
  int32_t n = 0;
  const double *rest = NULL, *mass = NULL;
  switch (b->kind) {
    case PIOLA_BODY_SOLID:
      if (!c->solid_rest)
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "rebuild of solid '%s': no tet mesh", b->name);
      PIOLA_TRY(check_change(b, c, c->solid_rest->vertex_count, c->solid_rest->tet_count,
                             piola__body_element_count(b)));
      PIOLA_TRY(rebuild_solid_object(b, c, nb));
      if (w->def.integrator != PIOLA_INTEGRATOR_NEWMARK) piola__elastic_body_drop_step_caches(nb->solid);
      n = piola_elastic_body_vertex_count(nb->solid);
      rest = piola_elastic_body_rest_positions(nb->solid);
      mass = piola_elastic_body_masses(nb->solid);
      nb->activation = b->activation;
      break;
    case PIOLA_BODY_SHELL:
    case PIOLA_BODY_NONE:
      return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED,
                        "rebuild of %s '%s': only solids can change their mesh", piola__body_kind_name(b->kind),
                        b->name);
  }
  PIOLA_TRY(piola__body_allocate(nb, n, b->name, 0, rest, mass));
  nb->stiffness_scale = b->stiffness_scale;
  nb->shear_viscosity = b->shear_viscosity;
  nb->bulk_viscosity = b->bulk_viscosity;
  nb->self_collision = b->self_collision;
  if (b->motion_count > 0) {
    nb->motions = malloc(sizeof *nb->motions * (size_t)b->motion_count);
    if (!nb->motions) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "rebuild of '%s': out of memory", b->name);
    memcpy(nb->motions, b->motions, sizeof *nb->motions * (size_t)b->motion_count);
    nb->motion_count = b->motion_count;
  }
  for (int32_t i = 0; i < n; ++i) {
    const int32_t p = c->node_parent ? c->node_parent[i] : -1;
    nb->flags[i] = p >= 0 ? b->flags[p] : NODE_FREE;
    nb->motion_of[i] = p >= 0 ? b->motion_of[p] : -1;
  }
  /* a parent held only because it had no mass is not a constraint to inherit */
  for (int32_t i = 0; i < n; ++i) {
    const int32_t p = c->node_parent ? c->node_parent[i] : -1;
    if (p >= 0 && nb->flags[i] == NODE_FIXED && !(b->mass[p] > 0)) nb->flags[i] = NODE_FREE;
  }
  piola__body_finish_masses(nb);
  memcpy(nb->x, c->x, 3 * sizeof(double) * (size_t)n);
  memcpy(nb->v, c->v, 3 * sizeof(double) * (size_t)n);
  for (int32_t i = 0; i < n; ++i)
    if (nb->flags[i] != NODE_FREE) piola__body_constrained_state(nb, i, w->time, nb->x + 3 * i, nb->v + 3 * i);
  return piola__body_update_forces(nb, w->time);
}

/* The split of rebuilt solid b for its new mesh (work_split.h,
 * piola_world_set_work_split_replanner): its old body, split, is gone, or b is whole. */
piola_status piola__body_resplit(piola_world *w, world_body *b) {
  if (!w->split_replanner.plan) return PIOLA_OK; /* whole on every process */
  int32_t solid = 0;
  while (piola__world_body_of(w, PIOLA_BODY_SOLID, solid) != b) solid++;
  piola_tet_mesh mesh = {.vertex_count = piola_elastic_body_vertex_count(b->solid),
                         .positions = (double *)piola_elastic_body_rest_positions(b->solid),
                         .tet_count = piola_elastic_body_tet_count(b->solid),
                         .tets = (int32_t *)piola_elastic_body_tets(b->solid)};
  const piola_work_split *split = NULL;
  PIOLA_TRY(w->split_replanner.plan(w->split_replanner.context, solid, &mesh, &split));
  b->product_valid = 0;
  return split ? piola__elastic_body_set_work_split(b->solid, split, 0) : PIOLA_OK;
}

piola_status piola__body_rebuild(piola_world *w, world_body *b, const body_change *change) {
  if (!w || !b || !change) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "rebuild: NULL argument");
  const piola_work_split *split = b->kind == PIOLA_BODY_SOLID ? b->solid->split : NULL;
  const int was_split = b->split_pending || (split && split->part_count > 1);
  /* the process and process count the body was split for, kept while its replan waits */
  const uint32_t pending = b->split_pending ? b->split_pending
                           : was_split ? (uint32_t)split->part_count << 16 | (uint32_t)split->part : 0;
  world_body nb;
  memset(&nb, 0, sizeof nb);
  nb.kind = b->kind;
  piola_status st = build_new(w, b, change, &nb);
  if (st != PIOLA_OK) {
    piola__body_free(&nb);
    return st;
  }
  nb.slot = b->slot;
  nb.fracture = b->fracture; /* the caller updates it to the new mesh */
  b->fracture = NULL;
  piola__body_free(b);
  *b = nb;
  w->bodies_version++;           /* the world's collision surface is rebuilt on next use */
  piola__world_collision_reset(w); /* an open interval's start positions are of the old mesh */
  if (!was_split) return PIOLA_OK;
  if (w->split_replans_deferred) { /* whole on this process for now, no collective step */
    b->split_pending = pending;
    return PIOLA_OK;
  }
  return piola__body_resplit(w, b);
}
