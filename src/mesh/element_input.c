#include "mesh/element_input.h"

#include <math.h>

#include "common/status_report.h"

piola_status piola__check_element_input(const char *body_name, const char *element_name,
                                        int corners, int32_t vertex_count,
                                        const double *positions, int32_t element_count,
                                        const int32_t *elements, const piola_material *materials,
                                        int32_t material_count, const int32_t *element_materials) {
  if (!materials || material_count <= 0)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "%s needs at least one material (material_count %d)", body_name,
                      (int)material_count);
  for (int32_t m = 0; m < material_count; ++m) {
    const piola_material *mat = &materials[m];
    if ((int)mat->model < 0 || mat->model >= PIOLA_MODEL_COUNT || !isfinite(mat->mu) ||
        !isfinite(mat->lambda) || !(mat->mu > 0))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "material %d is not an initialized material (use piola_material_init)",
                        (int)m);
  }
  for (int32_t i = 0; i < 3 * vertex_count; ++i)
    if (!isfinite(positions[i]))
      return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "rest position of vertex %d is not finite",
                        (int)(i / 3));
  for (int32_t e = 0; e < element_count; ++e) {
    for (int c = 0; c < corners; ++c) {
      int32_t v = elements[(int64_t)corners * e + c];
      if (v < 0 || v >= vertex_count)
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                          "%s %d corner %d refers to vertex %d, outside 0..%d", element_name,
                          (int)e, c, (int)v, (int)vertex_count - 1);
    }
    if (element_materials) {
      int32_t m = element_materials[e];
      if (m < 0 || m >= material_count)
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "%s %d has material index %d, outside 0..%d",
                          element_name, (int)e, (int)m, (int)material_count - 1);
    }
  }
  return PIOLA_OK;
}
