/* Internals of collision processing for deformable surfaces (BFA02).
 *
 * Why it is organised this way:
 * - Everything that touches a pair is expressed through one relative position,
 *   r = sum_k w_k x_k over the pair's four vertices (point minus the closest point of the
 *   triangle, or closest point of one edge minus that of the other). The weights sum to zero,
 *   so an impulse applied as dv_k = w_k J / m_k leaves linear momentum unchanged, and the same
 *   formula covers point-triangle and edge-edge pairs, unequal masses and pinned vertices
 *   (1 / m = 0). The change of relative velocity is J sum_k w_k^2 / m_k, so the impulse that
 *   produces a wanted change is a division by that sum.
 * - Detection (broad phase in a BVH, then the exact narrow test of each candidate pair) is
 *   the expensive part and runs in parallel over fixed blocks of query primitives; each block
 *   keeps its own list, and the lists are joined in block order, so the result does not
 *   depend on the thread count. Impulses are then applied one pair after the other
 *   (Gauss-Seidel), in that order, so later pairs see the velocities earlier pairs left.
 * - Rigid impact zones use the linearised rigid motion v = v_cm + w x (x0 - c). Over the step
 *   this moves the zone by the affine map x -> x + s dt (v_cm + w x (x - c)), whose matrix
 *   I + s dt [w]x has singular values 1 and sqrt(1 + (s dt |w|)^2): it never shrinks a
 *   distance, so no pair inside a zone can come closer than it was at the start of the step. */
#ifndef PIOLA_CONTACT_INTERNAL_H
#define PIOLA_CONTACT_INTERNAL_H

#include <stdint.h>

#include "contact/bvh.h"
#include "math/mat3.h"
#include "piola/collision_surface.h"

/* Fraction of the pair thickness within which continuous detection calls two primitives
 * touching, and the gap it leaves them at the end of the step. */
#define PIOLA__CCD_TOLERANCE 1e-3
#define PIOLA__CCD_TARGET_GAP 1e-2

/* One pair and what is needed to push it apart. */
typedef struct piola__contact {
  int32_t v[4];     /* vertices: point then triangle, or edge then edge */
  double w[4];      /* relative position r = sum w[k] x[k] */
  vec3 normal;      /* unit; r has a non-negative component along it at the start */
  double gap;       /* m: r . normal at the start of the step */
  double thickness; /* m: of the pair */
  double friction;  /* Coulomb coefficient of the pair */
} piola__contact;

typedef struct piola__contact_list {
  piola__contact *items;
  int64_t count, capacity;
} piola__contact_list;

int piola__contact_list_push(piola__contact_list *list, const piola__contact *c);

struct piola_collision_surface {
  int32_t vertex_count, triangle_count, edge_count, body_count;
  int32_t *triangles; /* 3 per triangle */
  int32_t *edges;     /* 2 per edge, lower index first, sorted */
  int32_t *vertex_body;
  piola_collision_body_def *bodies;
  /* Workspace, sized at creation and reused by every call. */
  double *inverse_mass;
  double *vertex_thickness;
  piola__box *vertex_boxes, *triangle_boxes, *edge_boxes;
  piola__bvh triangle_tree, edge_tree, vertex_tree;
  int32_t *queries;    /* query primitives of a detection pass */
  int32_t block_count; /* capacity of blocks */
  piola__contact_list *blocks;
  piola__contact_list found;
  int32_t *zone_parent;
  uint8_t *in_zone;
  uint8_t *dirty;      /* velocity changed since the last detection pass */
  uint8_t *on_surface; /* vertex of at least one triangle */
  int32_t zone_misfit; /* a zone could not follow its pinned vertices (this call) */
  int32_t tree_age;    /* calls since the trees were last built (0: never built) */
  int32_t *zone_order; /* vertices grouped by zone */
};

/* Velocity field of rigid impact zones: merges the vertices of every contact in `hits` into
 * zones (union-find in surface->zone_parent), then gives every vertex of every zone the rigid
 * velocity that keeps the zone's linear and angular momentum about its centre of mass at x0.
 * Pinned vertices keep their velocity; a zone holding some moves with the rigid motion that
 * fits the pinned vertices best. Returns the number of zones, or -1 out of memory. */
int32_t piola__impact_zones_apply(piola_collision_surface *surface, const piola__contact_list *hits,
                                  const double *x0, double *v, int32_t *zone_vertices);

/* Union-find root of a vertex, with path halving. */
int32_t piola__zone_root(int32_t *parent, int32_t i);

#endif
