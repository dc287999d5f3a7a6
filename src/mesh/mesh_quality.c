/* Element quality and surface topology. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "math/mat3.h"
#include "piola/mesh_quality.h"

static const double pi = 3.14159265358979323846;

void piola_tet_dihedral_angles(const double *x0, const double *x1, const double *x2, const double *x3,
                               double angles_degrees[6]) {
  const double *x[4] = {x0, x1, x2, x3};
  static const int edges[6][4] = {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2}, {1, 2, 0, 3}, {1, 3, 0, 2}, {2, 3, 0, 1}};
  for (int e = 0; e < 6; ++e) {
    /* Edge (a,b); the faces (a,b,c) and (a,b,d). Angle between c and d seen around the edge. */
    vec3 a = vec3_load(x[edges[e][0]]), b = vec3_load(x[edges[e][1]]);
    vec3 c = vec3_load(x[edges[e][2]]), d = vec3_load(x[edges[e][3]]);
    vec3 axis = vec3_sub(b, a);
    double l2 = vec3_norm2(axis);
    vec3 u = vec3_sub(c, a), w = vec3_sub(d, a);
    if (l2 > 0) {
      u = vec3_sub(u, vec3_scale(axis, vec3_dot(u, axis) / l2));
      w = vec3_sub(w, vec3_scale(axis, vec3_dot(w, axis) / l2));
    }
    double nu = vec3_norm(u), nw = vec3_norm(w);
    double angle = 0;
    if (nu > 0 && nw > 0) {
      double cosine = vec3_dot(u, w) / (nu * nw);
      angle = acos(cosine > 1 ? 1 : (cosine < -1 ? -1 : cosine)) * 180.0 / pi;
    }
    angles_degrees[e] = angle;
  }
}

static double face_area(vec3 a, vec3 b, vec3 c) { return 0.5 * vec3_norm(vec3_cross(vec3_sub(b, a), vec3_sub(c, a))); }

double piola_tet_aspect_ratio(const double *x0, const double *x1, const double *x2, const double *x3) {
  vec3 p[4] = {vec3_load(x0), vec3_load(x1), vec3_load(x2), vec3_load(x3)};
  double lmax = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) lmax = fmax(lmax, vec3_norm(vec3_sub(p[i], p[j])));
  double v = fabs(vec3_dot(vec3_sub(p[1], p[0]), vec3_cross(vec3_sub(p[2], p[0]), vec3_sub(p[3], p[0])))) / 6.0;
  double area = face_area(p[0], p[1], p[2]) + face_area(p[0], p[1], p[3]) + face_area(p[0], p[2], p[3]) +
                face_area(p[1], p[2], p[3]);
  if (!(v > 0) || !(area > 0)) return INFINITY;
  double inradius = 3.0 * v / area;
  return lmax / (2.0 * sqrt(6.0) * inradius);
}

double piola_tet_mean_ratio(const double *x0, const double *x1, const double *x2, const double *x3) {
  vec3 p[4] = {vec3_load(x0), vec3_load(x1), vec3_load(x2), vec3_load(x3)};
  double sum = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) sum += vec3_norm2(vec3_sub(p[i], p[j]));
  double lrms = sqrt(sum / 6.0);
  double v = fabs(vec3_dot(vec3_sub(p[1], p[0]), vec3_cross(vec3_sub(p[2], p[0]), vec3_sub(p[3], p[0])))) / 6.0;
  if (!(lrms > 0)) return 0;
  return 6.0 * sqrt(2.0) * v / (lrms * lrms * lrms);
}

piola_status piola_tet_mesh_measure(const piola_tet_mesh *mesh, piola_tet_mesh_quality *out) {
  if (!out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "mesh quality: output is NULL");
  memset(out, 0, sizeof *out);
  PIOLA_TRY(piola_tet_mesh_validate(mesh));
  out->min_volume = INFINITY;
  out->max_volume = -INFINITY;
  out->min_dihedral_degrees = 180;
  out->max_dihedral_degrees = 0;
  out->min_mean_ratio = INFINITY;
  for (int32_t t = 0; t < mesh->tet_count; ++t) {
    const int32_t *c = mesh->tets + 4 * (size_t)t;
    const double *x0 = mesh->positions + 3 * (size_t)c[0], *x1 = mesh->positions + 3 * (size_t)c[1],
                 *x2 = mesh->positions + 3 * (size_t)c[2], *x3 = mesh->positions + 3 * (size_t)c[3];
    double v = piola_tet_mesh_signed_volume(mesh, t);
    out->volume += v;
    out->min_volume = fmin(out->min_volume, v);
    out->max_volume = fmax(out->max_volume, v);
    double angles[6];
    piola_tet_dihedral_angles(x0, x1, x2, x3, angles);
    for (int k = 0; k < 6; ++k) {
      out->min_dihedral_degrees = fmin(out->min_dihedral_degrees, angles[k]);
      out->max_dihedral_degrees = fmax(out->max_dihedral_degrees, angles[k]);
    }
    out->min_mean_ratio = fmin(out->min_mean_ratio, piola_tet_mean_ratio(x0, x1, x2, x3));
    double aspect = piola_tet_aspect_ratio(x0, x1, x2, x3);
    /* Keep the few worst, sorted worst first (ties: lower index first). */
    int32_t n = out->worst_count;
    if (n < PIOLA_QUALITY_WORST || aspect > out->worst_aspect[n - 1]) {
      int32_t i = n < PIOLA_QUALITY_WORST ? n : n - 1;
      while (i > 0 && aspect > out->worst_aspect[i - 1]) {
        out->worst_aspect[i] = out->worst_aspect[i - 1];
        out->worst_tets[i] = out->worst_tets[i - 1];
        --i;
      }
      out->worst_aspect[i] = aspect;
      out->worst_tets[i] = t;
      if (n < PIOLA_QUALITY_WORST) ++out->worst_count;
    }
  }
  if (mesh->tet_count == 0) {
    out->min_volume = out->max_volume = 0;
    out->min_dihedral_degrees = out->max_dihedral_degrees = 0;
    out->min_mean_ratio = 0;
  }
  return PIOLA_OK;
}

