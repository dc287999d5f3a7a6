/* Generated sheets for cloth and shell scenes and tests: a rectangle with alternating
 * diagonals, a disk of concentric rings, and a (piece of a) torus surface. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "piola/shell_body.h"

static piola_status allocate(int64_t vertices, int64_t triangles, piola_tri_mesh *out) {
  if (vertices > INT32_MAX / 3 || triangles > INT32_MAX / 3)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "sheet too large: %lld vertices",
                      (long long)vertices);
  out->positions = calloc(3 * (size_t)vertices, sizeof(double));
  out->triangles = calloc(3 * (size_t)triangles, sizeof(int32_t));
  if (!out->positions || !out->triangles) {
    piola_tri_mesh_free(out);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "sheet with %lld vertices: out of memory",
                      (long long)vertices);
  }
  out->vertex_count = (int32_t)vertices;
  out->triangle_count = (int32_t)triangles;
  return PIOLA_OK;
}

piola_status piola_tri_mesh_rectangle(double width, double height, int32_t nx, int32_t ny,
                                      piola_tri_mesh *out) {
  if (!out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "rectangle: out is NULL");
  memset(out, 0, sizeof *out);
  if (!(width > 0) || !(height > 0) || !isfinite(width) || !isfinite(height))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "rectangle size must be finite and > 0 m, got %g x %g", width, height);
  if (nx < 1 || ny < 1 || nx > 1000000 || ny > 1000000)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "rectangle resolution must be in 1..1000000 cells per side, got %d x %d",
                      (int)nx, (int)ny);
  PIOLA_TRY(allocate((int64_t)(nx + 1) * (ny + 1), 2 * (int64_t)nx * ny, out));
  for (int32_t j = 0; j <= ny; ++j)
    for (int32_t i = 0; i <= nx; ++i) {
      double *p = out->positions + 3 * ((size_t)j * (nx + 1) + i);
      p[0] = -0.5 * width + width * i / nx;
      p[1] = -0.5 * height + height * j / ny;
      p[2] = 0.0;
    }
  int32_t *t = out->triangles;
  for (int32_t j = 0; j < ny; ++j)
    for (int32_t i = 0; i < nx; ++i) {
      int32_t a = j * (nx + 1) + i, b = a + 1, c = a + nx + 1, d = c + 1;
      if ((i + j) % 2 == 0) { /* diagonal a-d */
        int32_t tri[6] = {a, b, d, a, d, c};
        memcpy(t, tri, sizeof tri);
      } else { /* diagonal b-c */
        int32_t tri[6] = {a, b, c, b, d, c};
        memcpy(t, tri, sizeof tri);
      }
      t += 6;
    }
  return PIOLA_OK;
}

piola_status piola_tri_mesh_disk(double radius, int32_t rings, piola_tri_mesh *out) {
  if (!out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "disk: out is NULL");
  memset(out, 0, sizeof *out);
  if (!(radius > 0) || !isfinite(radius))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "disk radius must be finite and > 0 m, got %g",
                      radius);
  if (rings < 1 || rings > 20000)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "disk rings must be in 1..20000, got %d",
                      (int)rings);
  /* ring k (k >= 1) starts at vertex 1 + 3 k (k - 1) and has 6 k vertices */
  int64_t vertices = 1 + 3 * (int64_t)rings * (rings + 1);
  int64_t triangles = 6 * (int64_t)rings * rings;
  PIOLA_TRY(allocate(vertices, triangles, out));
  for (int32_t k = 1; k <= rings; ++k) {
    int32_t start = 1 + 3 * k * (k - 1);
    for (int32_t s = 0; s < 6 * k; ++s) {
      double angle = 2.0 * M_PI * s / (6.0 * k), r = radius * k / rings;
      double *p = out->positions + 3 * (size_t)(start + s);
      p[0] = r * cos(angle);
      p[1] = r * sin(angle);
    }
  }
  int32_t *t = out->triangles;
  for (int32_t k = 1; k <= rings; ++k) {
    /* between ring k - 1 (inner, 6 (k - 1) vertices, or the centre) and ring k (outer) */
    int32_t outer = 1 + 3 * k * (k - 1), inner = k == 1 ? 0 : 1 + 3 * (k - 1) * (k - 2);
    int32_t n_out = 6 * k, n_in = k == 1 ? 1 : 6 * (k - 1);
    for (int32_t side = 0; side < 6; ++side)
      for (int32_t q = 0; q < k; ++q) {
        /* outer vertices o0 = side k + q, o1 = o0 + 1; inner vertex i0 = side (k - 1) + q */
        int32_t o0 = outer + (side * k + q) % n_out, o1 = outer + (side * k + q + 1) % n_out;
        int32_t i0 = inner + (k == 1 ? 0 : (side * (k - 1) + q) % n_in);
        int32_t i1 = inner + (k == 1 ? 0 : (side * (k - 1) + q + 1) % n_in);
        t[0] = o0, t[1] = o1, t[2] = i0;
        t += 3;
        if (q < k - 1) {
          t[0] = i0, t[1] = o1, t[2] = i1;
          t += 3;
        }
      }
  }
  return PIOLA_OK;
}

piola_status piola_tri_mesh_torus(double major_radius, double minor_radius, int32_t around,
                                  int32_t tube, double sweep_degrees, piola_tri_mesh *out) {
  if (!out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "torus: out is NULL");
  memset(out, 0, sizeof *out);
  if (!(minor_radius > 0) || !(major_radius > minor_radius) || !isfinite(major_radius))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "torus radii must satisfy 0 < minor_radius < radius, got %g and %g m",
                      minor_radius, major_radius);
  if (around < 3 || tube < 3 || around > 100000 || tube > 100000)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "torus segments must be in 3..100000, got %d around and %d tube",
                      (int)around, (int)tube);
  if (!(sweep_degrees > 0 && sweep_degrees <= 360))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "torus sweep must be in (0, 360] degrees, got %g",
                      sweep_degrees);
  const int closed = sweep_degrees == 360;
  const int32_t rings = closed ? around : around + 1;
  PIOLA_TRY(allocate((int64_t)rings * tube, 2 * (int64_t)around * tube, out));
  const double sweep = sweep_degrees * M_PI / 180.0;
  for (int32_t i = 0; i < rings; ++i) {
    double u = sweep * i / around;
    for (int32_t j = 0; j < tube; ++j) {
      double w = 2.0 * M_PI * j / tube;
      double rho = major_radius + minor_radius * cos(w);
      double *p = out->positions + 3 * ((size_t)i * tube + j);
      p[0] = rho * cos(u);
      p[1] = rho * sin(u);
      p[2] = minor_radius * sin(w);
    }
  }
  int32_t *t = out->triangles;
  for (int32_t i = 0; i < around; ++i)
    for (int32_t j = 0; j < tube; ++j) {
      int32_t i1 = (i + 1) % rings, j1 = (j + 1) % tube;
      int32_t a = i * tube + j, b = i1 * tube + j, c = i * tube + j1, d = i1 * tube + j1;
      /* (a, b, c) spans d/du x d/dw, which points out of the tube */
      t[0] = a, t[1] = b, t[2] = c;
      t[3] = b, t[4] = d, t[5] = c;
      t += 6;
    }
  return PIOLA_OK;
}
