/* The rest state of an elastic body: validation, reorientation, Dm^-1, V0, lumped masses,
 * the vertex -> (tet, corner) incidence list, the smallest rest altitude and the largest wave
 * speed. Everything the force loop reads is laid out here (see elastic_body_internal.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "force/elastic_body_internal.h"
#include "force/fiber_lanes.h"
#include "force/stable_step_modulus.h"
#include "material/hgo_kernels.h"
#include "material/material_kernels.h"
#include "math/mat3.h"
#include "mesh/element_input.h"

/* A rest tet whose |V0| is below this fraction of (longest edge)^3 is degenerate. A regular
 * tet has V0 = 0.118 L^3; 1e-12 rejects only elements that are flat to round-off, whose Dm^-1
 * would be meaningless. */
#define DEGENERATE_VOLUME_RATIO 1e-12

static void *alloc_array(size_t count, size_t size) {
  return calloc(count == 0 ? 1 : count, size);
}

void piola__elastic_body_free_arrays(piola_elastic_body *body) {
  for (int k = 0; k < 4; ++k) free(body->tet_vertices[k]);
  for (int k = 0; k < 9; ++k) {
    free(body->dm_inv[k]);
  }
  free(body->u[0]);
  free(body->v[0]);
  free(body->rest_volume);
  free(body->tet_material);
  free(body->fhat);
  free(body->det_f);
  free(body->energy_density);
  free(body->block_energy);
  free(body->block_inverted);
  free(body->block_min_det);
  free(body->materials);
  free(body->tets);
  free(body->rest_positions);
  free(body->masses);
  free(body->positions);
  free(body->chunk_forces);
  piola__elastic_body_split_free(body);
  free(body->step_weight);
  free(body->step_gram);
  free(body->ogden_cache);
  free(body->hgo_cache);
  free(body->step_cache);
  piola__damping_matrix_free(&body->damping);
  for (int k = 0; k < 3; ++k) free(body->fiber[k]);
  free(body->fiber_aos);
  memset(body, 0, sizeof *body);
}

static piola_status validate_def(const piola_elastic_body_def *def) {
  if (!def) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "elastic body def is NULL");
  const piola_tet_mesh *mesh = def->rest_mesh;
  if (!mesh) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "elastic body rest_mesh is NULL");
  if (mesh->vertex_count <= 0 || mesh->tet_count <= 0 || !mesh->positions || !mesh->tets)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "elastic body rest_mesh needs vertices and tets (got %d vertices, %d tets)",
                      (int)mesh->vertex_count, (int)mesh->tet_count);
  if (mesh->tet_count > INT32_MAX / 4 - PIOLA_TET_BLOCK)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "elastic body has too many tets (%d)",
                      (int)mesh->tet_count);
  if (!(def->density > 0) || !isfinite(def->density))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "density must be > 0 kg/m^3, got %g",
                      def->density);
  if (def->material_fractions)
    for (int32_t t = 0; t < mesh->tet_count; ++t)
      if (!(def->material_fractions[t] > 0 && def->material_fractions[t] <= 1))
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                          "tet %d: material fraction must be in (0, 1], got %g", (int)t,
                          def->material_fractions[t]);
  return piola__check_element_input("elastic body", "tet", 4, mesh->vertex_count, mesh->positions,
                                    mesh->tet_count, mesh->tets, def->materials,
                                    def->material_count, def->tet_materials);
}

static double triangle_area(vec3 a, vec3 b, vec3 c) {
  return 0.5 * vec3_norm(vec3_cross(vec3_sub(b, a), vec3_sub(c, a)));
}

void piola__elastic_body_rest_rotations(piola_elastic_body *body, const uint8_t *held) {
  for (int32_t t = 0; t < body->padded_tet_count; ++t) {
    if (held && !held[t / PIOLA_TET_BLOCK]) continue;
    body->u[0][t] = body->u[4][t] = body->u[8][t] = 1.0;
    body->v[0][t] = body->v[4][t] = body->v[8][t] = 1.0;
    body->fhat[3 * t] = body->fhat[3 * t + 1] = body->fhat[3 * t + 2] = 1.0;
    body->det_f[t] = 1.0;
  }
}

