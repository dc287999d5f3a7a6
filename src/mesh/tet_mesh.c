/* Tetrahedral mesh core: ownership, validation, orientation and the boundary surface. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "math/mat3.h"
#include "mesh/mesh_internal.h"
#include "piola/mesh.h"

const int piola__tet_faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};

void piola_tet_mesh_free(piola_tet_mesh *mesh) {
  if (!mesh) return;
  free(mesh->positions);
  free(mesh->tets);
  free(mesh->tet_regions);
  free(mesh->tet_fibers);
  memset(mesh, 0, sizeof *mesh);
}

piola_status piola_tet_mesh_copy(const piola_tet_mesh *source, piola_tet_mesh *out) {
  if (!source || !out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "tet mesh copy: NULL argument");
  memset(out, 0, sizeof *out);
  if (source->vertex_count < 0 || source->tet_count < 0)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "tet mesh copy: negative counts");
  size_t nv = (size_t)source->vertex_count, nt = (size_t)source->tet_count;
  out->positions = malloc(3 * nv * sizeof(double) + 1);
  out->tets = malloc(4 * nt * sizeof(int32_t) + 1);
  if (source->tet_regions) out->tet_regions = malloc(nt * sizeof(int32_t) + 1);
  if (source->tet_fibers) out->tet_fibers = malloc(3 * nt * sizeof(double) + 1);
  if (!out->positions || !out->tets || (source->tet_regions && !out->tet_regions) ||
      (source->tet_fibers && !out->tet_fibers)) {
    piola_tet_mesh_free(out);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "tet mesh copy: out of memory");
  }
  if (nv) memcpy(out->positions, source->positions, 3 * nv * sizeof(double));
  if (nt) memcpy(out->tets, source->tets, 4 * nt * sizeof(int32_t));
  if (source->tet_regions && nt) memcpy(out->tet_regions, source->tet_regions, nt * sizeof(int32_t));
  if (source->tet_fibers && nt) memcpy(out->tet_fibers, source->tet_fibers, 3 * nt * sizeof(double));
  out->vertex_count = source->vertex_count;
  out->tet_count = source->tet_count;
  return PIOLA_OK;
}

piola_status piola_tet_mesh_validate(const piola_tet_mesh *mesh) {
  if (!mesh) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "tet mesh is NULL");
  if (mesh->vertex_count < 0 || mesh->tet_count < 0)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "tet mesh has negative counts (%d vertices, %d tets)",
                      (int)mesh->vertex_count, (int)mesh->tet_count);
  if ((mesh->vertex_count > 0 && !mesh->positions) || (mesh->tet_count > 0 && !mesh->tets))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "tet mesh arrays are NULL");
  for (int32_t i = 0; i < 3 * mesh->vertex_count; ++i)
    if (!isfinite(mesh->positions[i]))
      return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "vertex %d has a non-finite coordinate", (int)(i / 3));
  for (int32_t t = 0; t < mesh->tet_count; ++t)
    for (int k = 0; k < 4; ++k) {
      int32_t v = mesh->tets[4 * t + k];
      if (v < 0 || v >= mesh->vertex_count)
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "tet %d: vertex index %d out of range [0, %d)", (int)t,
                          (int)v, (int)mesh->vertex_count);
      for (int j = 0; j < k; ++j)
        if (mesh->tets[4 * t + j] == v)
          return PIOLA_FAIL(PIOLA_ERROR_DEGENERATE_ELEMENT, "tet %d repeats vertex %d", (int)t, (int)v);
    }
  for (int32_t t = 0; mesh->tet_fibers && t < mesh->tet_count; ++t)
    for (int k = 0; k < 3; ++k)
      if (!isfinite(mesh->tet_fibers[3 * (size_t)t + (size_t)k]))
        return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "tet %d: fibre direction is not finite", (int)t);
  return PIOLA_OK;
}

piola_status piola_tet_mesh_transform(piola_tet_mesh *mesh, piola_mat3 linear, piola_vec3 translation) {
  if (!mesh) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "tet mesh transform: NULL mesh");
  if (!mat3_is_finite(linear))
    return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE,
                      "tet mesh transform: the matrix has a non-finite entry");
  if (!isfinite(translation.x) || !isfinite(translation.y) || !isfinite(translation.z))
    return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE,
                      "tet mesh transform: the translation has a non-finite entry");
  double det = mat3_det(linear);
  if (!(det > 0) || !isfinite(det))
    return PIOLA_FAIL(
        PIOLA_ERROR_INVALID_ARGUMENT,
        "tet mesh transform: the matrix must have a finite positive determinant, got det %g", det);
  for (int32_t i = 0; i < mesh->vertex_count; ++i) {
    double *p = mesh->positions + 3 * (size_t)i;
    vec3_store(p, vec3_add(mat3_mul_vec(linear, vec3_load(p)), translation));
  }
  for (int32_t t = 0; mesh->tet_fibers && t < mesh->tet_count; ++t) {
    double *d = mesh->tet_fibers + 3 * (size_t)t;
    vec3 a = vec3_load(d), b = mat3_mul_vec(linear, a);
    double la = vec3_norm(a), lb = vec3_norm(b);
    /* a material direction is a tangent vector: it maps by the linear part; its length
     * (often 1 by convention, or a weight) is kept */
    vec3_store(d, lb > 0 ? vec3_scale(b, la / lb) : a);
  }
  return PIOLA_OK;
}

