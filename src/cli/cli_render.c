/* `piola render DIR`: pictures and a movie of a simulation's frames (docs/rendering.md).
 *
 * Reads DIR/frames/frame_NNNN.vtu (or, lacking those, DIR/surface/frame_NNNN.obj), the
 * scene's obstacles and gravity (--scene FILE, else DIR/scene.json when present) and the
 * frame times in DIR/sim.pvd, and writes DIR/render/frame_NNNN.png, optionally
 * DIR/render/contact_sheet.png and, when ffmpeg is on the PATH, DIR/render/movie.mp4. The
 * frames present when it starts are rendered, so it works on a running simulation. It
 * replaces the files it writes and deletes no other. Uses only the public API.
 * Exit codes: 0 done, 1 a failure while writing, 2 bad usage or input. */
#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "cli/cli_numbers.h"
#include "cli/commands.h"
#include "cli/render_cli.h"
#include "piola/threads.h"

static void usage(FILE *out) {
  fprintf(out,
          "usage: piola render DIR [options]\n"
          "\n"
          "Renders the frames of `piola run -o DIR` to DIR/render/frame_NNNN.png and a movie.\n"
          "  --color MODE            plain | inverted | energy | stress (default plain)\n"
          "  --field NAME            colour by any per-cell scalar field of the frames\n"
          "  --range auto|MIN,MAX    colour-map range (default auto: the 2nd to the 98th\n"
          "                          percentile of the values of up to 16 frames)\n"
          "  --width W, --height H   image size in pixels (default 1280 x 720)\n"
          "  --camera-position X,Y,Z camera position, m (default: chosen to frame the bodies)\n"
          "  --camera-target X,Y,Z   point at the image centre, m\n"
          "  --fov DEG               vertical field of view (default 40)\n"
          "  --up X,Y,Z              world up direction (default: against the scene's gravity;\n"
          "                          0,0,1 without a scene or gravity)\n"
          "  --frame-obstacles       frame nearby obstacles too, not only the bodies\n"
          "  --hide-obstacles        draw no obstacles\n"
          "  --hide-obstacle NAME    do not draw this obstacle (repeatable): its name, its type\n"
          "                          (plane, sphere, ..., gear, mesh), obstacles[i] or bones[i]\n"
          "  --every N               render every Nth frame (default 1)\n"
          "  --scene FILE            scene file for obstacles (default DIR/scene.json if present)\n"
          "  --no-ground             no ground plane unless the scene has a plane obstacle\n"
          "  --no-shadows            no shadows of the solids on the ground\n"
          "  --antialias             smooth edges (2 x 2 samples per pixel, 4 times slower)\n"
          "  --threads N             worker threads, 1 to 1024 (default: all cores)\n"
          "  --contact-sheet         also write DIR/render/contact_sheet.png\n"
          "  --sheet-frames N        frames on the contact sheet (default 12)\n"
          "  --sheet-width W         width of a contact-sheet tile in pixels (default 480)\n"
          "  --movie, --no-movie     write DIR/render/movie.mp4 with ffmpeg (default: when found)\n"
          "  --fps F                 movie frame rate (default: real time, from the frame times\n"
          "                          in DIR/sim.pvd and --every; 30 without them)\n"
          "  -h, --help              this text\n"
          "Files this command writes replace earlier ones of the same name; no other file is\n"
          "deleted.\n");
}

enum { MAX_HIDDEN = 64 };

typedef struct render_options {
  const char *dir, *color, *field, *scene;
  piola_render_def def;
  bool have_pos, have_target, have_up, have_range, sheet, frame_obstacles;
  int movie; /* -1: when ffmpeg is found */
  long every, sheet_frames, sheet_width, threads;
  double fps, range[2];
  piola_vec3 pos, target;
  const char *hidden[MAX_HIDDEN];
  int hidden_count;
  const char *first_named_hidden; /* the first --hide-obstacle NAME, if any */
} render_options;

