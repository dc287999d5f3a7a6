/* Contact between solids inside an implicit step (docs/time-stepping.md, "Solids against
 * each other inside the solve").
 *
 * The collision pass between bodies (contact.md) runs after the Newton solves; at a
 * frame-sized step it moves surface nodes by up to a frame's fall, and the solve after it
 * has to hold both sides where the pass put them, which fixes a dent no force balances (a
 * box dropped onto a box reached 19.5 J). So a solid with self_collision takes the other such
 * solids' boundary surfaces into its own Newton solve, like obstacles: a free node inside
 * another solid's surface, or within the pair's thickness of it, is put outside it and held
 * along the surface's normal, released when the hold would pull, with the surface's velocity
 * and the pair's mean coefficient for friction. Bodies are solved in the world's order, so
 * the other solid is at its step's end when it was solved before this one and at its start
 * otherwise; the later of the two keeps the gap, the earlier only stays out. The pass then
 * finds the surfaces apart where the solves saw the contact. */
#include <math.h>
#include <stdlib.h>

#include "common/status_report.h"
#include "contact/bvh.h"
#include "contact/proximity.h"
#include "sim/implicit_split.h"
#include "sim/solid_contacts.h"

/* The held distance, as a multiple of the pair's thickness: a little beyond it, so that the
 * collision pass's proximity test (closer than the thickness) does not act on a pair the
 * solve has already put apart */
#define HELD_GAP 1.1

/* Whether solid b takes part: self_collision on, whole on this process, not cut (its boundary
 * changes), not waiting to untangle. */
static int takes_part(const world_body *b) {
  return b->kind == PIOLA_BODY_SOLID && b->self_collision.enabled && !b->fracture &&
         !b->collision_waits && !piola__implicit_split_of(b) && b->n > 0;
}

/* How far node i of b has moved since its step began (m). */
static double node_move(const world_body *b, int32_t i) {
  const double *x = b->x + 3 * i, *x0 = b->x_old + 3 * i;
  return sqrt((x[0] - x0[0]) * (x[0] - x0[0]) + (x[1] - x0[1]) * (x[1] - x0[1]) +
              (x[2] - x0[2]) * (x[2] - x0[2]));
}

/* The largest move of b's boundary nodes in this step (m), b solved already. */
static double largest_move(const world_body *b) {
  const piola_tri_mesh *surface = b->boundary;
  double most = 0;
  for (int32_t t = 0; t < surface->triangle_count; ++t)
    for (int c = 0; c < 3; ++c) most = fmax(most, node_move(b, surface->triangles[3 * t + c]));
  return most;
}

/* What the solve under way knows of the other solids (world.solid_solve): each one's
 * boundary tree (piola__solid_boundary_tree) is built once per solve, at the first Newton
 * iteration that needs it, since the other solids stand still during the solve, with its
 * boundary's largest move in the step. The tree's boxes are not grown by a pair's reach
 * (which differs from pair to pair); a query grows its point by it instead, which finds the
 * same triangles. */
struct piola__solid_solve {
  int32_t count;     /* solids with a slot */
  int64_t *built_in; /* per solid, by its index among the solids: the solve its tree was
                        built in (-1: none) */
  double *move;      /* per solid: its boundary's largest move in this step then (m) */
  piola__index_list candidates;
};

void piola__solid_contacts_solve_begins(piola_world *w) { w->implicit_solve++; }

void piola__solid_contacts_free(piola_world *w) {
  struct piola__solid_solve *c = w->solid_solve;
  if (!c) return;
  free(c->built_in), free(c->move), free(c->candidates.items);
  free(c);
  w->solid_solve = NULL;
}

/* The tree over the boundary triangles of solid number k (other), built in this solve, and
 * its boundary's largest move in this step in *move; NULL when memory runs out. */
static const piola__bvh *solid_tree(piola_world *w, int32_t k, world_body *other, double *move) {
  struct piola__solid_solve *c = w->solid_solve;
  if (!c && !(c = w->solid_solve = calloc(1, sizeof *c))) return NULL;
  if (k >= c->count) {
    const int32_t count = w->kind_count[PIOLA_BODY_SOLID];
    int64_t *built_in = realloc(c->built_in, sizeof *built_in * (size_t)count);
    if (!built_in) return NULL;
    c->built_in = built_in;
    double *moves = realloc(c->move, sizeof *moves * (size_t)count);
    if (!moves) return NULL;
    c->move = moves;
    for (int32_t j = c->count; j < count; ++j) c->built_in[j] = -1;
    c->count = count;
  }
  if (c->built_in[k] == w->implicit_solve) {
    *move = c->move[k];
    return other->boundary_tree;
  }
  c->built_in[k] = -1;
  const piola__bvh *tree = piola__solid_boundary_tree(other, 1);
  if (!tree) return NULL;
  c->built_in[k] = w->implicit_solve;
  *move = c->move[k] = largest_move(other);
  return tree;
}

/* Node i of s against other's surface (tree over its triangles, candidates scratch): puts
 * it `gap` outside the nearest triangle that meets the box `near` when it is closer than that
 * or inside (a node held already: see below; thickness is the pair's). Returns 1 when it
 * did. */
