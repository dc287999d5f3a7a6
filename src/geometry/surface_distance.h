/* Signed distance to a closed triangle surface.
 *
 * Used by the mesher (inside/outside of a surface to be meshed, and the projection of
 * boundary nodes onto it) and by mesh obstacles (projection of colliding nodes).
 *
 * Distance: the exact Euclidean distance to the nearest triangle, found with a bounding
 * volume hierarchy (an axis-aligned box tree built by median splits, visited nearest child
 * first and pruned by box distance), so a query costs O(log n) triangles for points near
 * the surface.
 *
 * Sign: the generalized winding number w(p) = (1/4 pi) sum of the solid angles of the
 * triangles seen from p; w = 1 inside a closed, outward-wound surface and 0 outside. It is
 * robust where sign-by-nearest-normal tests are fragile (near edges and vertices, on thin
 * parts). The same tree speeds it up (as in Barill et al. 2018): a subtree far from p
 * (distance above 2 times its radius) contributes through its area-weighted normal as a
 * dipole at its area centroid; near subtrees are summed exactly (Van Oosterom-Strackee
 * formula). The approximation error is far below the 0.5 that separates inside from
 * outside, so the sign is exact away from the surface and the distance is exact everywhere.
 *
 * Only closed, edge-manifold, consistently oriented surfaces are accepted: create refuses
 * others with a message naming an offending edge by its vertex indices. The object is
 * read-only after creation, so queries are safe from many threads at once. */
#ifndef PIOLA_GEOMETRY_SURFACE_DISTANCE_H
#define PIOLA_GEOMETRY_SURFACE_DISTANCE_H

#include <stdint.h>

#include "math/mat3.h"
#include "piola/mesh.h"
#include "piola/status.h"

typedef struct piola__surface_distance piola__surface_distance;

/* Checks that every edge is used by exactly two triangles, in opposite directions, and
 * that no triangle repeats a vertex; names the first offending edge (vertex indices). */
piola_status piola__surface_check_closed(const piola_tri_mesh *mesh);

/* Copies the mesh (the caller may free it afterwards) and builds the tree. Fails on an
 * open, non-manifold or inconsistently oriented surface, bad indices or non-finite
 * positions. */
piola_status piola__surface_distance_create(const piola_tri_mesh *mesh,
                                            piola__surface_distance **out);
void piola__surface_distance_destroy(piola__surface_distance *surface);

/* Unsigned distance (m) from p to the surface; the closest point and its triangle. */
double piola__surface_closest_point(const piola__surface_distance *surface, vec3 p,
                                    vec3 *closest, int32_t *triangle);

/* The same, but only triangles closer than max_distance (m) are considered: returns
 * INFINITY (closest = p, triangle = -1) when there are none. Much
 * faster far from the surface, where only the sign matters. */
double piola__surface_closest_point_within(const piola__surface_distance *surface, vec3 p,
                                           double max_distance, vec3 *closest,
                                           int32_t *triangle);

/* Generalized winding number at p: about 1 inside, 0 outside. */
double piola__surface_winding_number(const piola__surface_distance *surface, vec3 p);

/* Signed distance (m), negative inside; normal = outward unit normal of the surface at the
 * closest point (direction from it to p, sign-corrected; the triangle normal when p is on
 * the surface). closest may be NULL. */
double piola__surface_signed_distance(const piola__surface_distance *surface, vec3 p,
                                      vec3 *normal, vec3 *closest);

/* Bounding box of the vertices (m). */
void piola__surface_bounds(const piola__surface_distance *surface, vec3 *lo, vec3 *hi);

/* Enclosed volume by the divergence theorem (m^3), positive for outward winding. */
double piola__surface_volume(const piola__surface_distance *surface);

#endif
