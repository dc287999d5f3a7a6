/* piola: a software preview renderer for simulation frames.
 *
 * Renders triangle surfaces (the boundary of solids, shells) together with the scene's
 * obstacles and a ground plane into an RGB image, on the CPU and without a display, so it
 * works on a server. Surfaces are rasterized with a z-buffer; obstacles are ray-marched
 * through their signed distance and composited by depth; the ground is a checkerboard.
 *
 *   piola_render_def def = piola_default_render_def();
 *   def.color = PIOLA_RENDER_COLOR_INVERTED;
 *   piola_renderer *r;
 *   piola_renderer_create(&def, &r);
 *   piola_renderer_load_scene_obstacles(r, "scene.json");      // optional
 *   piola_render_mesh mesh = {...};                            // or from piola_render_frame
 *   piola_renderer_fit_camera(r, lo, hi);                      // unless def sets a camera
 *   piola_image image = {0};
 *   piola_renderer_render(r, &mesh, &image);
 *   piola_image_write_png("frame.png", &image);
 *   piola_image_free(&image);
 *   piola_renderer_destroy(r);
 *
 * Output is deterministic: the same input gives the same bytes for any thread count.
 * See docs/rendering.md. */
#ifndef PIOLA_RENDER_H
#define PIOLA_RENDER_H

#include <stdbool.h>
#include <stdint.h>

#include "piola/export.h"
#include "piola/material.h"
#include "piola/math_types.h"
#include "piola/obstacle.h"
#include "piola/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* An 8-bit RGB image, rows top to bottom, 3 * width * height bytes. */
typedef struct piola_image {
  int32_t width, height; /* pixels */
  uint8_t *rgb;
} piola_image;

PIOLA_API void piola_image_free(piola_image *image);
/* Writes an 8-bit RGB PNG, whole or not at all. */
PIOLA_API piola_status piola_image_write_png(const char *path, const piola_image *image);
/* Reads an 8-bit RGB or RGBA PNG (alpha dropped) into image (freed first if it holds one). */
PIOLA_API piola_status piola_image_read_png(const char *path, piola_image *image);

/* A grid of `count` images, scaled down to tiles cell_width pixels wide (height following
 * the first image's aspect ratio), `columns` per row, each labelled with labels[i] (digits,
 * letters, '.', '-', '+', ':' and space; may be NULL). */
PIOLA_API piola_status piola_image_contact_sheet(const piola_image *images,
                                                 const char *const *labels, int32_t count,
                                                 int32_t columns, int32_t cell_width,
                                                 piola_image *out);

/* Draws text in the built-in 5x7 bitmap font at (x, y) (top left, pixels) on a dark box, with
 * `scale` pixels per font dot; characters as for contact-sheet labels. */
PIOLA_API void piola_image_draw_label(piola_image *image, int32_t x, int32_t y, int32_t scale,
                                      const char *text);

typedef enum piola_render_color {
  PIOLA_RENDER_COLOR_PLAIN = 0, /* one colour per part (solid), shaded */
  PIOLA_RENDER_COLOR_INVERTED,  /* plain, with faces of inverted elements in red */
  PIOLA_RENDER_COLOR_VALUE,     /* per-face scalar through a colour map, with a colour bar */
} piola_render_color;

typedef struct piola_render_def {
  int32_t width, height;    /* pixels, 16..16384. Default 1280 x 720 */
  piola_render_color color; /* Default PIOLA_RENDER_COLOR_PLAIN */
  /* Camera. With camera_set false, piola_renderer_fit_camera chooses one (a 3/4 view from
   * the front right, above) and these are ignored. */
  bool camera_set;            /* Default false */
  piola_vec3 camera_position; /* m */
  piola_vec3 camera_target;   /* m, the point at the image centre */
  piola_vec3 up;              /* world up direction (unit). Default (0, 0, 1) */
  double fov_degrees;         /* vertical field of view, degrees, in (1, 170). Default 40 */
  /* A checkerboard ground: where the scene has a plane obstacle it is drawn as the ground;
   * otherwise, with ground set, a ground plane is drawn through the lowest point given to
   * piola_renderer_fit_camera (or at ground_height when that was not called). */
  bool ground;          /* Default true */
  double ground_height; /* m along `up`. Default 0 */
  bool shadows;         /* the surfaces cast shadows on the ground. Default true */
  int32_t supersample;  /* 1..4: antialiasing by rendering s x s samples per pixel and
                           averaging them (s^2 times the cost). Default 1 */
  /* Colour-map range of PIOLA_RENDER_COLOR_VALUE; value_min >= value_max chooses the range
   * from each frame's values (the smaller of 0 and their minimum, to their 99th percentile).
   * A range no wider than 1e-6 max(|min|, |max|) is one value, the field uniform up to
   * rounding: faces within that of its centre take the middle colour, the rest an end colour,
   * and the bar shows that colour with the value (docs/rendering.md). */
  double value_min, value_max;
  const char *value_label; /* caption above the colour bar (copied), or NULL */
} piola_render_def;

