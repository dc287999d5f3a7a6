/* Solid torus obstacle: a tube of minor_radius around the circle of major radius (the
 * def's `radius`) in the plane normal to the axis. */
#include "sim/obstacles/obstacle_shapes.h"

#include "common/status_report.h"
#include "geometry/analytic_shapes.h"

piola_status piola__torus_init(const piola_obstacle_def *def, piola__torus_shape *shape) {
  shape->center = def->center;
  shape->major_radius = def->radius;
  shape->minor_radius = def->minor_radius;
  PIOLA_TRY(piola__obstacle_positive(def->radius, "torus radius (major)"));
  PIOLA_TRY(piola__obstacle_positive(def->minor_radius, "torus minor_radius"));
  /* A self-intersecting (spindle) torus has no exact distance of this simple form. */
  if (!(def->minor_radius < def->radius))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "torus minor_radius (%g m) must be < radius (%g m)", def->minor_radius,
                      def->radius);
  return piola__obstacle_unit_axis(def->axis, "torus axis", &shape->axis);
}

double piola__torus_distance(const piola__torus_shape *shape, vec3 p, vec3 *normal) {
  return piola__shape_torus_distance(p, shape->center, shape->axis, shape->major_radius,
                              shape->minor_radius, normal);
}
