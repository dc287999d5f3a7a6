/* A solid's `fibers` key turned into one fibre direction per tet of the placed rest mesh:
 * the per-tet data of the mesh file, a uniform axis, or the tangent of the polyline segment nearest each tet's rest centroid
 * (a muscle's fibres follow its line of action from one end to the other). Directions are
 * in scene coordinates, like the placed mesh. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "math/mat3.h"
#include "scene/scene_desc.h"

/* Squared distance from p to the segment [a, b]. */
static double segment_distance2(vec3 p, vec3 a, vec3 b) {
  const vec3 ab = vec3_sub(b, a);
  double t = vec3_dot(vec3_sub(p, a), ab) / vec3_dot(ab, ab);
  t = t < 0 ? 0 : (t > 1 ? 1 : t);
  return vec3_norm2(vec3_sub(p, vec3_add(a, vec3_scale(ab, t))));
}

piola_status piola__scene_fiber_directions(const scene_fibers *fibers, const piola_tet_mesh *mesh,
                                           double **out) {
  *out = NULL;
  if (fibers->kind == SCENE_FIBERS_NONE) return PIOLA_OK;
  if (fibers->kind == SCENE_FIBERS_FROM_MESH && !mesh->tet_fibers)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "fibers.from_mesh: the mesh file has no per-tet fibre data (a 3-component "
                      "cell array named \"fiber\" or \"fibers\" in .vtu, or $ElementData of that "
                      "name in .msh; see docs/file-formats.md)");
  double *a = malloc(sizeof(double) * 3 * (size_t)mesh->tet_count);
  if (!a) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fibers: out of memory");
  if (fibers->kind == SCENE_FIBERS_FROM_MESH) {
    /* already turned with the rest shape by the scene's transform; the body normalises them
     * and names a zero one by its tet */
    memcpy(a, mesh->tet_fibers, sizeof(double) * 3 * (size_t)mesh->tet_count);
    *out = a;
    return PIOLA_OK;
  }
  for (int32_t t = 0; t < mesh->tet_count; ++t) {
    vec3 d = fibers->axis;
    vec3 c = {0, 0, 0};
    for (int k = 0; k < 4; ++k)
      c = vec3_add(c, vec3_load(mesh->positions + 3 * (size_t)mesh->tets[4 * (size_t)t + k]));
    c = vec3_scale(c, 0.25);
    if (fibers->kind == SCENE_FIBERS_AROUND) {
      const vec3 point = {fibers->point.x, fibers->point.y, fibers->point.z};
      d = vec3_cross(d, vec3_sub(c, point));
      const double n = vec3_norm(d);
      if (!(n > 0)) {
        free(a);
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                          "fibers.around: the centroid of tet %d lies on the axis, so it has no "
                          "circumferential direction",
                          (int)t);
      }
      d = vec3_scale(d, 1.0 / n);
    }
    if (fibers->kind == SCENE_FIBERS_CURVE) {
      double best = INFINITY;
      for (int32_t s = 0; s + 1 < fibers->curve_points; ++s) {
        const vec3 p0 = vec3_load(fibers->curve + 3 * s), p1 = vec3_load(fibers->curve + 3 * s + 3);
        const double d2 = segment_distance2(c, p0, p1);
        if (d2 < best) best = d2, d = vec3_sub(p1, p0);
      }
      d = vec3_scale(d, 1.0 / vec3_norm(d));
    }
    vec3_store(a + 3 * (size_t)t, d);
  }
  *out = a;
  return PIOLA_OK;
}
