/* Internal pieces of the preview renderer.
 *
 * Why a software rasterizer: previews must come out of a headless server with no GPU and no
 * display, from a library that already links only libpng. A z-buffer rasterizer over
 * triangles is simple, exact about coverage (the silhouette tests count pixels) and fast
 * enough: 100K triangles at 1280x720 take tens of milliseconds.
 *
 * One frame is drawn in two passes that share a depth buffer of view-space depth (the
 * distance along the camera's forward axis, m):
 *   1. a ray pass over every pixel: background gradient, ground checkerboard (analytic plane
 *      intersection) and obstacles (sphere tracing of their signed distance inside their
 *      bounding sphere). Obstacles are implicit surfaces of any shape, so tracing the
 *      distance field draws every shape, and its motion, with no tessellation to cache.
 *   2. the surface triangles, binned into horizontal bands of rows; each band is owned by
 *      one thread, so no two threads touch the same pixel and the result is identical for
 *      any thread count. Triangles in a band are drawn in index order and a tie in depth
 *      keeps the earlier one, so the image is fully deterministic.
 * Lighting is computed at triangle corners (two-sided: the side facing the camera is lit)
 * and interpolated; base colours are per face, so per-face flags (inverted elements) and
 * per-face values stay crisp. */
#ifndef PIOLA_RENDER_RENDER_INTERNAL_H
#define PIOLA_RENDER_RENDER_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>

#include "math/mat3.h"
#include "piola/render.h"

/* Colours the tests look for, so they are named once. */
#define RENDER_INVERTED_R 230
#define RENDER_INVERTED_G 28
#define RENDER_INVERTED_B 36
#define RENDER_OBSTACLE_R 178
#define RENDER_OBSTACLE_G 170
#define RENDER_OBSTACLE_B 156

typedef struct render_rgb {
  float r, g, b; /* 0..255 */
} render_rgb;

typedef struct render_camera {
  vec3 position, forward, right, up; /* orthonormal forward, right, up */
  vec3 key, fill;                    /* unit directions towards the lights (view-fixed) */
  double focal_px;                   /* focal length in pixels */
  int32_t width, height;
} render_camera;

struct piola_renderer {
  piola_render_def def;
  char label[128];
  /* Mesh obstacles are also kept as triangles (t = 0 pose): they are rasterized, since
   * tracing a mesh's distance field costs tens of microseconds per query. */
  piola_tri_mesh *obstacle_meshes; /* per obstacle; empty for analytic shapes */
  piola_obstacle **obstacles;
  int32_t obstacle_count, obstacle_capacity;
  vec3 camera_position, camera_target;
  double ground_height; /* m along up, for the fallback ground */
  double checker_size;  /* m */
  double scene_size;    /* m, for fog and tracing tolerances */
  /* Planes as a finite floor (set by fit_camera): a square of half side floor_half_size
   * centred under floor_center, fading out at its edge; walls are not drawn. INFINITY:
   * every plane is drawn whole (a camera set without fitting). */
  vec3 floor_center;
  double floor_half_size; /* m */
  /* per-frame buffers, reused */
  float *depth;
  size_t depth_capacity;
};

render_camera piola__render_camera(const piola_renderer *r);

/* Brightness of a surface with unit normal n seen along the unit vector `to_eye` (from the
 * surface to the camera): a key light from the upper left of the view, a weak fill from
 * the right and ambient light. Two-sided: a normal facing away is flipped. *spec receives
 * the specular highlight (0..1, white). */
static inline float render_light(const render_camera *c, vec3 n, vec3 to_eye, float *spec) {
  if (vec3_dot(n, to_eye) < 0) n = vec3_neg(n);
  const vec3 key = c->key, fill = c->fill;
  double kd = vec3_dot(n, key), fd = vec3_dot(n, fill);
  vec3 h = vec3_add(key, to_eye);
  double hn = vec3_norm(h);
  double s = hn > 0 ? vec3_dot(n, h) / hn : 0;
  s = s > 0 ? s : 0;
  s *= s, s *= s, s *= s, s *= s, s *= s; /* s^32 */
  *spec = (float)(0.22 * s);
  return (float)(0.30 + 0.62 * (kd > 0 ? kd : 0) + 0.16 * (fd > 0 ? fd : 0));
}