static bool parse_range(const char *v, render_options *o) {
  if (strcmp(v, "auto") == 0) {
    o->have_range = false;
    return true;
  }
  const char *comma = strchr(v, ',');
  if (!comma) return false;
  char lo[64];
  snprintf(lo, sizeof lo, "%.*s", (int)(comma - v), v);
  o->have_range = cli_parse_double(lo, &o->range[0]) && cli_parse_double(comma + 1, &o->range[1]) &&
                  o->range[1] > o->range[0];
  return o->have_range;
}

/* Fills o from the command line; returns -1 to go on, else the exit code. */
static int parse_options(int argc, char **argv, render_options *o) {
  memset(o, 0, sizeof *o);
  o->color = "plain";
  o->def = piola_default_render_def();
  o->movie = -1;
  o->every = 1, o->sheet_frames = 12, o->sheet_width = 480;
  o->fps = NAN;
  long w = o->def.width, h = o->def.height;
  for (int i = 1; i < argc; ++i) {
    const char *a = argv[i];
    const char *v = i + 1 < argc ? argv[i + 1] : NULL;
#define NEEDS(ok, what)                                        \
  do {                                                         \
    if (!v || !(ok)) {                                         \
      fprintf(stderr, "piola render: %s needs %s\n", a, what); \
      return 2;                                                \
    }                                                          \
    ++i;                                                       \
  } while (0)
    if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
      usage(stdout);
      return 0;
    } else if (strcmp(a, "--color") == 0 || strcmp(a, "--colour") == 0) {
      NEEDS(strcmp(v, "plain") == 0 || strcmp(v, "inverted") == 0 || strcmp(v, "energy") == 0 ||
                strcmp(v, "stress") == 0,
            "one of plain, inverted, energy, stress");
      o->color = v;
    } else if (strcmp(a, "--field") == 0) {
      NEEDS(v[0], "a cell field name");
      o->field = v;
    } else if (strcmp(a, "--range") == 0) {
      NEEDS(parse_range(v, o), "auto or MIN,MAX with MIN < MAX");
    } else if (strcmp(a, "--width") == 0) {
      NEEDS(cli_parse_long(v, 16, 16384, &w), "an integer in [16, 16384]");
    } else if (strcmp(a, "--height") == 0) {
      NEEDS(cli_parse_long(v, 16, 16384, &h), "an integer in [16, 16384]");
    } else if (strcmp(a, "--camera-position") == 0) {
      NEEDS(cli_parse_vec3(v, &o->pos), "X,Y,Z in metres");
      o->have_pos = true;
    } else if (strcmp(a, "--camera-target") == 0) {
      NEEDS(cli_parse_vec3(v, &o->target), "X,Y,Z in metres");
      o->have_target = true;
    } else if (strcmp(a, "--fov") == 0) {
      NEEDS(cli_parse_double(v, &o->def.fov_degrees) && o->def.fov_degrees > 1 &&
                o->def.fov_degrees < 170,
            "degrees in (1, 170)");
    } else if (strcmp(a, "--up") == 0) {
      NEEDS(cli_parse_vec3(v, &o->def.up) && (o->def.up.x != 0 || o->def.up.y != 0 || o->def.up.z != 0),
            "a nonzero X,Y,Z");
      o->have_up = true;
    } else if (strcmp(a, "--frame-obstacles") == 0) {
      o->frame_obstacles = true;
    } else if (strcmp(a, "--hide-obstacles") == 0) {
      o->hidden[0] = "all";
      o->hidden_count = o->hidden_count > 0 ? o->hidden_count : 1;
    } else if (strcmp(a, "--hide-obstacle") == 0) {
      NEEDS(v[0] && o->hidden_count < MAX_HIDDEN, "a name, a type, obstacles[i] or bones[i] "
                                                   "(at most 64 of them)");
      if (!o->first_named_hidden) o->first_named_hidden = v;
      o->hidden[o->hidden_count++] = v;
    } else if (strcmp(a, "--every") == 0) {
      NEEDS(cli_parse_long(v, 1, 1000000, &o->every), "an integer >= 1");
    } else if (strcmp(a, "--scene") == 0) {
      NEEDS(v[0], "a scene file");
      o->scene = v;
    } else if (strcmp(a, "--no-ground") == 0) {
      o->def.ground = false;
    } else if (strcmp(a, "--no-shadows") == 0) {
      o->def.shadows = false;
    } else if (strcmp(a, "--antialias") == 0) {
      o->def.supersample = 2;
    } else if (strcmp(a, "--threads") == 0) {
      NEEDS(cli_parse_long(v, 1, 1024, &o->threads), "an integer in [1, 1024]");
    } else if (strcmp(a, "--contact-sheet") == 0) {
      o->sheet = true;
    } else if (strcmp(a, "--sheet-frames") == 0) {
      NEEDS(cli_parse_long(v, 1, 100, &o->sheet_frames), "an integer in [1, 100]");
      o->sheet = true;
    } else if (strcmp(a, "--sheet-width") == 0) {
      NEEDS(cli_parse_long(v, 32, 4096, &o->sheet_width), "an integer in [32, 4096]");
      o->sheet = true;
    } else if (strcmp(a, "--movie") == 0) {
      o->movie = 1;
    } else if (strcmp(a, "--no-movie") == 0) {
      o->movie = 0;
    } else if (strcmp(a, "--fps") == 0) {
      NEEDS(cli_parse_double(v, &o->fps) && o->fps > 0 && o->fps <= 1000,
            "frames per second in (0, 1000]");
    } else if (a[0] == '-' && a[1]) {
      fprintf(stderr, "piola render: unknown option '%s'\n", a);
      usage(stderr);
      return 2;
    } else if (!o->dir) {
      o->dir = a;
    } else {
      fprintf(stderr, "piola render: more than one folder given ('%s' and '%s')\n", o->dir, a);
      return 2;
    }
#undef NEEDS
  }
  if (!o->dir) {
    fprintf(stderr, "piola render: no folder given\n");
    usage(stderr);
    return 2;
  }
  struct stat st;
  if (stat(o->dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
    fprintf(stderr, "piola render: %s is not a folder\n", o->dir);
    return 2;
  }
  if (strlen(o->dir) > 3800) {
    fprintf(stderr, "piola render: folder path too long\n");
    return 2;
  }
  o->def.width = (int32_t)w, o->def.height = (int32_t)h;
  return -1;
}

