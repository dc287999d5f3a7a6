/* Mesh obstacle: a closed triangle surface.
 *
 * The queries are those of geometry/surface_distance (shared with the mesher): the exact
 * distance to the nearest triangle through a bounding volume hierarchy, signed by the
 * generalized winding number (the sum of the triangles' signed solid angles over 4 pi, 1
 * inside and 0 outside), which is robust where the closest feature is an edge or a vertex
 * shared by faces whose normals disagree. The normal is the direction from the closest point
 * to the query point (flipped inside), as in the paper's section 10 for the Buddha, or the
 * triangle normal on the surface.
 *
 * Creation validates (indices, finite positions, closed, manifold and consistently oriented,
 * by the shared surface check, with messages naming the mesh obstacle) and winds an inward-wound
 * surface outward, since the winding number of an inward surface is -1 inside. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "geometry/surface_distance.h"
#include "sim/obstacles/obstacle_shapes.h"

/* The surface checks of geometry/surface_distance, with messages that name the obstacle. */
static piola_status check_closed(const piola_tri_mesh *mesh) {
  piola_status s = piola__surface_check_closed(mesh);
  if (s == PIOLA_OK) return s;
  char reason[256];
  snprintf(reason, sizeof reason, "%s", piola_last_error());
  return PIOLA_FAIL(s, "mesh obstacle: %s", reason);
}

piola_status piola__mesh_obstacle_init(const piola_obstacle_def *def, piola__mesh_shape *shape) {
  memset(shape, 0, sizeof *shape);
  const piola_tri_mesh *mesh = def->mesh;
  if (!mesh || mesh->vertex_count < 4 || mesh->triangle_count < 4 || !mesh->positions ||
      !mesh->triangles)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "mesh obstacle needs a closed triangle mesh (>= 4 vertices and triangles)");
  PIOLA_TRY(check_closed(mesh));

  /* Wind outward: an inward-wound surface encloses negative volume; build from a flipped copy. */
  double volume = 0;
  for (int32_t t = 0; t < mesh->triangle_count; ++t) {
    const int32_t *tri = mesh->triangles + 3 * t;
    vec3 a = vec3_load(mesh->positions + 3 * tri[0]), b = vec3_load(mesh->positions + 3 * tri[1]),
         c = vec3_load(mesh->positions + 3 * tri[2]);
    volume += vec3_dot(a, vec3_cross(b, c)) / 6.0;
  }
  if (!(fabs(volume) > 0))
    return PIOLA_FAIL(PIOLA_ERROR_DEGENERATE_ELEMENT, "mesh obstacle encloses no volume");
  piola_tri_mesh outward = *mesh;
  int32_t *flipped = NULL;
  if (volume < 0) {
    flipped = malloc(sizeof(int32_t) * 3 * (size_t)mesh->triangle_count);
    if (!flipped) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "mesh obstacle flip");
    for (int32_t t = 0; t < mesh->triangle_count; ++t) {
      flipped[3 * t] = mesh->triangles[3 * t];
      flipped[3 * t + 1] = mesh->triangles[3 * t + 2];
      flipped[3 * t + 2] = mesh->triangles[3 * t + 1];
    }
    outward.triangles = flipped;
  }
  piola__surface_distance *surface = NULL;
  piola_status s = piola__surface_distance_create(&outward, &surface);
  free(flipped);
  if (s != PIOLA_OK) return s;
  shape->accel = surface;
  shape->vertex_count = mesh->vertex_count;
  shape->triangle_count = mesh->triangle_count;
  piola__surface_bounds(surface, &shape->box_min, &shape->box_max);
  return PIOLA_OK;
}

void piola__mesh_obstacle_free(piola__mesh_shape *shape) {
  piola__surface_distance_destroy(shape->accel);
  shape->accel = NULL;
}

double piola__mesh_obstacle_distance(const piola__mesh_shape *shape, vec3 p, vec3 *normal) {
  return piola__surface_signed_distance(shape->accel, p, normal, NULL);
}

bool piola__mesh_obstacle_contains(const piola__mesh_shape *shape, vec3 p) {
  return piola__surface_winding_number(shape->accel, p) > 0.5;
}
