/* piola: self-collision and contact between deformable surfaces (Bridson, Fedkiw and
 * Anderson 2002, "BFA02"), run after the time step (paper section 9: "outside the step").
 *
 * A collision surface is a set of triangles over numbered vertices, grouped in bodies. Each
 * body has a thickness (m) and a Coulomb friction coefficient. Cloth and shells give their
 * own triangles; a volumetric solid gives its boundary surface (piola_tet_mesh_boundary).
 * Every pair of primitives is checked, within one body (self-contact) and between bodies.
 *
 * piola_collision_surface_process takes the start-of-step positions x0 (m), the velocities
 * v (m/s) the integrator proposes, and the step length dt (s): the proposed end positions are
 * x1 = x0 + dt v. It changes v, in three stages:
 *   1. repulsion: point-triangle and edge-edge pairs closer than the thickness at x0 get an
 *      inelastic impulse that stops their approach, a repulsion impulse limited as in BFA02,
 *      and Coulomb friction on their relative tangential velocity;
 *   2. continuous collision detection: every point-triangle and edge-edge pair that becomes
 *      coplanar within [0, dt] and touches there gets an inelastic impulse; this repeats up to
 *      `collision_iterations` times;
 *   3. rigid impact zones: vertices of pairs that still collide are merged into zones that
 *      move with the rigid velocity field (v_cm + w x r) that keeps their linear and angular
 *      momentum; zones grow and merge until no collision is left.
 * If x0 has no two triangles (without a shared vertex) that touch, then after the call none of
 * the paths x0 + s dt v, s in [0, 1], makes a vertex pass through a triangle or an edge through
 * an edge, so x1 has no intersecting triangle pair either (see docs/contact.md for the limits:
 * pinned vertices within a zone must move rigidly together). */
#ifndef PIOLA_COLLISION_SURFACE_H
#define PIOLA_COLLISION_SURFACE_H

#include <stdint.h>

#include "piola/export.h"
#include "piola/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct piola_collision_body_def {
  double thickness; /* m, > 0: pairs within the body closer than this repel; between two
                       bodies the mean of their thicknesses applies. Default 1e-3 */
  double friction;  /* Coulomb coefficient mu, >= 0. Default 0.3 */
} piola_collision_body_def;

PIOLA_API piola_collision_body_def piola_default_collision_body_def(void);

typedef struct piola_collision_surface_def {
  int32_t vertex_count;
  int32_t triangle_count;
  const int32_t *triangles;               /* 3 * triangle_count vertex indices, copied */
  int32_t body_count;                     /* >= 1 */
  const piola_collision_body_def *bodies; /* body_count entries, copied */
  const int32_t *vertex_body; /* vertex_count body indices, copied; NULL: all in body 0 */
  /* Embedded vertices (optional; all NULL and node_count 0: vertex i is the moving point i).
   * Otherwise the moving points are node_count nodes and vertex i is the fixed combination
   * sum_k embed_weights[4i+k] x(embed_nodes[4i+k]) of up to four of them (barycentric
   * weights in [0, 1] summing to 1; an unused slot has weight 0 and node -1), such as a
   * point of a crack face inside a cut tet. piola_collision_surface_process then takes x0, v
   * and mass per node, and every impulse on a vertex acts on its nodes by these weights,
   * so the vertices' paths it checks are the ones the nodes' velocities give. Copied. */
  int32_t node_count;
  const int32_t *embed_nodes; /* 4 per vertex */
  const double *embed_weights; /* 4 per vertex */
} piola_collision_surface_def;

/* Nodes a vertex of an embedded collision surface can combine. */
#define PIOLA_COLLISION_EMBED_NODES 4

PIOLA_API piola_collision_surface_def piola_default_collision_surface_def(void);

/* Tunable parts of processing. All have defaults; none needs changing for correctness. */
typedef struct piola_collision_settings {
  int repulsion;              /* 1: stage 1 runs; 0: it is skipped. Default 1 */
  double repulsion_stiffness; /* N/m: spring constant k that limits the repulsion impulse to
                                 dt k d (d the overlap with the thickness); INFINITY: the
                                 impulse only brings the approach speed to 0.1 d / dt as in
                                 BFA02. Default INFINITY */
  int collision_iterations;   /* stage 2 passes before rigid impact zones, >= 0. Default 5 */
  int max_zone_iterations;    /* stage 3 passes, >= 1; each merges or grows zones, and
                                 when they run out stats.resolved is 0. Default 200 */
} piola_collision_settings;

PIOLA_API piola_collision_settings piola_default_collision_settings(void);

/* What one call did. */
typedef struct piola_collision_stats {
  int64_t contacts;         /* stage 1 pairs within the thickness that got an impulse */
  int64_t impacts;          /* stage 2 collisions resolved by impulses (summed over passes) */
  int32_t impact_zones;     /* stage 3 zones at the end (0 when stage 2 sufficed) */
  int32_t zone_vertices;    /* vertices moved rigidly in those zones */
  int32_t collision_passes; /* stage 2 passes run */
  int32_t zone_passes;      /* stage 3 passes run */
  int32_t resolved;         /* 1 when the final check found no collision; 0 when the zone
                               passes ran out, or a zone holds pinned vertices that do not move
                               rigidly together (so the zone cannot follow them all) */
} piola_collision_stats;

typedef struct piola_collision_surface piola_collision_surface;

/* Validates def (indices in range, no repeated vertex in a triangle, thickness > 0, friction
 * >= 0, finite) and builds the surface and its edge list. */
PIOLA_API piola_status piola_collision_surface_create(const piola_collision_surface_def *def,
                                                      piola_collision_surface **out);

PIOLA_API void piola_collision_surface_destroy(piola_collision_surface *surface);

PIOLA_API int32_t piola_collision_surface_vertex_count(const piola_collision_surface *surface);
PIOLA_API int32_t piola_collision_surface_edge_count(const piola_collision_surface *surface);

/* One call per step. x0 (m, 3 * vertex_count): positions at the start of the step; v (m/s,
 * 3 * vertex_count): proposed velocities, changed in place; mass (kg, vertex_count): > 0, or
 * INFINITY for a pinned vertex, whose velocity is never changed (on an embedded surface all
 * three are per node, node_count of them, and a vertex is pinned when all its nodes are);
 * dt (s) > 0. settings and
 * stats may be NULL (defaults; no statistics). Fails with PIOLA_ERROR_NOT_FINITE on NaN/Inf
 * in x0 or v and PIOLA_ERROR_INVALID_ARGUMENT on a bad mass, dt or setting, leaving v
 * unchanged; after PIOLA_ERROR_OUT_OF_MEMORY v may hold partly processed velocities (each
 * stage leaves v finite). The result does not depend on the number of threads. */
PIOLA_API piola_status piola_collision_surface_process(piola_collision_surface *surface,
                                                       const double *x0, double *v,
                                                       const double *mass, double dt,
                                                       const piola_collision_settings *settings,
                                                       piola_collision_stats *stats);

#ifdef __cplusplus
}
#endif

#endif
