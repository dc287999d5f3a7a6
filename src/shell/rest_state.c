/* The rest state of a shell body: validation, per-triangle rest frames (Dm^-1), volumes and
 * lumped masses, the hinges at interior edges with their rest weights and angles, the
 * incidence lists and the CFL quantities. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "material/membrane_kernels.h"
#include "math/mat3.h"
#include "mesh/element_input.h"
#include "shell/shell_body_internal.h"
#include "shell/shell_stable_step.h"

/* A rest triangle whose area is below this fraction of (longest edge)^2 is degenerate:
 * its Dm^-1 would be meaningless. */
#define DEGENERATE_AREA_RATIO 1e-12

static void *alloc_array(size_t count, size_t size) { return calloc(count == 0 ? 1 : count, size); }

void piola__shell_body_free_arrays(piola_shell_body *body) {
  free(body->triangles);
  free(body->hinges);
  free(body->triangle_forces);
  free(body->hinge_forces);
  free(body->tri_start);
  free(body->tri_incidence);
  free(body->hinge_start);
  free(body->hinge_incidence);
  free(body->triangle_indices);
  free(body->hinge_indices);
  free(body->rest_angles);
  free(body->angles);
  free(body->fhat);
  free(body->fp_inv);
  free(body->materials);
  free(body->rest_positions);
  free(body->masses);
  free(body->inverse_sqrt_masses);
  free(body->vertex_rate2);
  if (body->pattern) {
    free(body->pattern->row_start), free(body->pattern->col);
    free(body->pattern->triangle_slot), free(body->pattern->hinge_slot);
    free(body->pattern);
  }
  memset(body, 0, sizeof *body);
}

static piola_status validate_def(const piola_shell_body_def *def) {
  if (!def) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "shell body def is NULL");
  const piola_tri_mesh *mesh = def->rest_mesh;
  if (!mesh) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "shell body rest_mesh is NULL");
  if (mesh->vertex_count <= 0 || mesh->triangle_count <= 0 || !mesh->positions || !mesh->triangles)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "shell body rest_mesh needs vertices and triangles (got %d vertices, %d "
                      "triangles)",
                      (int)mesh->vertex_count, (int)mesh->triangle_count);
  if (mesh->triangle_count > INT32_MAX / 8)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "shell body has too many triangles (%d)",
                      (int)mesh->triangle_count);
  if (!(def->thickness > 0) || !isfinite(def->thickness))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "thickness must be > 0 m, got %g",
                      def->thickness);
  if (!(def->density > 0) || !isfinite(def->density))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "density must be > 0 kg/m^3, got %g",
                      def->density);
  const piola_shell_bending_def *b = &def->bending;
  if (!(b->stiffness >= 0) || !isfinite(b->stiffness))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "bending.stiffness must be >= 0 N m, got %g",
                      b->stiffness);
  if (!(b->damping >= 0) || !isfinite(b->damping))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "bending.damping must be >= 0 N m s, got %g",
                      b->damping);
  if (!(b->yield_angle >= 0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "bending.yield_angle must be >= 0 rad (INFINITY: no plastic bending), got %g",
                      b->yield_angle);
  if (!(b->plastic_rate > 0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "bending.plastic_rate must be > 0 1/s, got %g",
                      b->plastic_rate);
  const piola_shell_plasticity_def *p = &def->plasticity;
  if (!(p->yield_strain >= 0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "plasticity.yield_strain must be >= 0 (INFINITY: no plasticity), got %g",
                      p->yield_strain);
  if (!(p->rate > 0))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "plasticity.rate must be > 0 1/s, got %g",
                      p->rate);
  if (!(p->max_plastic_stretch > 1) || !isfinite(p->max_plastic_stretch))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "plasticity.max_plastic_stretch must be finite and > 1, got %g",
                      p->max_plastic_stretch);
  PIOLA_TRY(piola__check_element_input("shell body", "triangle", 3, mesh->vertex_count,
                                       mesh->positions, mesh->triangle_count, mesh->triangles,
                                       def->materials, def->material_count,
                                       def->triangle_materials));
  if (def->reference_normals)
    for (int32_t i = 0; i < 3 * mesh->triangle_count; ++i)
      if (!isfinite(def->reference_normals[i]))
        return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "reference normal of triangle %d is not finite",
                          (int)(i / 3));
  return PIOLA_OK;
}