static int hold_outside(world_body *s, int32_t i, world_body *other, const piola__bvh *tree,
                        piola__index_list *candidates, const piola__box *near, double gap,
                        double thickness, double mu, double *surface_velocity, double *surface_mu,
                        uint8_t mark) {
  const piola_tri_mesh *surface = other->boundary;
  const vec3 x = vec3_load(s->x + 3 * i);
  candidates->count = 0;
  if (piola__bvh_query(tree, near, candidates) != 0) return 0;
  double best = INFINITY, weights[3] = {0, 0, 0};
  int32_t best_t = -1;
  for (int64_t k = 0; k < candidates->count; ++k) {
    const int32_t t = candidates->items[k], *tri = surface->triangles + 3 * t;
    double w[3];
    const double d2 = piola__point_triangle_closest(x, vec3_load(other->x + 3 * tri[0]),
                                                    vec3_load(other->x + 3 * tri[1]),
                                                    vec3_load(other->x + 3 * tri[2]), w);
    if (d2 < best) best = d2, best_t = t, weights[0] = w[0], weights[1] = w[1], weights[2] = w[2];
  }
  if (best_t < 0) return 0;
  const int32_t *tri = surface->triangles + 3 * best_t;
  const vec3 a = vec3_load(other->x + 3 * tri[0]), b = vec3_load(other->x + 3 * tri[1]),
             c = vec3_load(other->x + 3 * tri[2]);
  const vec3 p = vec3_add(vec3_add(vec3_scale(a, weights[0]), vec3_scale(b, weights[1])),
                          vec3_scale(c, weights[2]));
  const vec3 face = vec3_cross(vec3_sub(b, a), vec3_sub(c, a)); /* outward */
  const double face_norm = vec3_norm(face);
  const vec3 d = vec3_sub(x, p);
  const double dn = sqrt(best), side = vec3_dot(d, face);
  /* inside where the offset clearly points into the solid (on an edge or a corner it can be
   * perpendicular to the face's normal, a rounding residue of either sign) */
  const int inside = side < -1e-9 * dn * face_norm;
  /* a node held already is put out again only once it has come within the thickness of a
   * solid solved before it, where the collision pass would act, or half the thickness into
   * one solved after it, whose own solve keeps the gap. Held along one triangle's normal, it
   * slides along that triangle's offset plane, and in a dent of the other surface that takes
   * it towards the next triangle: put out at every approach, nodes of
   * examples/solids_stack.json went from triangle to triangle of the dent at every Newton
   * iteration, up to 128 times in a frame, and the steps did not converge */
  const double least = gap > 0 ? thickness : -0.5 * thickness;
  if (s->colliding[i] == mark ? !((inside ? -dn : dn) < least) : !inside && !(dn < gap)) return 0;
  vec3 normal;
  if (dn > 0 && (inside || side > 1e-9 * dn * face_norm))
    normal = vec3_scale(d, (inside ? -1.0 : 1.0) / dn);
  else if (face_norm > 0)
    normal = vec3_scale(face, 1.0 / face_norm);
  else
    return 0; /* a collapsed triangle with the node on it: no direction to hold */
  vec3_store(s->x + 3 * i, vec3_add(p, vec3_scale(normal, gap)));
  vec3_store(s->normals + 3 * i, normal);
  const vec3 vs = vec3_add(vec3_add(vec3_scale(vec3_load(other->v + 3 * tri[0]), weights[0]),
                                    vec3_scale(vec3_load(other->v + 3 * tri[1]), weights[1])),
                           vec3_scale(vec3_load(other->v + 3 * tri[2]), weights[2]));
  vec3_store(surface_velocity + 3 * i, vs);
  surface_mu[i] = mu;
  s->colliding[i] = mark;
  s->solid_contacts++, other->solid_contacts++;
  return 1;
}

int32_t piola__solid_contacts_with_solids(piola_world *w, world_body *s, uint8_t mark,
                                          double *surface_velocity, double *surface_mu) {
  if (!takes_part(s)) return 0;
  int32_t moved = 0;
  for (int32_t k = 0; k < w->kind_count[PIOLA_BODY_SOLID]; ++k) {
    world_body *other = piola__world_body_of(w, PIOLA_BODY_SOLID, k);
    if (other == s || !takes_part(other)) continue;
    if (piola__solid_boundary(other) != PIOLA_OK) break;
    double other_move = 0;
    const piola__bvh *tree = solid_tree(w, k, other, &other_move);
    if (!tree) break;
    if (tree->node_count == 0) continue;
    /* against a solid solved after this one, still at its step's start: only out of it, onto
     * its surface; that solid then keeps the gap from this one's end of step. Both keeping
     * the gap, each against the other's surface, pushed the lower of two boxes at rest on
     * each other into a dent wherever a node of its top came within the gap of a face of
     * the upper box (1.6 J in single frames) */
    const double thickness = 0.5 * (s->self_collision.thickness + other->self_collision.thickness);
    const double gap = other > s ? 0.0 : HELD_GAP * thickness;
    const double mu = 0.5 * (s->self_collision.friction + other->self_collision.friction);
    /* a node is searched for as deep inside as the two bodies' motions in this step can have
     * taken it (its own move and the other's largest; one solved later has not moved yet),
     * not deeper: one is left to the collision pass. Projecting every node up to a boundary
     * edge deep (5 cm in examples/solids_stack.json) took some to the far side of a thin
     * part, and a run reached 38 kJ */
    const double reach = gap + (other > s ? 0.0 : other_move);
    const piola__box whole = tree->nodes[0].box;
    for (int32_t i = 0; i < s->n; ++i) {
      if (s->flags[i] != NODE_FREE || !(s->mass[i] > 0)) continue;
      const piola__box near = piola__box_around(s->x + 3 * i, node_move(s, i) + reach);
      if (!piola__boxes_overlap(&near, &whole)) continue;
      moved += hold_outside(s, i, other, tree, &w->solid_solve->candidates, &near, gap, thickness,
                            mu, surface_velocity, surface_mu, mark);
    }
  }
  return moved;
}
