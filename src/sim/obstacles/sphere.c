/* Solid ball obstacle. */
#include "sim/obstacles/obstacle_shapes.h"

#include "common/status_report.h"
#include "geometry/analytic_shapes.h"

piola_status piola__sphere_init(const piola_obstacle_def *def, piola__sphere_shape *shape) {
  shape->center = def->center;
  shape->radius = def->radius;
  return piola__obstacle_positive(def->radius, "sphere radius");
}

double piola__sphere_distance(const piola__sphere_shape *shape, vec3 p, vec3 *normal) {
  return piola__shape_sphere_distance(p, shape->center, shape->radius, normal);
}