static int compare_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* The colour range `auto`: the 2nd to the 98th percentile of all the values seen. Energy
 * densities are heavy-tailed (a few crushed elements dwarf everything), so the extremes
 * would leave the rest of the map dark; colours beyond the range are clamped. */
typedef struct value_pool {
  double *v;
  size_t n, cap;
  bool failed;
} value_pool;

static void pool_add(value_pool *p, const double *v, int32_t n) {
  for (int32_t i = 0; i < n && !p->failed; ++i) {
    if (!isfinite(v[i])) continue;
    if (p->n == p->cap) {
      size_t cap = p->cap ? 2 * p->cap : 4096;
      double *grown = realloc(p->v, cap * sizeof *grown);
      if (!grown) {
        p->failed = true;
        break;
      }
      p->v = grown, p->cap = cap;
    }
    p->v[p->n++] = v[i];
  }
}

static void pool_range(value_pool *p, double *lo, double *hi) {
  *lo = 0, *hi = 1;
  if (p->n == 0) return;
  qsort(p->v, p->n, sizeof *p->v, compare_double);
  *lo = p->v[(size_t)floor(0.02 * (double)(p->n - 1))];
  *hi = p->v[(size_t)ceil(0.98 * (double)(p->n - 1))];
  if (!(*hi > *lo)) *lo = p->v[0], *hi = p->v[p->n - 1];
  /* all values equal, V: a range 1e-7 |V| either side, which the renderer draws as the one
   * value V (render.h); V = 0 stays 0..0, which it reads as choosing each frame's range,
   * again the one value 0 where every face is 0 */
  if (!(*hi > *lo)) {
    const double v = *lo;
    *lo = v - 1e-7 * fabs(v), *hi = v + 1e-7 * fabs(v);
  }
}

static void mesh_bounds(const piola_render_mesh *m, piola_vec3 *lo, piola_vec3 *hi) {
  for (int32_t i = 0; i < m->vertex_count; ++i) {
    const double *p = m->positions + 3 * (size_t)i;
    lo->x = fmin(lo->x, p[0]), lo->y = fmin(lo->y, p[1]), lo->z = fmin(lo->z, p[2]);
    hi->x = fmax(hi->x, p[0]), hi->y = fmax(hi->y, p[1]), hi->z = fmax(hi->z, p[2]);
  }
}