piola_status piola__elastic_body_build_rest_state(piola_elastic_body *body,
                                                  const piola_elastic_body_def *def,
                                                  int write_state) {
  PIOLA_TRY(validate_def(def));
  const piola_tet_mesh *mesh = def->rest_mesh;
  int32_t nv = mesh->vertex_count, nt = mesh->tet_count;
  int32_t np = (nt + PIOLA_TET_BLOCK - 1) / PIOLA_TET_BLOCK * PIOLA_TET_BLOCK;
  body->vertex_count = nv;
  body->tet_count = nt;
  body->padded_tet_count = np;
  body->density = def->density;
  body->material_count = def->material_count;

  int ok = 1;
  for (int k = 0; k < 4; ++k) ok &= (body->tet_vertices[k] = alloc_array((size_t)np, sizeof(int32_t))) != NULL;
  for (int k = 0; k < 9; ++k) {
    ok &= (body->dm_inv[k] = alloc_array((size_t)np, sizeof(double))) != NULL;
  }
  size_t nb = (size_t)np / PIOLA_TET_BLOCK;
  ok &= (body->u[0] = alloc_array(9 * (size_t)np, sizeof(double))) != NULL;
  ok &= (body->v[0] = alloc_array(9 * (size_t)np, sizeof(double))) != NULL;
  if (ok)
    for (int k = 1; k < 9; ++k) {
      body->u[k] = body->u[0] + (size_t)k * (size_t)np;
      body->v[k] = body->v[0] + (size_t)k * (size_t)np;
    }
  ok &= (body->rest_volume = alloc_array((size_t)np, sizeof(double))) != NULL;
  ok &= (body->tet_material = alloc_array((size_t)np, sizeof(int32_t))) != NULL;
  ok &= (body->fhat = alloc_array(3 * (size_t)np, sizeof(double))) != NULL;
  ok &= (body->det_f = alloc_array((size_t)np, sizeof(double))) != NULL;
  ok &= (body->energy_density = alloc_array((size_t)np, sizeof(double))) != NULL;
  ok &= (body->block_energy = alloc_array(nb, sizeof(double))) != NULL;
  ok &= (body->block_inverted = alloc_array(nb, sizeof(int32_t))) != NULL;
  ok &= (body->block_min_det = alloc_array(nb, sizeof(double))) != NULL;
  ok &= (body->materials = alloc_array((size_t)def->material_count, sizeof(piola_material))) != NULL;
  ok &= (body->tets = alloc_array(4 * (size_t)nt, sizeof(int32_t))) != NULL;
  ok &= (body->rest_positions = alloc_array(3 * (size_t)nv, sizeof(double))) != NULL;
  ok &= (body->masses = alloc_array((size_t)nv, sizeof(double))) != NULL;
  ok &= (body->positions = alloc_array(3 * (size_t)nv, sizeof(double))) != NULL;
  if (nb >= PIOLA_PARALLEL_MIN_BLOCKS)
    ok &= (body->chunk_forces = alloc_array(PIOLA_FORCE_CHUNKS * 3 * (size_t)nv, sizeof(double))) != NULL;
  if (!ok) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "elastic body with %d tets: out of memory", (int)nt);

  memcpy(body->materials, def->materials, sizeof(piola_material) * (size_t)def->material_count);
  memcpy(body->rest_positions, mesh->positions, sizeof(double) * 3 * (size_t)nv);
  memcpy(body->positions, mesh->positions, sizeof(double) * 3 * (size_t)nv);
  body->uniform_material = def->tet_materials ? def->tet_materials[0] : 0;

  double min_altitude = INFINITY;
  for (int32_t t = 0; t < nt; ++t) {
    int32_t idx[4];
    for (int c = 0; c < 4; ++c) idx[c] = mesh->tets[4 * t + c];
    vec3 x0 = vec3_load(mesh->positions + 3 * idx[0]);
    vec3 x1 = vec3_load(mesh->positions + 3 * idx[1]);
    vec3 x2 = vec3_load(mesh->positions + 3 * idx[2]);
    vec3 x3 = vec3_load(mesh->positions + 3 * idx[3]);
    mat3 dm = mat3_from_columns(vec3_sub(x1, x0), vec3_sub(x2, x0), vec3_sub(x3, x0));
    double volume = mat3_det(dm) / 6.0;
    double longest = 0;
    vec3 xs[4] = {x0, x1, x2, x3};
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) longest = fmax(longest, vec3_norm(vec3_sub(xs[a], xs[b])));
    if (!(fabs(volume) > DEGENERATE_VOLUME_RATIO * longest * longest * longest))
      return PIOLA_FAIL(PIOLA_ERROR_DEGENERATE_ELEMENT,
                        "rest tet %d (vertices %d %d %d %d) is degenerate: volume %g m^3, "
                        "longest edge %g m", (int)t, (int)idx[0], (int)idx[1], (int)idx[2],
                        (int)idx[3], volume, longest);
    if (volume < 0) {
      /* reorient: swapping corners 1 and 2 flips the sign of the volume */
      int32_t tmp = idx[1]; idx[1] = idx[2]; idx[2] = tmp;
      vec3 tx = x1; x1 = x2; x2 = tx;
      dm = mat3_from_columns(vec3_sub(x1, x0), vec3_sub(x2, x0), vec3_sub(x3, x0));
      volume = -volume;
    }
    mat3 dm_inv = mat3_inverse(dm);
    const double geometric_volume = volume;
    if (def->material_fractions) volume *= def->material_fractions[t];
    for (int c = 0; c < 4; ++c) {
      body->tets[4 * t + c] = idx[c];
      body->tet_vertices[c][t] = idx[c];
      body->masses[idx[c]] += 0.25 * def->density * volume;
    }
    for (int k = 0; k < 9; ++k) body->dm_inv[k][t] = dm_inv.m[k / 3][k % 3];
    body->rest_volume[t] = volume;
    int32_t m = def->tet_materials ? def->tet_materials[t] : 0;
    body->tet_material[t] = m;
    if (m != body->uniform_material) body->uniform_material = -1;
    /* altitude from each corner = 3 V0 / area of the opposite face */
    double areas[4] = {triangle_area(x1, x2, x3), triangle_area(x0, x2, x3),
                       triangle_area(x0, x1, x3), triangle_area(x0, x1, x2)};
    for (int c = 0; c < 4; ++c) min_altitude = fmin(min_altitude, 3.0 * geometric_volume / areas[c]);
  }
  /* padding tets: zero Dm^-1 and volume, all corners at vertex 0, the first material */
  for (int32_t t = nt; t < np; ++t) body->tet_material[t] = body->uniform_material >= 0 ? body->uniform_material : 0;
  if (body->uniform_material >= 0) {
    const piola_material *um = &body->materials[body->uniform_material];
    /* calloc: pages stay unmapped until the force loop writes them (a local split's) */
    /* Ogden's powers (Mooney-Rivlin's are closed forms, which its force loop and the pass
     * evaluate without a cache) */
    if (um->model == PIOLA_MODEL_OGDEN && um->inversion_mode != PIOLA_INVERSION_ENERGY &&
        !(body->ogden_cache = calloc(OGDEN_CACHE_SLOTS * (size_t)np, sizeof(double))))
      return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "elastic body with %d tets: out of memory", (int)nt);
    if (STEP_CACHE_MODEL(um->model) && um->inversion_mode != PIOLA_INVERSION_ENERGY &&
        !(um->model == PIOLA_MODEL_HGO && def->fiber_directions) &&
        !(body->step_cache = calloc(STEP_CACHE_SLOTS * (size_t)(np / PIOLA_TET_BLOCK), sizeof(double))))
      return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "elastic body with %d tets: out of memory", (int)nt);
    if (um->model == PIOLA_MODEL_HGO && def->fiber_directions &&
        !(body->hgo_cache = calloc(HGO_CACHE_SLOTS * (size_t)np, sizeof(double))))
      return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "elastic body with %d tets: out of memory", (int)nt);
  }
  body->min_rest_altitude = min_altitude;
  PIOLA_TRY(piola__fiber_copy(body, def));

  double speed = 0;
  for (int32_t m = 0; m < def->material_count; ++m) {
    const piola_material *mat = &def->materials[m];
    speed = fmax(speed, sqrt(fmax(0.0, mat->lambda + 2.0 * mat->mu + mat->fiber_modulus) /
                              def->density));
  }
  body->max_wave_speed = speed;
  if (write_state) piola__elastic_body_rest_rotations(body, NULL);
  body->energy_valid = 1; /* zero at rest */
  body->last_stiffness_scale = 1.0;
  return piola__damping_matrix_init(&body->damping, body);
}

void piola__elastic_body_drop_step_caches(piola_elastic_body *body) {
  free(body->step_cache), body->step_cache = NULL;
  free(body->ogden_cache), body->ogden_cache = NULL;
  free(body->hgo_cache), body->hgo_cache = NULL;
}