/* Counting sort of (element, slot) pairs by vertex: each vertex's list is in element order. */
static piola_status build_incidence(int32_t vertex_count, int32_t element_count, int slots,
                                    const int32_t *elements, int32_t **start_out,
                                    int32_t **incidence_out) {
  int32_t *start = alloc_array((size_t)vertex_count + 1, sizeof(int32_t));
  int32_t *incidence = alloc_array((size_t)slots * (size_t)element_count, sizeof(int32_t));
  int32_t *fill = alloc_array((size_t)vertex_count, sizeof(int32_t));
  if (!start || !incidence || !fill) {
    free(start);
    free(incidence);
    free(fill);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "shell body incidence: out of memory");
  }
  for (int32_t e = 0; e < element_count; ++e)
    for (int c = 0; c < slots; ++c) start[elements[slots * e + c] + 1]++;
  for (int32_t i = 0; i < vertex_count; ++i) start[i + 1] += start[i];
  for (int32_t e = 0; e < element_count; ++e)
    for (int c = 0; c < slots; ++c) {
      int32_t v = elements[slots * e + c];
      incidence[start[v] + fill[v]++] = slots * e + c;
    }
  free(fill);
  *start_out = start;
  *incidence_out = incidence;
  return PIOLA_OK;
}

/* An undirected edge key with the triangle and corner it came from. */
typedef struct edge_record {
  int32_t a, b;     /* a < b */
  int32_t triangle; /* triangle index */
  int32_t corner;   /* the edge runs from corner to corner + 1 (mod 3) */
} edge_record;

static int compare_edges(const void *pa, const void *pb) {
  const edge_record *x = pa, *y = pb;
  if (x->a != y->a) return x->a < y->a ? -1 : 1;
  if (x->b != y->b) return x->b < y->b ? -1 : 1;
  if (x->triangle != y->triangle) return x->triangle < y->triangle ? -1 : 1;
  return 0;
}

/* Hinges: every edge shared by exactly two triangles, in order of (a, b). x3 -> x4 is the
 * edge as the first triangle winds it, x1 that triangle's third corner, x2 the other's. */
static piola_status build_hinges(piola_shell_body *body) {
  const int32_t nt = body->triangle_count;
  edge_record *edges = alloc_array(3 * (size_t)nt, sizeof(edge_record));
  if (!edges) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "shell body edges: out of memory");
  for (int32_t t = 0; t < nt; ++t)
    for (int c = 0; c < 3; ++c) {
      int32_t p = body->triangles[t].v[c], q = body->triangles[t].v[(c + 1) % 3];
      edges[3 * t + c] = (edge_record){p < q ? p : q, p < q ? q : p, t, c};
    }
  qsort(edges, 3 * (size_t)nt, sizeof(edge_record), compare_edges);
  int32_t count = 0;
  for (size_t i = 0; i < 3 * (size_t)nt;) {
    size_t j = i;
    while (j < 3 * (size_t)nt && edges[j].a == edges[i].a && edges[j].b == edges[i].b) ++j;
    if (j - i == 2 && edges[i].triangle != edges[i + 1].triangle) ++count;
    i = j;
  }
  body->hinge_count = count;
  body->hinges = alloc_array((size_t)count, sizeof(shell_hinge));
  if (!body->hinges) {
    free(edges);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "shell body hinges: out of memory");
  }
  int32_t h = 0;
  for (size_t i = 0; i < 3 * (size_t)nt;) {
    size_t j = i;
    while (j < 3 * (size_t)nt && edges[j].a == edges[i].a && edges[j].b == edges[i].b) ++j;
    if (j - i == 2 && edges[i].triangle != edges[i + 1].triangle) {
      const shell_triangle *ta = &body->triangles[edges[i].triangle];
      const shell_triangle *tb = &body->triangles[edges[i + 1].triangle];
      int c = edges[i].corner;
      shell_hinge *hg = &body->hinges[h++];
      hg->v[2] = ta->v[c];
      hg->v[3] = ta->v[(c + 1) % 3];
      hg->v[0] = ta->v[(c + 2) % 3];
      hg->v[1] = tb->v[(edges[i + 1].corner + 2) % 3];
    }
    i = j;
  }
  free(edges);
  return PIOLA_OK;
}