/* What is drawn and how: the frames, the value field and its range, the scene. */
typedef struct render_plan {
  int *frames;
  int count;
  bool vtu;
  const char *value_field;
  char label[96];
  char scene_path[4200];
  bool use_scene;
  render_cli_stress stress;
  piola_vec3 lo, hi; /* the bodies' box over the sampled frames */
} render_plan;

/* The frames to draw (every --every-th of those in DIR). Returns -1 to go on, else the exit
 * code. */
static int plan_frames(const render_options *o, render_plan *p) {
  char folder[4200];
  snprintf(folder, sizeof folder, "%s/frames", o->dir);
  p->count = render_cli_list_frames(folder, ".vtu", &p->frames);
  p->vtu = p->count > 0;
  if (p->count == 0) {
    snprintf(folder, sizeof folder, "%s/surface", o->dir);
    p->count = render_cli_list_frames(folder, ".obj", &p->frames);
  }
  if (p->count < 0) {
    fprintf(stderr, "piola render: out of memory\n");
    return 1;
  }
  if (p->count == 0) {
    fprintf(stderr,
            "piola render: %s has no frames (frames/frame_NNNN.vtu or surface/frame_NNNN.obj)\n",
            o->dir);
    return 2;
  }
  int kept = 0;
  for (int i = 0; i < p->count; i += (int)o->every) p->frames[kept++] = p->frames[i];
  p->count = kept;
  return -1;
}

/* For --color stress without a stress field in the frames: the scene's materials, to
 * compute it. Returns -1 to go on, else the exit code. */
static int plan_stress(const render_options *o, render_plan *p, int first_frame) {
  render_cli_frame lf;
  if (render_cli_load_frame(o->dir, p->vtu, first_frame, NULL, 0, NULL, &lf) != 0) return 2;
  static const char *const names[] = {"von_mises_stress", "von_mises", "stress"};
  for (int k = 0; k < 3 && !p->value_field; ++k)
    if (piola_render_frame_has_field(lf.vtu, names[k])) p->value_field = names[k];
  bool has_displacement = lf.vtu && piola_render_frame_has_rest_positions(lf.vtu);
  render_cli_frame_free(&lf);
  snprintf(p->label, sizeof p->label, "von Mises stress (Pa)");
  if (p->value_field) return -1;
  int32_t n = 0;
  if (!p->use_scene) {
    fprintf(stderr,
            "piola render: stress colouring needs the scene's materials: %s/scene.json is "
            "missing, give --scene FILE\n",
            o->dir);
    return 2;
  }
  if (!has_displacement) {
    fprintf(stderr, "piola render: the frames have neither a stress field nor displacements; "
                    "use --color energy\n");
    return 2;
  }
  if (piola_render_scene_materials(p->scene_path, p->stress.materials, 256, &n) != PIOLA_OK ||
      n < 1 || n > 256) {
    fprintf(stderr, "piola render: materials for stress colouring: %s\n",
            n > 256  ? "more than 256 solids"
            : n < 1 ? "the scene has no solids"
                    : piola_last_error());
    return 2;
  }
  p->stress.count = n;
  p->value_field = "von_mises_stress";
  return -1;
}

/* Samples up to 16 frames (first and last included) for the camera's box and the colour
 * range, so the view and the colours hold still through the movie. Returns -1 to go on,
 * else the exit code. */
