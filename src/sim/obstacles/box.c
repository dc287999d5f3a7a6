/* Solid box obstacle, aligned with the world axes at t = 0 (the motion may rotate it). */
#include "sim/obstacles/obstacle_shapes.h"

#include "common/status_report.h"
#include "geometry/analytic_shapes.h"

piola_status piola__box_init(const piola_obstacle_def *def, piola__box_shape *shape) {
  shape->center = def->center;
  shape->half_extents = def->half_extents;
  PIOLA_TRY(piola__obstacle_positive(def->half_extents.x, "box half_extents.x"));
  PIOLA_TRY(piola__obstacle_positive(def->half_extents.y, "box half_extents.y"));
  return piola__obstacle_positive(def->half_extents.z, "box half_extents.z");
}

double piola__box_distance(const piola__box_shape *shape, vec3 p, vec3 *normal) {
  return piola__shape_box_distance(p, shape->center, shape->half_extents, normal);
}