static double tri_area(const double *a, const double *b, const double *c) {
  vec3 pa = vec3_load(a);
  return 0.5 * vec3_norm(vec3_cross(vec3_sub(vec3_load(b), pa), vec3_sub(vec3_load(c), pa)));
}

piola_status piola__shell_body_build(piola_shell_body *body, const piola_shell_body_def *def) {
  PIOLA_TRY(validate_def(def));
  const piola_tri_mesh *mesh = def->rest_mesh;
  const int32_t nv = mesh->vertex_count, nt = mesh->triangle_count;
  body->vertex_count = nv;
  body->triangle_count = nt;
  body->thickness = def->thickness;
  body->density = def->density;
  body->bending = def->bending;
  body->plasticity = def->plasticity;
  body->use_reference_normals = def->use_reference_normals;
  body->material_count = def->material_count;
  body->last_stiffness_scale = 1.0;

  int ok = 1;
  ok &= (body->triangles = alloc_array((size_t)nt, sizeof(shell_triangle))) != NULL;
  ok &= (body->triangle_forces = alloc_array(9 * (size_t)nt, sizeof(double))) != NULL;
  ok &= (body->triangle_indices = alloc_array(3 * (size_t)nt, sizeof(int32_t))) != NULL;
  ok &= (body->fhat = alloc_array(2 * (size_t)nt, sizeof(double))) != NULL;
  ok &= (body->fp_inv = alloc_array(4 * (size_t)nt, sizeof(double))) != NULL;
  ok &= (body->materials = alloc_array((size_t)def->material_count, sizeof(piola_material))) != NULL;
  ok &= (body->rest_positions = alloc_array(3 * (size_t)nv, sizeof(double))) != NULL;
  ok &= (body->masses = alloc_array((size_t)nv, sizeof(double))) != NULL;
  if (!ok)
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "shell body with %d triangles: out of memory",
                      (int)nt);
  memcpy(body->rest_positions, mesh->positions, sizeof(double) * 3 * (size_t)nv);
  double speed = 0;
  for (int32_t m = 0; m < def->material_count; ++m) {
    body->materials[m] = membrane_material_from(&def->materials[m]);
    speed = fmax(speed, sqrt((body->materials[m].lambda + 2.0 * body->materials[m].mu) /
                             def->density));
  }
  body->max_wave_speed = speed;

  double min_altitude = INFINITY;
  for (int32_t t = 0; t < nt; ++t) {
    shell_triangle *tri = &body->triangles[t];
    for (int c = 0; c < 3; ++c) tri->v[c] = body->triangle_indices[3 * t + c] = mesh->triangles[3 * t + c];
    tri->material = def->triangle_materials ? def->triangle_materials[t] : 0;
    vec3 x0 = vec3_load(mesh->positions + 3 * tri->v[0]);
    vec3 e1 = vec3_sub(vec3_load(mesh->positions + 3 * tri->v[1]), x0);
    vec3 e2 = vec3_sub(vec3_load(mesh->positions + 3 * tri->v[2]), x0);
    vec3 n = vec3_cross(e1, e2);
    double area = 0.5 * vec3_norm(n);
    double l1 = vec3_norm(e1), l2 = vec3_norm(e2), l3 = vec3_norm(vec3_sub(e2, e1));
    double longest = fmax(l1, fmax(l2, l3));
    if (!(area > DEGENERATE_AREA_RATIO * longest * longest))
      return PIOLA_FAIL(PIOLA_ERROR_DEGENERATE_ELEMENT,
                        "rest triangle %d (vertices %d %d %d) is degenerate: area %g m^2, longest "
                        "edge %g m",
                        (int)t, (int)tri->v[0], (int)tri->v[1], (int)tri->v[2], area, longest);
    /* rest frame: t1 along e1, t2 in the plane, Dm = [[|e1|, e2.t1], [0, e2.t2]] */
    vec3 t1 = vec3_scale(e1, 1.0 / l1);
    double a = vec3_dot(e2, t1);
    double b = 2.0 * area / l1; /* e2 . t2 */
    /* Dm^-1 = [[1/|e1|, -a/(|e1| b)], [0, 1/b]] */
    tri->dm_inv[0] = 1.0 / l1;
    tri->dm_inv[1] = -a / (l1 * b);
    tri->dm_inv[2] = 0.0;
    tri->dm_inv[3] = 1.0 / b;
    tri->fp_inv[0] = tri->fp_inv[3] = 1.0;
    memcpy(tri->dm_inv_eff, tri->dm_inv, sizeof tri->dm_inv);
    tri->volume = area * def->thickness;
    if (def->reference_normals)
      for (int k = 0; k < 3; ++k) tri->reference[k] = def->reference_normals[3 * t + k];
    else
      vec3_store(tri->reference, n);
    tri->u[0] = tri->u[3] = 1.0;
    tri->vrot[0] = tri->vrot[3] = 1.0;
    tri->fhat[0] = tri->fhat[1] = 1.0;
    body->fhat[2 * t] = body->fhat[2 * t + 1] = 1.0;
    body->fp_inv[4 * t] = body->fp_inv[4 * t + 3] = 1.0;
    for (int c = 0; c < 3; ++c) body->masses[tri->v[c]] += def->density * tri->volume / 3.0;
    min_altitude = fmin(min_altitude, 2.0 * area / longest);
  }
  /* plastic flow can shrink the effective rest shape by up to max_plastic_stretch */
  body->min_rest_altitude = isfinite(def->plasticity.yield_strain)
                                ? min_altitude / def->plasticity.max_plastic_stretch
                                : min_altitude;

  PIOLA_TRY(build_hinges(body));
  const int32_t nh = body->hinge_count;
  ok &= (body->hinge_forces = alloc_array(12 * (size_t)nh, sizeof(double))) != NULL;
  ok &= (body->hinge_indices = alloc_array(4 * (size_t)nh, sizeof(int32_t))) != NULL;
  ok &= (body->rest_angles = alloc_array((size_t)nh, sizeof(double))) != NULL;
  ok &= (body->angles = alloc_array((size_t)nh, sizeof(double))) != NULL;
  if (!ok)
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "shell body with %d hinges: out of memory",
                      (int)nh);
  body->inverse_sqrt_masses = alloc_array((size_t)nv, sizeof(double));
  body->vertex_rate2 = alloc_array((size_t)nv, sizeof(double));
  if (!body->inverse_sqrt_masses || !body->vertex_rate2)
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "shell body: out of memory");
  for (int32_t i = 0; i < nv; ++i)
    body->inverse_sqrt_masses[i] = body->masses[i] > 0 ? 1.0 / sqrt(body->masses[i]) : 0.0;
  for (int32_t h = 0; h < nh; ++h) {
    shell_hinge *hg = &body->hinges[h];
    const double *p[4];
    for (int k = 0; k < 4; ++k) {
      body->hinge_indices[4 * h + k] = hg->v[k];
      p[k] = mesh->positions + 3 * hg->v[k];
    }
    double a1 = tri_area(p[0], p[2], p[3]), a2 = tri_area(p[1], p[2], p[3]);
    vec3 e = vec3_sub(vec3_load(p[3]), vec3_load(p[2]));
    /* 2, not BMF03's 1/2 (|N| = 2 A): calibrated so that D is the plate's flexural rigidity */
    hg->weight = 2.0 * vec3_dot(e, e) / (a1 + a2);
    hg->rest_angle = piola__hinge_angle(p[0], p[1], p[2], p[3], hg->grad);
    hg->angle = hg->rest_angle;
    body->rest_angles[h] = body->angles[h] = hg->rest_angle;
  }
  /* bending stability: the step bound's Gershgorin estimate (shell_stable_step.h) at the
   * rest gradients; the time scale is 1 / omega */
  const double largest = piola__shell_body_bending_rate2(body);
  body->bending_time_scale = largest > 0 ? 1.0 / sqrt(largest) : INFINITY;

  PIOLA_TRY(build_incidence(nv, nt, 3, body->triangle_indices, &body->tri_start,
                            &body->tri_incidence));
  PIOLA_TRY(build_incidence(nv, nh, 4, body->hinge_indices, &body->hinge_start,
                            &body->hinge_incidence));
  return PIOLA_OK;
}