static int plan_view(render_options *o, render_plan *p) {
  p->lo = (piola_vec3){INFINITY, INFINITY, INFINITY};
  p->hi = (piola_vec3){-INFINITY, -INFINITY, -INFINITY};
  value_pool pool = {0};
  int samples = p->count < 16 ? p->count : 16;
  for (int s = 0; s < samples; ++s) {
    int idx = samples > 1 ? (int)((long)s * (p->count - 1) / (samples - 1)) : 0;
    render_cli_frame lf;
    if (render_cli_load_frame(o->dir, p->vtu, p->frames[idx], p->value_field, 0, &p->stress,
                              &lf) != 0) {
      free(pool.v);
      return 2;
    }
    mesh_bounds(&lf.mesh, &p->lo, &p->hi);
    if (p->value_field) pool_add(&pool, lf.mesh.values, lf.mesh.triangle_count);
    render_cli_frame_free(&lf);
  }
  if (pool.failed) {
    free(pool.v);
    fprintf(stderr, "piola render: out of memory\n");
    return 1;
  }
  if (p->value_field) {
    if (!p->label[0]) snprintf(p->label, sizeof p->label, "%s", p->value_field);
    o->def.value_label = p->label;
    if (o->have_range)
      o->def.value_min = o->range[0], o->def.value_max = o->range[1];
    else
      pool_range(&pool, &o->def.value_min, &o->def.value_max);
  }
  free(pool.v);
  if (!(p->lo.x <= p->hi.x)) p->lo = p->hi = (piola_vec3){0, 0, 0}; /* empty surfaces */
  return -1;
}

/* The renderer with the scene's obstacles and the camera: fitted to the bodies (obstacles
 * added after fitting, so they do not grow the box, unless --frame-obstacles), with
 * whatever the flags set replacing its parts. */
static int make_renderer(render_options *o, render_plan *p, piola_renderer **out) {
  piola_renderer *r = NULL;
  if (!p->use_scene && o->first_named_hidden) {
    fprintf(stderr,
            "piola render: --hide-obstacle %s names nothing: there is no scene to take obstacles "
            "from (no scene.json in the folder and no --scene)\n",
            o->first_named_hidden);
    return 2;
  }
  for (int pass = 0; pass < 2; ++pass) {
    if (piola_renderer_create(&o->def, &r) != PIOLA_OK) {
      fprintf(stderr, "piola render: %s\n", piola_last_error());
      return 2;
    }
    if (!o->frame_obstacles) piola_renderer_fit_camera(r, p->lo, p->hi);
    if (p->use_scene &&
        piola_renderer_load_scene_obstacles_hiding(r, p->scene_path, o->hidden,
                                                   o->hidden_count) != PIOLA_OK) {
      fprintf(stderr, "piola render: %s\n", piola_last_error());
      if (o->scene || o->hidden_count > 0) {
        piola_renderer_destroy(r);
        return 2;
      }
      fprintf(stderr, "piola render: drawing without the scene's obstacles\n");
      p->use_scene = false;
    }
    if (o->frame_obstacles) piola_renderer_fit_camera(r, p->lo, p->hi);
    if (pass == 1 || !(o->have_pos || o->have_target)) break;
    piola_vec3 auto_pos, auto_target;
    piola_renderer_camera(r, &auto_pos, &auto_target);
    piola_renderer_destroy(r);
    o->def.camera_set = true;
    o->def.camera_position = o->have_pos ? o->pos : auto_pos;
    o->def.camera_target = o->have_target ? o->target : auto_target;
  }
  *out = r;
  return -1;
}

static double now_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int write_sheet(const render_options *o, const char *render_dir, piola_image *images,
                       char (*labels)[96], int count) {
  const char *label_ptrs[100];
  for (int i = 0; i < count; ++i) label_ptrs[i] = labels[i];
  int columns = count <= 4 ? count : count <= 9 ? 3 : 4;
  if (count > 12) columns = 5;
  piola_image out = {0};
  char path[4400];
  snprintf(path, sizeof path, "%s/contact_sheet.png", render_dir);
  int rc = 0;
  if (piola_image_contact_sheet(images, label_ptrs, count, columns, (int32_t)o->sheet_width,
                                &out) != PIOLA_OK ||
      piola_image_write_png(path, &out) != PIOLA_OK) {
    fprintf(stderr, "piola render: contact sheet: %s\n", piola_last_error());
    rc = 1;
  } else {
    fprintf(stderr, "piola render: contact sheet of %d frames: %s\n", count, path);
  }
  piola_image_free(&out);
  return rc;
}

