/* Stress of a saved frame, for `--color stress`.
 *
 * A frame stores current positions and displacements, so each tet's rest shape and hence
 * its deformation gradient F = Ds Dm^-1 are known; with the material of its solid (from the
 * scene) the diagonalized stress Phat(Fhat) follows exactly as the simulation computes it,
 * inversion extension included. The colour is the von Mises equivalent of the principal
 * first Piola-Kirchhoff stresses: unlike a Cauchy stress it needs no division by det F, so it
 * stays finite for flat and inverted elements, which is where one looks. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "piola/diagonalize.h"
#include "piola/scene.h"
#include "render/render_internal.h"

static mat3 edge_matrix(const double *x, const int32_t *t) {
  vec3 a = vec3_load(x + 3 * (size_t)t[0]);
  return mat3_from_columns(vec3_sub(vec3_load(x + 3 * (size_t)t[1]), a),
                           vec3_sub(vec3_load(x + 3 * (size_t)t[2]), a),
                           vec3_sub(vec3_load(x + 3 * (size_t)t[3]), a));
}

bool piola_render_frame_has_rest_positions(const piola_render_frame *f) { return f && f->rest; }

piola_status piola_render_frame_add_stress(piola_render_frame *f,
                                           const piola_material_def *materials,
                                           int32_t material_count) {
  if (!f || (!materials && material_count > 0) || material_count < 0)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "frame stress: NULL argument");
  if (!f->rest)
    return PIOLA_FAIL(
        PIOLA_ERROR_INVALID_ARGUMENT,
        "frame stress: the frame has no `displacement` point field (rest positions unknown)");
  piola_material *mats = malloc((size_t)(material_count > 0 ? material_count : 1) * sizeof *mats);
  if (!mats) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "frame stress: out of memory");
  for (int32_t i = 0; i < material_count; ++i)
    if (piola_material_init(&materials[i], &mats[i]) != PIOLA_OK) {
      free(mats);
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "frame stress: material of solid %d: %s",
                        (int)i, piola_last_error());
    }
  const double *solid = NULL;
  for (int i = 0; i < f->field_count; ++i)
    if (strcmp(f->fields[i].name, "solid") == 0) solid = f->fields[i].values;
  double *vm = calloc((size_t)(f->cell_count > 0 ? f->cell_count : 1), sizeof *vm);
  render_cell_field *grown = realloc(f->fields, (size_t)(f->field_count + 1) * sizeof *grown);
  if (grown) f->fields = grown;
  if (!vm || !grown) {
    free(mats), free(vm);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "frame stress: out of memory");
  }
  piola_status st = PIOLA_OK;
  for (int32_t t = 0; t < f->tet_count && st == PIOLA_OK; ++t) {
    int32_t c = f->tet_cell[t];
    double s = solid ? solid[c] : 0;
    if (!(s >= 0 && s < material_count) || s != floor(s)) {
      st = PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "frame stress: cell %d belongs to solid %g, but %d materials given", (int)c,
                      s, (int)material_count);
      break;
    }
    const int32_t *tet = f->tets + 4 * (size_t)t;
    mat3 dm = edge_matrix(f->rest, tet), ds = edge_matrix(f->points, tet);
    double det = mat3_det(dm);
    if (!(fabs(det) > 0) || !isfinite(det)) continue; /* a degenerate rest tet: no stress */
    mat3 F = mat3_mul(ds, mat3_inverse(dm));
    mat3 u, v;
    vec3 fh;
    if (piola_diagonalize3(&F, &u, &fh, &v) != PIOLA_OK) continue;
    double fhat[3] = {fh.x, fh.y, fh.z}, p[3];
    piola_material_stress(&mats[(int32_t)s], fhat, p);
    vm[c] = sqrt(0.5 * ((p[0] - p[1]) * (p[0] - p[1]) + (p[1] - p[2]) * (p[1] - p[2]) +
                        (p[2] - p[0]) * (p[2] - p[0])));
  }
  free(mats);
  if (st != PIOLA_OK) {
    free(vm);
    return st;
  }
  /* replace an earlier field of the same name */
  for (int i = 0; i < f->field_count; ++i)
    if (strcmp(f->fields[i].name, "von_mises_stress") == 0) {
      free(f->fields[i].values);
      f->fields[i].values = vm;
      return PIOLA_OK;
    }
  snprintf(f->fields[f->field_count].name, sizeof f->fields[0].name, "von_mises_stress");
  f->fields[f->field_count++].values = vm;
  return PIOLA_OK;
}

piola_status piola_render_scene_materials(const char *path, piola_material_def *materials,
                                          int32_t capacity, int32_t *count) {
  if (!path || !count || capacity < 0 || (capacity > 0 && !materials))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "scene materials: NULL argument");
  *count = 0;
  piola_scene_desc *desc;
  PIOLA_TRY(piola_scene_parse_file(path, &desc));
  *count = piola_scene_desc_solid_count(desc);
  for (int32_t i = 0; i < *count && i < capacity; ++i)
    materials[i] = piola_scene_desc_solid_material(desc, i);
  piola_scene_desc_destroy(desc);
  return PIOLA_OK;
}