/* Shadows on the ground (shadow_map.c): heights of the surfaces along the sun direction on
 * a square grid; size 0 means no shadows. */
typedef struct render_shadow {
  vec3 sun, u, v; /* unit direction towards the sun; grid axes */
  double u0, v0;  /* m: grid origin along u, v */
  double texel;   /* m */
  int size;       /* texels per side, 0: none */
  float *height;  /* size * size, m along sun; -inf where no surface */
} render_shadow;

/* The sun: `up` tilted towards the key light's side. */
vec3 piola__render_sun(const render_camera *cam, vec3 up);
/* Builds the map of mesh (NULL or empty: none). Never fails for lack of memory: then no
 * shadows are drawn. */
piola_status piola__render_shadow_build(vec3 sun, const piola_render_mesh *mesh, render_shadow *s);
void piola__render_shadow_free(render_shadow *s);
/* Fraction (0..1) of shadow at world point p. */
double piola__render_shadow_at(const render_shadow *s, vec3 p);

/* Pass 1: background, ground and obstacles for every pixel; fills depth (m) and rgb. The
 * ground is darkened where `shadow` says so. */
void piola__render_ray_pass(const piola_renderer *r, const render_camera *cam, double time,
                            const render_shadow *shadow, float *depth, uint8_t *rgb);

/* Pass 2: the surface triangles, with per-face base colours (3 floats each, 0..255). */
piola_status piola__render_triangles(const render_camera *cam, const piola_render_mesh *mesh,
                                     const float *face_rgb, float *depth, uint8_t *rgb);

/* Colour map (0..1 -> viridis: dark purple, blue, teal, green, yellow; never red). */
render_rgb piola__render_colormap(double s);

/* A colour range [lo, hi] no wider than this fraction of max(|lo|, |hi|) is rounding noise
 * around one value (color_bar.c says why this much). */
#define RENDER_UNIFORM_TOLERANCE 1e-6
/* Whether [lo, hi] (lo <= hi) is one value: hi - lo <= RENDER_UNIFORM_TOLERANCE max(|lo|,
 * |hi|), which includes lo == hi. */
bool piola__render_range_is_uniform(double lo, double hi);
/* Where value v falls on the colour map for the range [lo, hi]: (v - lo) / (hi - lo), or for
 * a uniform range 0.5 (the middle) within the tolerance of its centre, 0 below, 1 above. */
double piola__render_range_position(double v, double lo, double hi);

/* Vertical colour bar at the right edge with labels of the range [lo, hi] (hi, middle, lo,
 * with as many digits as tell them apart), or for a uniform range the middle colour and one
 * label, the value. */
void piola__render_color_bar(piola_image *image, double lo, double hi, const char *label);

/* Text in the built-in 5x7 bitmap font; scale is the pixel size of one font dot. Unknown
 * characters are drawn as blanks. Returns the width drawn, pixels. */
int piola__render_text(piola_image *image, int x, int y, int scale, const char *text, uint8_t r,
                       uint8_t g, uint8_t b);
int piola__render_text_width(const char *text, int scale);

/* Fills a rectangle, clipped to the image. */
void piola__render_fill_rect(piola_image *image, int x0, int y0, int w, int h, uint8_t r, uint8_t g,
                             uint8_t b);

/* A frame read from a VTU file (frame_read.c). */
typedef struct render_cell_field {
  char name[64];
  double *values; /* per cell */
} render_cell_field;

struct piola_render_frame {
  int64_t point_count, cell_count;
  double *points;    /* 3 * point_count, m */
  double *rest;      /* 3 * point_count rest positions (points - displacement), or NULL */
  int32_t *tets;     /* 4 * tet_count vertex indices */
  int32_t *tet_cell; /* cell index of each tet */
  int32_t tet_count;
  int32_t *surface;      /* 3 * surface_count vertex indices */
  int32_t *surface_cell; /* owning cell of each face */
  int32_t surface_count;
  uint8_t *cell_inverted;
  int32_t inverted_count;
  render_cell_field *fields;
  int field_count;
  /* filled per call of piola_render_frame_mesh */
  uint8_t *face_inverted;
  double *face_values;
  int32_t *face_parts;
};

/* Allocates (or reuses) image storage for width x height. */
piola_status piola__image_resize(piola_image *image, int32_t width, int32_t height);

#endif