double piola_tet_mesh_signed_volume(const piola_tet_mesh *mesh, int32_t t) {
  const int32_t *c = mesh->tets + 4 * (size_t)t;
  vec3 x0 = vec3_load(mesh->positions + 3 * (size_t)c[0]);
  vec3 e1 = vec3_sub(vec3_load(mesh->positions + 3 * (size_t)c[1]), x0);
  vec3 e2 = vec3_sub(vec3_load(mesh->positions + 3 * (size_t)c[2]), x0);
  vec3 e3 = vec3_sub(vec3_load(mesh->positions + 3 * (size_t)c[3]), x0);
  return vec3_dot(e1, vec3_cross(e2, e3)) / 6.0;
}

int32_t piola_tet_mesh_orient(piola_tet_mesh *mesh) {
  int32_t flipped = 0;
  for (int32_t t = 0; t < mesh->tet_count; ++t) {
    if (piola_tet_mesh_signed_volume(mesh, t) < 0) {
      int32_t *c = mesh->tets + 4 * (size_t)t;
      int32_t s = c[2];
      c[2] = c[3];
      c[3] = s;
      ++flipped;
    }
  }
  return flipped;
}

void piola__sort_small(int32_t *v, int n) {
  for (int i = 1; i < n; ++i) {
    int32_t x = v[i];
    int j = i - 1;
    while (j >= 0 && v[j] > x) {
      v[j + 1] = v[j];
      --j;
    }
    v[j + 1] = x;
  }
}

static int key_less(const int32_t *keys, int width, int32_t a, int32_t b) {
  for (int k = 1; k < width; ++k) {
    int32_t x = keys[(size_t)width * a + k], y = keys[(size_t)width * b + k];
    if (x != y) return x < y;
  }
  return a < b; /* stable: ties keep input order */
}

int piola__group_keys(const int32_t *keys, int32_t count, int width, int32_t vertex_count, int32_t *order,
                      int32_t *start) {
  memset(start, 0, ((size_t)vertex_count + 1) * sizeof(int32_t));
  for (int32_t i = 0; i < count; ++i) start[keys[(size_t)width * i] + 1]++;
  for (int32_t v = 0; v < vertex_count; ++v) start[v + 1] += start[v];
  int32_t *fill = malloc(((size_t)vertex_count + 1) * sizeof(int32_t));
  if (!fill) return -1;
  memcpy(fill, start, ((size_t)vertex_count + 1) * sizeof(int32_t));
  for (int32_t i = 0; i < count; ++i) order[fill[keys[(size_t)width * i]]++] = i;
  free(fill);
  /* Insertion sort inside each bucket by the remaining key entries; buckets are small. */
  for (int32_t v = 0; v < vertex_count; ++v) {
    int32_t b = start[v], e = start[v + 1];
    for (int32_t i = b + 1; i < e; ++i) {
      int32_t x = order[i];
      int32_t j = i - 1;
      while (j >= b && key_less(keys, width, x, order[j])) {
        order[j + 1] = order[j];
        --j;
      }
      order[j + 1] = x;
    }
  }
  return 0;
}

