/* The triangle pass: project, light at the corners, bin into bands of rows, fill.
 *
 * Coverage samples the pixel centre (a pixel belongs to a triangle when its centre is
 * inside or on an edge), so a silhouette covers the pixels whose centres fall inside the
 * projected outline: the pixel count of a disk is its area up to the boundary's jitter.
 * Depth is interpolated perspective-correctly (1/z is affine in screen space); colours are
 * interpolated in screen space, which is invisible on triangles a few pixels wide. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "piola/threads.h"
#include "render/render_internal.h"

enum { BAND_ROWS = 16 };

typedef struct tri_setup {
  float rgb[3][3];        /* lit colour at each corner, 0..255 */
  int32_t x0, x1, y0, y1; /* pixel bounding box, inclusive; y0 > y1 when culled */
} tri_setup;

piola_status piola__render_triangles(const render_camera *cam, const piola_render_mesh *mesh,
                                     const float *face_rgb, float *depth, uint8_t *rgb) {
  const int32_t nv = mesh->vertex_count, nt = mesh->triangle_count;
  const int W = cam->width, H = cam->height;
  double *proj = malloc(3 * (size_t)(nv > 0 ? nv : 1) * sizeof *proj); /* sx, sy, z */
  double *vn = calloc(3 * (size_t)(nv > 0 ? nv : 1), sizeof *vn);
  tri_setup *setup = malloc((size_t)nt * sizeof *setup);
  int32_t band_count = (H + BAND_ROWS - 1) / BAND_ROWS;
  int64_t *band_start = calloc((size_t)band_count + 1, sizeof *band_start);
  if (!proj || !vn || !setup || !band_start) {
    free(proj), free(vn), free(setup), free(band_start);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "render: out of memory for %d triangles", (int)nt);
  }
  const double *x = mesh->positions;
  const int32_t *tri = mesh->triangles;

#pragma omp parallel for schedule(static) num_threads(piola_thread_count())
  for (int32_t v = 0; v < nv; ++v) {
    vec3 d = vec3_sub(vec3_load(x + 3 * (size_t)v), cam->position);
    double z = vec3_dot(d, cam->forward);
    double inv = z > 0 ? cam->focal_px / z : 0;
    proj[3 * (size_t)v] = 0.5 * W + vec3_dot(d, cam->right) * inv;
    proj[3 * (size_t)v + 1] = 0.5 * H - vec3_dot(d, cam->up) * inv;
    proj[3 * (size_t)v + 2] = z;
  }
  /* area-weighted vertex normals, summed in triangle order (deterministic) */
  for (int32_t t = 0; t < nt; ++t) {
    const int32_t *c = tri + 3 * (size_t)t;
    vec3 a = vec3_load(x + 3 * (size_t)c[0]), b = vec3_load(x + 3 * (size_t)c[1]),
         e = vec3_load(x + 3 * (size_t)c[2]);
    vec3 n = vec3_cross(vec3_sub(b, a), vec3_sub(e, a));
    for (int k = 0; k < 3; ++k) {
      double *p = vn + 3 * (size_t)c[k];
      p[0] += n.x, p[1] += n.y, p[2] += n.z;
    }
  }

  const double near_z = 1e-6;
