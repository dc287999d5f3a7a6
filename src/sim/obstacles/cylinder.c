/* Solid capped cylinder obstacle: radius around the axis, |height| <= half_length. */
#include "sim/obstacles/obstacle_shapes.h"

#include "common/status_report.h"
#include "geometry/analytic_shapes.h"

piola_status piola__cylinder_init(const piola_obstacle_def *def, piola__axial_shape *shape) {
  shape->center = def->center;
  shape->radius = def->radius;
  shape->half_length = def->half_length;
  PIOLA_TRY(piola__obstacle_positive(def->radius, "cylinder radius"));
  PIOLA_TRY(piola__obstacle_positive(def->half_length, "cylinder half_length"));
  return piola__obstacle_unit_axis(def->axis, "cylinder axis", &shape->axis);
}

double piola__cylinder_distance(const piola__axial_shape *shape, vec3 p, vec3 *normal) {
  return piola__shape_cylinder_distance(p, shape->center, shape->axis, shape->radius, shape->half_length,
                                 normal);
}