PIOLA_API piola_render_def piola_default_render_def(void);

/* One frame's surface: triangles wound outward (counter-clockwise seen from outside);
 * shells may be wound either way, both sides are lit. */
typedef struct piola_render_mesh {
  int32_t vertex_count;
  const double *positions; /* 3 * vertex_count, m */
  int32_t triangle_count;
  const int32_t *triangles; /* 3 * triangle_count vertex indices */
  const uint8_t *inverted;  /* per triangle: nonzero on a face of an inverted element, or NULL */
  const double *values;     /* per triangle scalar for PIOLA_RENDER_COLOR_VALUE, or NULL */
  const int32_t *parts;     /* per triangle part (solid) index for the plain colours, or NULL */
  double time;              /* s: where scripted obstacles are */
} piola_render_mesh;

typedef struct piola_renderer piola_renderer;

PIOLA_API piola_status piola_renderer_create(const piola_render_def *def, piola_renderer **out);
PIOLA_API void piola_renderer_destroy(piola_renderer *renderer);

/* Adds an obstacle to draw (the definition is copied and validated as by
 * piola_obstacle_create). */
PIOLA_API piola_status piola_renderer_add_obstacle(piola_renderer *renderer,
                                                   const piola_obstacle_def *def);
/* Adds every obstacle of a scene file (piola/scene.h format); solids are not read. */
PIOLA_API piola_status piola_renderer_load_scene_obstacles(piola_renderer *renderer,
                                                           const char *scene_path);
/* Like piola_renderer_load_scene_obstacles, leaving out every obstacle and bone that one of
 * hide[0 .. hide_count) names: "all", a type ("plane", "sphere", ..., "mesh"), the `name` of
 * an obstacle or a bone, or "obstacles[i]" / "bones[i]" (0-based). A name that matches
 * nothing is an error (PIOLA_ERROR_INVALID_ARGUMENT, listing the names the scene has), and
 * nothing is added then. */
PIOLA_API piola_status piola_renderer_load_scene_obstacles_hiding(piola_renderer *renderer,
                                                                  const char *scene_path,
                                                                  const char *const *hide,
                                                                  int32_t hide_count);
/* The up direction of a scene file: minus its gravity at t = 0, normalized, or (0, 0, 1)
 * when that gravity is zero (piola's convention). Only the parser runs. */
PIOLA_API piola_status piola_render_scene_up(const char *scene_path, piola_vec3 *up);
PIOLA_API int32_t piola_renderer_obstacle_count(const piola_renderer *renderer);

/* Chooses the camera so the box [lo, hi] (m) fills the view, looking from the front right
 * and above, unless the def set a camera; also places the fallback ground at the box's
 * lowest point along `up`. The box is grown by the bounding spheres (at t = 0) of the
 * obstacles added so far that are no larger than the box and near it: add obstacles first
 * to frame them too, or after to frame the box alone (obstacles may then be cut by the
 * image border). Once fitted, planes (plane obstacles and the fallback ground) are drawn as
 * a finite floor: a square 8 times the framed box's radius across, centred under it and
 * fading out at its edge, and only planes that face up (normal within 60 degrees of `up`);
 * walls and ceilings are not drawn. */
PIOLA_API void piola_renderer_fit_camera(piola_renderer *renderer, piola_vec3 lo, piola_vec3 hi);

/* The camera in use (after fit_camera or from the def). */
PIOLA_API void piola_renderer_camera(const piola_renderer *renderer, piola_vec3 *position,
                                     piola_vec3 *target);