int cli_render(int argc, char **argv);
int cli_render(int argc, char **argv) {
  render_options o;
  int rc = parse_options(argc, argv, &o);
  if (rc >= 0) return rc;
  if (o.threads > 0) piola_set_thread_count((int)o.threads);
  static render_plan p; /* large (materials): not on the stack */
  memset(&p, 0, sizeof p);
  rc = plan_frames(&o, &p);
  if (rc >= 0) return free(p.frames), rc;

  /* the scene (obstacles, gravity, materials for stresses): --scene FILE, else the copy
   * `piola run` leaves in DIR */
  if (o.scene)
    snprintf(p.scene_path, sizeof p.scene_path, "%s", o.scene);
  else
    snprintf(p.scene_path, sizeof p.scene_path, "%s/scene.json", o.dir);
  struct stat st;
  p.use_scene = o.scene || (stat(p.scene_path, &st) == 0 && S_ISREG(st.st_mode));
  if (!o.have_up && p.use_scene && piola_render_scene_up(p.scene_path, &o.def.up) != PIOLA_OK)
    o.def.up = (piola_vec3){0, 0, 1}; /* an unreadable scene is reported with its obstacles */

  /* colour mode and field */
  if (strcmp(o.color, "inverted") == 0) {
    /* which tets are inverted is in the VTU frames only */
    if (!p.vtu) {
      fprintf(stderr,
              "piola render: --color inverted needs the VTU frames in %s/frames (the "
              "OBJ surfaces draw in plain colours only)\n",
              o.dir);
      return free(p.frames), 2;
    }
    o.def.color = PIOLA_RENDER_COLOR_INVERTED;
  }
  p.value_field = o.field;
  if (!p.value_field && strcmp(o.color, "energy") == 0) {
    p.value_field = "energy_density";
    snprintf(p.label, sizeof p.label, "energy density (J/m^3)");
  }
  if (p.value_field || strcmp(o.color, "stress") == 0) {
    if (!p.vtu) {
      fprintf(stderr, "piola render: colouring by a field needs the VTU frames in %s/frames\n",
              o.dir);
      return free(p.frames), 2;
    }
    o.def.color = PIOLA_RENDER_COLOR_VALUE;
  }
  if (strcmp(o.color, "stress") == 0 && !o.field) rc = plan_stress(&o, &p, p.frames[0]);
  if (rc < 0) rc = plan_view(&o, &p);
  piola_renderer *r = NULL;
  if (rc < 0) rc = make_renderer(&o, &p, &r);
  if (rc >= 0) return free(p.frames), rc;
  rc = 0;

  char render_dir[4200];
  snprintf(render_dir, sizeof render_dir, "%s/render", o.dir);
  if (mkdir(render_dir, 0777) != 0 && errno != EEXIST) {
    fprintf(stderr, "piola render: cannot create %s: %s\n", render_dir, strerror(errno));
    piola_renderer_destroy(r);
    return free(p.frames), 1;
  }
  char *pvd = NULL;
  {
    char path[4200];
    snprintf(path, sizeof path, "%s/sim.pvd", o.dir);
    pvd = render_cli_read_text(path);
  }
  int count = p.count;
  int sheet_count = o.sheet ? (count < o.sheet_frames ? count : (int)o.sheet_frames) : 0;
  piola_image *sheet_images =
      calloc((size_t)(sheet_count > 0 ? sheet_count : 1), sizeof *sheet_images);
  char(*sheet_labels)[96] =
      calloc((size_t)(sheet_count > 0 ? sheet_count : 1), sizeof *sheet_labels);
  if (!sheet_images || !sheet_labels) rc = 1;
  fprintf(stderr, "piola render: %d frames of %s -> %s (%d x %d, %s%s%s)\n", count, o.dir,
          render_dir, (int)o.def.width, (int)o.def.height, o.color, p.value_field ? ": " : "",
          p.value_field ? p.value_field : "");
  double first_gap_time = NAN, first_time = NAN;
  piola_image img = {0};
  int next_sheet = 0, label_scale = o.def.height >= 600 ? 2 : 1;
  double t_start = now_seconds();
  for (int i = 0; rc == 0 && i < count; ++i) {
    int f = p.frames[i];
    double t = render_cli_frame_time(pvd, f);
    if (!isfinite(t)) t = f / (isfinite(o.fps) ? o.fps : 30.0);
    if (i == 0) first_time = t;
    if (i == 1) first_gap_time = t - first_time;
    render_cli_frame lf;
    if (render_cli_load_frame(o.dir, p.vtu, f, p.value_field, t, &p.stress, &lf) != 0) {
      rc = 1;
      break;
    }
    if (piola_renderer_render(r, &lf.mesh, &img) != PIOLA_OK) {
      fprintf(stderr, "piola render: frame %d: %s\n", f, piola_last_error());
      render_cli_frame_free(&lf);
      rc = 1;
      break;
    }
    int inverted = lf.vtu ? (int)piola_render_frame_inverted_count(lf.vtu) : 0;
    render_cli_frame_free(&lf);
    char text[96];
    if (o.def.color == PIOLA_RENDER_COLOR_INVERTED)
      snprintf(text, sizeof text, "FRAME %d  T = %.3f S  INVERTED %d", f, t, inverted);
    else
      snprintf(text, sizeof text, "FRAME %d  T = %.3f S", f, t);
    /* evenly spaced frames for the contact sheet, kept without the frame's own label: the
     * sheet draws one of its own size, and a frame scaled up to the tile showed its label
     * out from under the sheet's */
    if (next_sheet < sheet_count) {
      int want = sheet_count > 1 ? (int)((long)next_sheet * (count - 1) / (sheet_count - 1)) : 0;
      if (i == want) {
        const size_t bytes = 3 * (size_t)img.width * (size_t)img.height;
        piola_image *copy = &sheet_images[next_sheet];
        copy->rgb = malloc(bytes);
        if (!copy->rgb) {
          fprintf(stderr, "piola render: out of memory\n");
          rc = 1;
          break;
        }
        memcpy(copy->rgb, img.rgb, bytes);
        copy->width = img.width, copy->height = img.height;
        snprintf(sheet_labels[next_sheet], sizeof sheet_labels[0], "%s", text);
        ++next_sheet;
      }
    }
    piola_image_draw_label(&img, 8 * label_scale, 8 * label_scale, label_scale, text);
    char path[4400];
    snprintf(path, sizeof path, "%s/frame_%04d.png", render_dir, f);
    if (piola_image_write_png(path, &img) != PIOLA_OK) {
      fprintf(stderr, "piola render: %s\n", piola_last_error());
      rc = 1;
      break;
    }
  }
  double per_frame = count > 0 ? (now_seconds() - t_start) / count : 0;
  piola_image_free(&img);
  piola_renderer_destroy(r);
  free(pvd);
  if (rc == 0)
    fprintf(stderr, "piola render: %d PNGs written (%.3f s per frame)\n", count, per_frame);
  if (rc == 0 && sheet_count > 0) rc = write_sheet(&o, render_dir, sheet_images, sheet_labels, sheet_count);
  for (int i = 0; i < sheet_count; ++i) piola_image_free(&sheet_images[i]);
  free(sheet_images);
  free(sheet_labels);

  double fps = o.fps;
  if (rc == 0 && o.movie != 0 && !isfinite(fps)) {
    /* real time: the simulation's frame spacing, times the thinning of --every */
    fps = 30;
    if (count >= 2 && first_gap_time > 0) fps = 1.0 / first_gap_time;
    if (!(fps >= 1)) fps = 1;
    if (fps > 120) fps = 120;
  }
  if (rc == 0 && o.movie != 0) {
    if (!render_cli_find_in_path("ffmpeg")) {
      fprintf(stderr,
              "piola render: ffmpeg not found on PATH: no movie (scripts/install-deps.sh installs "
              "it)\n");
      if (o.movie == 1) rc = 1;
    } else {
      const char *encoder = NULL;
      if (render_cli_make_movie(render_dir, p.frames, count, fps, &encoder) == 0) {
        fprintf(stderr, "piola render: movie of %d frames at %g fps (%s): %s/movie.mp4\n", count,
                fps, encoder, render_dir);
      } else {
        fprintf(stderr, "piola render: ffmpeg failed; see %s/ffmpeg.log\n", render_dir);
        rc = 1;
      }
    }
  }
  free(p.frames);
  return rc;
}
