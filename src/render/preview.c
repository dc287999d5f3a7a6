/* Previews during `piola run`: a scene copy, optional per-frame images, and preview.png.
 *
 * The preview reads back the VTU the frame writer just wrote instead of looking into the
 * world: the picture then shows exactly what was saved, and the renderer stays downstream
 * of the output stage (data flows one way). */
#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/status_report.h"
#include "piola/files.h"
#include "piola/scene.h"
#include "render/render_internal.h"

struct piola_preview {
  char dir[3600];
  bool every_frame;
  piola_renderer *renderer; /* created at frame 0, camera fitted to it */
  char scene[PATH_MAX];     /* absolute scene path, or "" */
  piola_vec3 lo0, hi0;      /* frame 0 bounds */
  int32_t last_frame;
  double last_time;
};

piola_status piola_preview_open(const char *dir, const char *scene_path, bool every_frame,
                                piola_preview **out) {
  if (!dir || !out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "preview: NULL argument");
  *out = NULL;
  if (strlen(dir) >= 3500)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "preview: path too long");
  piola_preview *p = calloc(1, sizeof *p);
  if (!p) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "preview: out of memory");
  snprintf(p->dir, sizeof p->dir, "%s", dir);
  p->every_frame = every_frame;
  p->last_frame = -1;
  p->lo0 = (piola_vec3){INFINITY, INFINITY, INFINITY};
  p->hi0 = (piola_vec3){-INFINITY, -INFINITY, -INFINITY};
  piola_status st = PIOLA_OK;
  if (scene_path) {
    if (!realpath(scene_path, p->scene)) p->scene[0] = '\0';
    char copy[4096];
    snprintf(copy, sizeof copy, "%s/scene.json", dir);
    st = piola_scene_copy_resolved(scene_path, copy);
  }
  if (st == PIOLA_OK && every_frame) {
    char path[4096];
    snprintf(path, sizeof path, "%s/render", dir);
    if (mkdir(path, 0777) != 0 && errno != EEXIST)
      st = PIOLA_FAIL(PIOLA_ERROR_IO, "cannot create %s: %s", path, strerror(errno));
    DIR *d = st == PIOLA_OK ? opendir(path) : NULL;
    if (d) { /* images of an earlier run (with --force) */
      char file[4400];
      for (struct dirent *e; (e = readdir(d));)
        if (strncmp(e->d_name, "frame_", 6) == 0 && strstr(e->d_name, ".png")) {
          snprintf(file, sizeof file, "%s/%s", path, e->d_name);
          unlink(file);
        }
      closedir(d);
    }
  }
  if (st != PIOLA_OK) {
    free(p);
    return st;
  }
  *out = p;
  return PIOLA_OK;
}

/* Renders frame `frame` of the folder to png with renderer r (created on first use). */
static piola_status render_to(piola_preview *p, piola_renderer **r, bool fit_union, int32_t frame,
                              double time, const char *png) {
  char path[4096];
  snprintf(path, sizeof path, "%s/frames/frame_%04d.vtu", p->dir, (int)frame);
  piola_render_frame *f;
  PIOLA_TRY(piola_render_frame_read(path, &f));
  piola_vec3 lo, hi;
  piola_render_frame_bounds(f, &lo, &hi);
  piola_status st = PIOLA_OK;
  if (!*r) {
    piola_render_def def = piola_default_render_def();
    def.color = PIOLA_RENDER_COLOR_INVERTED;
    /* Frame by frame, later frames are unknown: no made-up ground under frame 0 (a scene's
     * plane obstacles are still drawn), and a margin for motion. */
    def.ground = fit_union;
    st = piola_renderer_create(&def, r);
    if (st == PIOLA_OK && p->scene[0]) {
      st = piola_renderer_load_scene_obstacles(*r, p->scene);
      if (st != PIOLA_OK) st = PIOLA_OK; /* draw the solids anyway */
    }
    if (st == PIOLA_OK) {
      if (fit_union) {
        lo = (piola_vec3){fmin(lo.x, p->lo0.x), fmin(lo.y, p->lo0.y), fmin(lo.z, p->lo0.z)};
        hi = (piola_vec3){fmax(hi.x, p->hi0.x), fmax(hi.y, p->hi0.y), fmax(hi.z, p->hi0.z)};
      } else {
        piola_vec3 c = {0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), 0.5 * (lo.z + hi.z)};
        lo = (piola_vec3){c.x + 1.3 * (lo.x - c.x), c.y + 1.3 * (lo.y - c.y),
                          c.z + 1.3 * (lo.z - c.z)};
        hi = (piola_vec3){c.x + 1.3 * (hi.x - c.x), c.y + 1.3 * (hi.y - c.y),
                          c.z + 1.3 * (hi.z - c.z)};
      }
      if (lo.x <= hi.x) piola_renderer_fit_camera(*r, lo, hi);
    }
  }
  piola_render_mesh mesh;
  piola_image img = {0};
  if (st == PIOLA_OK) st = piola_render_frame_mesh(f, NULL, time, &mesh);
  if (st == PIOLA_OK) st = piola_renderer_render(*r, &mesh, &img);
  if (st == PIOLA_OK) {
    char text[96];
    snprintf(text, sizeof text, "FRAME %d  T = %.3f S  INVERTED %d", (int)frame, time,
             (int)piola_render_frame_inverted_count(f));
    piola_image_draw_label(&img, 16, 16, 2, text);
    st = piola_image_write_png(png, &img);
  }
  piola_image_free(&img);
  piola_render_frame_destroy(f);
  return st;
}

piola_status piola_preview_frame_written(piola_preview *p, int32_t frame, double time) {
  if (!p) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "preview: NULL argument");
  if (p->last_frame < 0 && frame == 0) {
    /* remember frame 0's bounds for the final preview's camera */
    char path[4096];
    snprintf(path, sizeof path, "%s/frames/frame_0000.vtu", p->dir);
    piola_render_frame *f;
    if (piola_render_frame_read(path, &f) == PIOLA_OK) {
      piola_render_frame_bounds(f, &p->lo0, &p->hi0);
      piola_render_frame_destroy(f);
    }
  }
  p->last_frame = frame;
  p->last_time = time;
  if (!p->every_frame) return PIOLA_OK;
  char png[4096];
  snprintf(png, sizeof png, "%s/render/frame_%04d.png", p->dir, (int)frame);
  return render_to(p, &p->renderer, false, frame, time, png);
}

piola_status piola_preview_close(piola_preview *p) {
  if (!p) return PIOLA_OK;
  piola_status st = PIOLA_OK;
  if (p->last_frame >= 0) {
    char png[4096];
    snprintf(png, sizeof png, "%s/preview.png", p->dir);
    piola_renderer *r = NULL;
    st = render_to(p, &r, p->lo0.x <= p->hi0.x, p->last_frame, p->last_time, png);
    piola_renderer_destroy(r);
  }
  piola_renderer_destroy(p->renderer);
  free(p);
  return st;
}
