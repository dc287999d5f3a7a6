/* Half-space obstacle: the solid side is below the plane (opposite to its normal). */
#include "sim/obstacles/obstacle_shapes.h"

#include "common/status_report.h"
#include "geometry/analytic_shapes.h"

piola_status piola__plane_init(const piola_obstacle_def *def, piola__plane_shape *shape) {
  shape->point = def->center;
  return piola__obstacle_unit_axis(def->axis, "plane normal (axis)", &shape->normal);
}

double piola__plane_distance(const piola__plane_shape *shape, vec3 p, vec3 *normal) {
  return piola__shape_plane_distance(p, shape->point, shape->normal, normal);
}