static int keys_equal(const int32_t *keys, int width, int32_t a, int32_t b) {
  return memcmp(keys + (size_t)width * a, keys + (size_t)width * b, (size_t)width * sizeof(int32_t)) == 0;
}

piola_status piola_tet_mesh_boundary(const piola_tet_mesh *mesh, piola_tri_mesh *out) {
  if (!out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "boundary: output is NULL");
  memset(out, 0, sizeof *out);
  PIOLA_TRY(piola_tet_mesh_validate(mesh));
  size_t nf = 4 * (size_t)mesh->tet_count;
  if (nf > INT32_MAX) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "boundary: too many tets");
  int32_t *keys = malloc(3 * nf * sizeof(int32_t) + 1);
  int32_t *order = malloc(nf * sizeof(int32_t) + 1);
  int32_t *start = malloc(((size_t)mesh->vertex_count + 1) * sizeof(int32_t));
  int32_t *kept = malloc(nf * sizeof(int32_t) + 1);
  piola_status status = PIOLA_OK;
  if (!keys || !order || !start || !kept) {
    status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "boundary: out of memory");
    goto done;
  }
  for (size_t f = 0; f < nf; ++f) {
    const int32_t *c = mesh->tets + 4 * (f / 4);
    for (int k = 0; k < 3; ++k) keys[3 * f + k] = c[piola__tet_faces[f % 4][k]];
    piola__sort_small(keys + 3 * f, 3);
  }
  if (piola__group_keys(keys, (int32_t)nf, 3, mesh->vertex_count, order, start) != 0) {
    status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "boundary: out of memory");
    goto done;
  }
  int32_t kept_count = 0;
  for (size_t i = 0; i < nf;) {
    size_t j = i + 1;
    while (j < nf && keys_equal(keys, 3, order[i], order[j])) ++j;
    if (j - i == 1) kept[kept_count++] = order[i];
    i = j;
  }
  /* Keep faces in tet order so the output does not depend on the grouping. */
  int32_t *mark = order; /* reuse as a flag array */
  memset(mark, 0, nf * sizeof(int32_t));
  for (int32_t i = 0; i < kept_count; ++i) mark[kept[i]] = 1;
  out->triangles = malloc(3 * (size_t)kept_count * sizeof(int32_t) + 1);
  out->positions = malloc(3 * (size_t)mesh->vertex_count * sizeof(double) + 1);
  if (!out->triangles || !out->positions) {
    piola_tri_mesh_free(out);
    status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "boundary: out of memory");
    goto done;
  }
  int32_t n = 0;
  for (size_t f = 0; f < nf; ++f) {
    if (!mark[f]) continue;
    const int32_t *c = mesh->tets + 4 * (f / 4);
    for (int k = 0; k < 3; ++k) out->triangles[3 * (size_t)n + k] = c[piola__tet_faces[f % 4][k]];
    ++n;
  }
  out->triangle_count = n;
  out->vertex_count = mesh->vertex_count;
  if (mesh->vertex_count) memcpy(out->positions, mesh->positions, 3 * (size_t)mesh->vertex_count * sizeof(double));
done:
  free(keys);
  free(order);
  free(start);
  free(kept);
  return status;
}

/* "file:line" when the line is known, else "file". */
static const char *where(char *buf, size_t size, const char *source, const int32_t *lines, int32_t t) {
  if (lines) snprintf(buf, size, "%s:%d", source, (int)lines[t]);
  else snprintf(buf, size, "%s", source);
  return buf;
}

