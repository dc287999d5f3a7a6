/* Capsule obstacle: all points within radius of the segment center +- half_length axis. */
#include "sim/obstacles/obstacle_shapes.h"

#include <math.h>

#include "common/status_report.h"
#include "geometry/analytic_shapes.h"

piola_status piola__capsule_init(const piola_obstacle_def *def, piola__axial_shape *shape) {
  shape->center = def->center;
  shape->radius = def->radius;
  shape->half_length = def->half_length;
  PIOLA_TRY(piola__obstacle_positive(def->radius, "capsule radius"));
  /* A zero half length is a sphere, which is still a valid capsule. */
  if (!(def->half_length >= 0) || !isfinite(def->half_length))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "capsule half_length must be finite and >= 0 m, got %g", def->half_length);
  return piola__obstacle_unit_axis(def->axis, "capsule axis", &shape->axis);
}

double piola__capsule_distance(const piola__axial_shape *shape, vec3 p, vec3 *normal) {
  return piola__shape_capsule_distance(p, shape->center, shape->axis, shape->radius, shape->half_length,
                                normal);
}