/* Renders mesh (may be NULL: obstacles and ground only) into image (allocated or resized). */
PIOLA_API piola_status piola_renderer_render(piola_renderer *renderer,
                                             const piola_render_mesh *mesh, piola_image *image);

/* A frame written by `piola run` (DIR/frames/frame_NNNN.vtu): the boundary surface of its
 * tets (and its triangles, for shells), with per-face flags of inverted elements and any
 * per-cell scalar field carried to the faces. */
typedef struct piola_render_frame piola_render_frame;

/* Reads a VTU file written by piola (appended raw data). A frame is inverted where its
 * `inverted` cell field is nonzero or, when that field is absent, where a tet's signed
 * volume is negative. */
PIOLA_API piola_status piola_render_frame_read(const char *vtu_path, piola_render_frame **out);
PIOLA_API void piola_render_frame_destroy(piola_render_frame *frame);
/* The frame's surface; `value_field` names a per-cell scalar to colour by (NULL: none).
 * Fails with PIOLA_ERROR_INVALID_ARGUMENT when the frame has no such field. Pointers stay
 * valid while the frame lives. */
PIOLA_API piola_status piola_render_frame_mesh(const piola_render_frame *frame,
                                               const char *value_field, double time,
                                               piola_render_mesh *out);
PIOLA_API bool piola_render_frame_has_field(const piola_render_frame *frame, const char *name);
/* Number of inverted elements (tets and triangles) in the frame. */
PIOLA_API int32_t piola_render_frame_inverted_count(const piola_render_frame *frame);
/* Whether the frame has a `displacement` point field, so rest positions are known. */
PIOLA_API bool piola_render_frame_has_rest_positions(const piola_render_frame *frame);
/* Adds the per-cell field "von_mises_stress" (Pa): the von Mises equivalent
 * sqrt(((P1 - P2)^2 + (P2 - P3)^2 + (P3 - P1)^2) / 2) of the principal first Piola-Kirchhoff
 * stresses of each tet, from its deformation gradient (rest positions are the points minus
 * the frame's `displacement` point field) and the material of its solid: materials[s] for
 * the tets whose `solid` cell field is s (0 without that field). Finite for flat and inverted
 * tets. A frame knows no plastic flow or keyframed stiffness: for such solids this is the
 * stress of the total deformation at unit stiffness scale. Triangle cells get 0.
 * PIOLA_ERROR_INVALID_ARGUMENT without a displacement field or when a solid has no material. */
PIOLA_API piola_status piola_render_frame_add_stress(piola_render_frame *frame,
                                                     const piola_material_def *materials,
                                                     int32_t material_count);
/* The materials of a scene file's solids, in order: the first `capacity` are written to
 * materials and *count receives the number of solids. Only the parser runs. */
PIOLA_API piola_status piola_render_scene_materials(const char *scene_path,
                                                    piola_material_def *materials, int32_t capacity,
                                                    int32_t *count);
/* Bounding box of the frame's points, m. */
PIOLA_API void piola_render_frame_bounds(const piola_render_frame *frame, piola_vec3 *lo,
                                         piola_vec3 *hi);

/* Previews written while `piola run` writes an output folder DIR:
 *   DIR/scene.json             a copy of the scene, relative mesh paths made absolute, so
 *                              `piola render DIR` finds the obstacles later
 *   DIR/render/frame_NNNN.png  every frame as it is written, when every_frame is set (the
 *                              camera is fitted to frame 0 and then holds still)
 *   DIR/preview.png            the last frame, written by piola_preview_close
 * Frames are read back from DIR/frames/frame_NNNN.vtu, so the preview shows exactly what
 * was saved. Inverted elements are drawn in red. */
typedef struct piola_preview piola_preview;

/* scene_path may be NULL (no obstacles, no copy). */
PIOLA_API piola_status piola_preview_open(const char *dir, const char *scene_path, bool every_frame,
                                          piola_preview **out);
/* Call after frame `frame` (time in s) was written to DIR. */
PIOLA_API piola_status piola_preview_frame_written(piola_preview *preview, int32_t frame,
                                                   double time);
/* Writes DIR/preview.png of the last frame written (if any) and frees the preview. */
PIOLA_API piola_status piola_preview_close(piola_preview *preview);

#ifdef __cplusplus
}
#endif

#endif