piola_status piola__tet_mesh_finish(piola_tet_mesh *mesh, const char *source, const int32_t *lines) {
  char at[1024];
  if (mesh->tet_count == 0)
    return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: the mesh has no tetrahedra", source);
  for (int32_t i = 0; i < 3 * mesh->vertex_count; ++i)
    if (!isfinite(mesh->positions[i]))
      return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: vertex %d has a non-finite coordinate", source, (int)(i / 3));
  for (int32_t t = 0; t < mesh->tet_count; ++t) {
    const int32_t *c = mesh->tets + 4 * (size_t)t;
    for (int k = 0; k < 4; ++k) {
      if (c[k] < 0 || c[k] >= mesh->vertex_count)
        return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: tet %d: vertex index out of range", source, (int)t);
      for (int j = 0; j < k; ++j)
        if (c[j] == c[k])
          return PIOLA_FAIL(PIOLA_ERROR_DEGENERATE_ELEMENT, "%s: tet %d (element %d in the file) repeats a vertex",
                            where(at, sizeof at, source, lines, t), (int)t, (int)t + 1);
    }
    /* Zero volume relative to the tet's size: |6V| <= 1e-12 * (longest edge)^3. */
    vec3 x0 = vec3_load(mesh->positions + 3 * (size_t)c[0]);
    vec3 e1 = vec3_sub(vec3_load(mesh->positions + 3 * (size_t)c[1]), x0);
    vec3 e2 = vec3_sub(vec3_load(mesh->positions + 3 * (size_t)c[2]), x0);
    vec3 e3 = vec3_sub(vec3_load(mesh->positions + 3 * (size_t)c[3]), x0);
    double lmax2 = fmax(fmax(fmax(vec3_norm2(e1), vec3_norm2(e2)), fmax(vec3_norm2(e3), vec3_norm2(vec3_sub(e2, e1)))),
                        fmax(vec3_norm2(vec3_sub(e3, e1)), vec3_norm2(vec3_sub(e3, e2))));
    double v6 = vec3_dot(e1, vec3_cross(e2, e3));
    if (!(v6 * v6 > 1e-24 * lmax2 * lmax2 * lmax2))
      return PIOLA_FAIL(PIOLA_ERROR_DEGENERATE_ELEMENT,
                        "%s: tet %d (element %d in the file) is degenerate (zero volume)",
                        where(at, sizeof at, source, lines, t), (int)t, (int)t + 1);
  }
  /* Duplicated tets: same vertex set twice. */
  size_t nt = (size_t)mesh->tet_count;
  int32_t *keys = malloc(4 * nt * sizeof(int32_t));
  int32_t *order = malloc(nt * sizeof(int32_t));
  int32_t *start = malloc(((size_t)mesh->vertex_count + 1) * sizeof(int32_t));
  piola_status status = PIOLA_OK;
  if (!keys || !order || !start) {
    status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", source);
  } else {
    memcpy(keys, mesh->tets, 4 * nt * sizeof(int32_t));
    for (size_t t = 0; t < nt; ++t) piola__sort_small(keys + 4 * t, 4);
    if (piola__group_keys(keys, (int32_t)nt, 4, mesh->vertex_count, order, start) != 0) {
      status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", source);
    } else {
      for (size_t i = 0; i + 1 < nt; ++i)
        if (keys_equal(keys, 4, order[i], order[i + 1])) {
          int32_t a = order[i] < order[i + 1] ? order[i] : order[i + 1];
          int32_t b = order[i] < order[i + 1] ? order[i + 1] : order[i];
          status = PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: tet %d (element %d in the file) duplicates tet %d",
                              where(at, sizeof at, source, lines, b), (int)b, (int)b + 1, (int)a);
          break;
        }
    }
  }
  free(keys);
  free(order);
  free(start);
  if (status != PIOLA_OK) return status;
  piola_tet_mesh_orient(mesh);
  return PIOLA_OK;
}