static int cmp_u64(const void *a, const void *b) {
  uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
  return (x > y) - (x < y);
}

piola_status piola_tri_mesh_topology(const piola_tri_mesh *mesh, piola_surface_topology *out) {
  if (!mesh || !out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "surface topology: NULL argument");
  memset(out, 0, sizeof *out);
  size_t nf = (size_t)mesh->triangle_count, nv = (size_t)mesh->vertex_count;
  for (size_t i = 0; i < 3 * nf; ++i)
    if (mesh->triangles[i] < 0 || (size_t)mesh->triangles[i] >= nv)
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "triangle %zu has a vertex out of range", i / 3);
  /* Directed half-edges as (min << 32 | max) << 1 | (direction is min->max ? 0 : 1). */
  uint64_t *half = malloc(3 * nf * sizeof(uint64_t) + 1);
  int32_t *first_face = malloc((nv + 1) * sizeof(int32_t));
  if (!half || !first_face) {
    free(half);
    free(first_face);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "surface topology: out of memory");
  }
  memset(first_face, 0, (nv + 1) * sizeof(int32_t));
  for (size_t f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      uint32_t a = (uint32_t)mesh->triangles[3 * f + k], b = (uint32_t)mesh->triangles[3 * f + (k + 1) % 3];
      uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
      half[3 * f + k] = ((((uint64_t)lo << 32) | hi) << 1) | (a > b);
      first_face[a] = 1;
    }
  for (size_t v = 0; v < nv; ++v) out->used_vertices += first_face[v];
  qsort(half, 3 * nf, sizeof(uint64_t), cmp_u64);
  for (size_t i = 0; i < 3 * nf;) {
    size_t j = i + 1;
    while (j < 3 * nf && (half[j] >> 1) == (half[i] >> 1)) ++j;
    size_t uses = j - i;
    out->edges++;
    if (uses == 1) out->open_edges++;
    else if (uses > 2) out->nonmanifold_edges++;
    else if ((half[i] & 1) == (half[i + 1] & 1)) out->misoriented_edges++;
    i = j;
  }
  free(half);
  out->euler_characteristic = out->used_vertices - out->edges + (int32_t)nf;
  out->closed = out->open_edges == 0 && out->nonmanifold_edges == 0;
  out->oriented = out->misoriented_edges == 0;
  /* Vertex fans (closed surfaces): the link of each vertex must be one cycle. */
  if (out->closed && out->oriented) {
    int32_t *start = first_face;
    memset(start, 0, (nv + 1) * sizeof(int32_t));
    for (size_t i = 0; i < 3 * nf; ++i) start[mesh->triangles[i] + 1]++;
    for (size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
    int32_t *link = malloc(2 * 3 * nf * sizeof(int32_t) + 1);
    int32_t *fill = malloc((nv + 1) * sizeof(int32_t));
    if (!link || !fill) {
      free(link);
      free(fill);
      free(first_face);
      return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "surface topology: out of memory");
    }
    memcpy(fill, start, (nv + 1) * sizeof(int32_t));
    for (size_t f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k) {
        int32_t v = mesh->triangles[3 * f + k];
        int32_t slot = fill[v]++;
        link[2 * slot] = mesh->triangles[3 * f + (k + 1) % 3];
        link[2 * slot + 1] = mesh->triangles[3 * f + (k + 2) % 3];
      }
    for (size_t v = 0; v < nv; ++v) {
      int32_t b = start[v], e = start[v + 1];
      if (e == b) continue;
      int32_t from = link[2 * b], steps = 0, at = b;
      do {
        int32_t to = link[2 * at + 1];
        ++steps;
        at = -1;
        for (int32_t i = b; i < e; ++i)
          if (link[2 * i] == to) {
            at = i;
            break;
          }
        if (at < 0 || to == from) break;
      } while (steps <= e - b);
      if (steps != e - b) out->nonmanifold_vertices++;
    }
    free(link);
    free(fill);
  }
  free(first_face);
  out->manifold = out->nonmanifold_edges == 0 && out->nonmanifold_vertices == 0;
  return PIOLA_OK;
}

double piola_tri_mesh_enclosed_volume(const piola_tri_mesh *mesh) {
  double v = 0;
  for (int32_t f = 0; f < mesh->triangle_count; ++f) {
    const int32_t *q = mesh->triangles + 3 * (size_t)f;
    vec3 a = vec3_load(mesh->positions + 3 * (size_t)q[0]), b = vec3_load(mesh->positions + 3 * (size_t)q[1]),
         c = vec3_load(mesh->positions + 3 * (size_t)q[2]);
    v += vec3_dot(a, vec3_cross(b, c));
  }
  return v / 6.0;
}
