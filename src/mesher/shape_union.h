/* The level set phi of the region to mesh: the union of the shapes in a piola_mesher_def,
 * phi = min over shapes of their signed distances (negative inside, m). Analytic shapes use
 * geometry/analytic_shapes.h; surfaces use geometry/surface_distance.h. The minimum is the
 * exact distance outside the union and near its boundary away from where shapes meet, which
 * is all the mesher needs: the sign everywhere, the value and gradient near the surface. */
#ifndef PIOLA_MESHER_SHAPE_UNION_H
#define PIOLA_MESHER_SHAPE_UNION_H

#include "geometry/surface_distance.h"
#include "math/mat3.h"
#include "piola/mesher.h"

typedef struct piola__shape_union {
  piola_shape shapes[PIOLA_MESHER_MAX_SHAPES];
  piola__surface_distance *surfaces[PIOLA_MESHER_MAX_SHAPES];
  int count;
} piola__shape_union;

/* Validates the shapes (positive sizes, unit axes are normalised) and builds the surface
 * distance trees. */
piola_status piola__shape_union_create(const piola_mesher_def *def, piola__shape_union *out);
void piola__shape_union_destroy(piola__shape_union *u);

/* Bounding box of the union (m). */
void piola__shape_union_bounds(const piola__shape_union *u, vec3 *lo, vec3 *hi);

/* phi(p) (m) and its gradient, the outward unit normal (may be NULL). */
double piola__shape_union_phi(const piola__shape_union *u, vec3 p, vec3 *normal);

/* phi of the analytic shapes only (INFINITY when there are none). */
double piola__shape_union_phi_analytic(const piola__shape_union *u, vec3 p);

/* The point of the surface phi = 0 nearest to p (a few Newton steps p - phi grad phi). */
vec3 piola__shape_union_project(const piola__shape_union *u, vec3 p);

#endif