#pragma omp parallel for schedule(static) num_threads(piola_thread_count())
  for (int32_t t = 0; t < nt; ++t) {
    tri_setup *s = &setup[t];
    s->y0 = 1, s->y1 = 0;
    const int32_t *c = tri + 3 * (size_t)t;
    const double *p0 = proj + 3 * (size_t)c[0], *p1 = proj + 3 * (size_t)c[1],
                 *p2 = proj + 3 * (size_t)c[2];
    if (!(p0[2] > near_z && p1[2] > near_z && p2[2] > near_z)) continue; /* behind or at the eye */
    double area = (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0]);
    if (!(area != 0) || !isfinite(area)) continue;
    double fx0 = fmin(p0[0], fmin(p1[0], p2[0])), fx1 = fmax(p0[0], fmax(p1[0], p2[0]));
    double fy0 = fmin(p0[1], fmin(p1[1], p2[1])), fy1 = fmax(p0[1], fmax(p1[1], p2[1]));
    /* pixels whose centres (i + 0.5) can be inside */
    double ix0 = ceil(fx0 - 0.5), ix1 = floor(fx1 - 0.5), iy0 = ceil(fy0 - 0.5),
           iy1 = floor(fy1 - 0.5);
    if (ix0 < 0) ix0 = 0;
    if (iy0 < 0) iy0 = 0;
    if (ix1 > W - 1) ix1 = W - 1;
    if (iy1 > H - 1) iy1 = H - 1;
    if (ix0 > ix1 || iy0 > iy1) continue;
    vec3 a = vec3_load(x + 3 * (size_t)c[0]), b = vec3_load(x + 3 * (size_t)c[1]),
         e = vec3_load(x + 3 * (size_t)c[2]);
    vec3 fn = vec3_cross(vec3_sub(b, a), vec3_sub(e, a));
    double fl = vec3_norm(fn);
    fn = fl > 0 ? vec3_scale(fn, 1.0 / fl) : cam->forward;
    vec3 centroid = vec3_scale(vec3_add(vec3_add(a, b), e), 1.0 / 3);
    double facing = vec3_dot(fn, vec3_sub(cam->position, centroid));
    double flip = facing < 0 ? -1 : 1; /* light the side that faces the camera */
    const float *base = face_rgb + 3 * (size_t)t;
    for (int k = 0; k < 3; ++k) {
      vec3 pos = vec3_load(x + 3 * (size_t)c[k]);
      vec3 n = vec3_load(vn + 3 * (size_t)c[k]);
      double nl = vec3_norm(n);
      /* a vertex normal more than ~35 degrees off the face (creases, folds, box edges)
       * gives way to it: smooth surfaces look smooth and sharp edges stay sharp */
      n = (nl > 0 && vec3_dot(n, fn) > 0.82 * nl) ? vec3_scale(n, 1.0 / nl) : fn;
      n = vec3_scale(n, flip);
      vec3 eye = vec3_sub(cam->position, pos);
      double el = vec3_norm(eye);
      eye = el > 0 ? vec3_scale(eye, 1.0 / el) : vec3_neg(cam->forward);
      float spec;
      float light = render_light(cam, n, eye, &spec);
      for (int ch = 0; ch < 3; ++ch) s->rgb[k][ch] = base[ch] * light + 255.f * spec;
    }
    s->x0 = (int32_t)ix0, s->x1 = (int32_t)ix1, s->y0 = (int32_t)iy0, s->y1 = (int32_t)iy1;
  }

  /* bin: count, prefix sum, fill in triangle order */
  for (int32_t t = 0; t < nt; ++t)
    if (setup[t].y0 <= setup[t].y1)
      for (int32_t b = setup[t].y0 / BAND_ROWS; b <= setup[t].y1 / BAND_ROWS; ++b)
        ++band_start[b + 1];
  for (int32_t b = 0; b < band_count; ++b) band_start[b + 1] += band_start[b];
  int32_t *binned =
      malloc((size_t)(band_start[band_count] > 0 ? band_start[band_count] : 1) * sizeof *binned);
  int64_t *fill = malloc((size_t)band_count * sizeof *fill);
  if (!binned || !fill) {
    free(proj), free(vn), free(setup), free(band_start), free(binned), free(fill);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "render: out of memory binning %d triangles",
                      (int)nt);
  }
  memcpy(fill, band_start, (size_t)band_count * sizeof *fill);
  for (int32_t t = 0; t < nt; ++t)
    if (setup[t].y0 <= setup[t].y1)
      for (int32_t b = setup[t].y0 / BAND_ROWS; b <= setup[t].y1 / BAND_ROWS; ++b)
        binned[fill[b]++] = t;

#pragma omp parallel for schedule(dynamic, 1) num_threads(piola_thread_count())
  for (int32_t b = 0; b < band_count; ++b) {
    int32_t row0 = b * BAND_ROWS, row1 = row0 + BAND_ROWS - 1;
    if (row1 > H - 1) row1 = H - 1;
    for (int64_t k = band_start[b]; k < band_start[b + 1]; ++k) {
      int32_t t = binned[k];
      const tri_setup *s = &setup[t];
      const int32_t *c = tri + 3 * (size_t)t;
      const double *p[3] = {proj + 3 * (size_t)c[0], proj + 3 * (size_t)c[1],
                            proj + 3 * (size_t)c[2]};
      double area =
          (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]);
      double inv_area = 1.0 / area;
      /* barycentric weight of corner k: edge function of the opposite edge / area */
      double A[3], B[3], C[3];
      for (int q = 0; q < 3; ++q) {
        const double *u = p[(q + 1) % 3], *v = p[(q + 2) % 3];
        A[q] = (u[1] - v[1]) * inv_area;
        B[q] = (v[0] - u[0]) * inv_area;
        C[q] = (u[0] * v[1] - v[0] * u[1]) * inv_area;
      }
      double iz[3] = {1.0 / p[0][2], 1.0 / p[1][2], 1.0 / p[2][2]};
      int32_t y0 = s->y0 > row0 ? s->y0 : row0, y1 = s->y1 < row1 ? s->y1 : row1;
      for (int32_t py = y0; py <= y1; ++py) {
        double cy = py + 0.5;
        for (int32_t px = s->x0; px <= s->x1; ++px) {
          double cx = px + 0.5;
          double w0 = A[0] * cx + B[0] * cy + C[0];
          double w1 = A[1] * cx + B[1] * cy + C[1];
          double w2 = A[2] * cx + B[2] * cy + C[2];
          if (w0 < 0 || w1 < 0 || w2 < 0) continue;
          double z = 1.0 / (w0 * iz[0] + w1 * iz[1] + w2 * iz[2]);
          size_t i = (size_t)py * (size_t)W + (size_t)px;
          if (!((float)z < depth[i])) continue;
          depth[i] = (float)z;
          for (int ch = 0; ch < 3; ++ch) {
            double v = w0 * s->rgb[0][ch] + w1 * s->rgb[1][ch] + w2 * s->rgb[2][ch] + 0.5;
            rgb[3 * i + (size_t)ch] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v);
          }
        }
      }
    }
  }
  free(proj), free(vn), free(setup), free(band_start), free(binned), free(fill);
  return PIOLA_OK;
}
