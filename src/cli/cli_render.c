/* `piola render DIR`: pictures and a movie of a simulation's frames (docs/rendering.md).
 *
 * Reads DIR/frames/frame_NNNN.vtu (or, lacking those, DIR/surface/frame_NNNN.obj), the
 * scene's obstacles (--scene FILE, else DIR/scene.json when present) and the frame times in
 * DIR/sim.pvd, and writes DIR/render/frame_NNNN.png, optionally DIR/render/contact_sheet.png
 * and, when ffmpeg is on the PATH, DIR/render/movie.mp4. The frames present when it starts
 * are rendered, so it works on a running simulation. Uses only the public API.
 * Exit codes: 0 done, 1 a failure while writing, 2 bad usage or input. */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "cli/cli_numbers.h"
#include "cli/commands.h"
#include "piola/mesh_io.h"
#include "piola/render.h"

static void usage(FILE *out) {
  fprintf(out,
          "usage: piola render DIR [options]\n"
          "\n"
          "Renders the frames of `piola run -o DIR` to DIR/render/frame_NNNN.png and a movie.\n"
          "  --color MODE            plain | inverted | energy | stress (default plain)\n"
          "  --field NAME            colour by any per-cell scalar field of the frames\n"
          "  --range MIN,MAX         colour-map range (default: 0 to the 99th percentile)\n"
          "  --width W, --height H   image size in pixels (default 1280 x 720)\n"
          "  --camera-position X,Y,Z camera position, m (default: chosen to frame the scene)\n"
          "  --camera-target X,Y,Z   point at the image centre, m\n"
          "  --fov DEG               vertical field of view (default 40)\n"
          "  --up X,Y,Z              world up direction (default 0,0,1)\n"
          "  --every N               render every Nth frame (default 1)\n"
          "  --scene FILE            scene file for obstacles (default DIR/scene.json if present)\n"
          "  --no-ground             no ground plane unless the scene has a plane obstacle\n"
          "  --no-shadows            no shadows of the solids on the ground\n"
          "  --antialias             smooth edges (2 x 2 samples per pixel, 4 times slower)\n"
          "  --contact-sheet         also write DIR/render/contact_sheet.png\n"
          "  --sheet-frames N        frames on the contact sheet (default 12)\n"
          "  --movie, --no-movie     write DIR/render/movie.mp4 with ffmpeg (default: when found)\n"
          "  --fps F                 movie frame rate (default: real time, from the frame times\n"
          "                          in DIR/sim.pvd and --every; 30 without them)\n"
          "  -h, --help              this text\n");
}

static bool is_dir(const char *path) {
  struct stat st;
  return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

static bool is_file(const char *path) {
  struct stat st;
  return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

static int compare_int(const void *a, const void *b) {
  int x = *(const int *)a, y = *(const int *)b;
  return (x > y) - (x < y);
}

/* Frame numbers of folder/frame_NNNN<suffix>, sorted; returns the count (-1: no memory). */
static int list_frames(const char *folder, const char *suffix, int **out) {
  *out = NULL;
  DIR *d = opendir(folder);
  if (!d) return 0;
  int n = 0, cap = 0;
  size_t sl = strlen(suffix);
  for (struct dirent *e; (e = readdir(d));) {
    const char *name = e->d_name;
    size_t len = strlen(name);
    if (len <= 6 + sl || strncmp(name, "frame_", 6) != 0 || strcmp(name + len - sl, suffix) != 0)
      continue;
    bool digits = true;
    for (size_t i = 6; i < len - sl; ++i) digits = digits && name[i] >= '0' && name[i] <= '9';
    if (!digits || len - sl - 6 > 9) continue;
    if (n == cap) {
      cap = cap ? 2 * cap : 64;
      int *grown = realloc(*out, (size_t)cap * sizeof *grown);
      if (!grown) {
        closedir(d);
        free(*out);
        *out = NULL;
        return -1;
      }
      *out = grown;
    }
    (*out)[n++] = atoi(name + 6);
  }
  closedir(d);
  if (n > 0) qsort(*out, (size_t)n, sizeof **out, compare_int);
  return n;
}

/* Time (s) of a frame from DIR/sim.pvd, or NAN. */
static double frame_time_from_pvd(const char *pvd, int frame) {
  if (!pvd) return NAN;
  char key[64];
  snprintf(key, sizeof key, "frame_%04d.vtu", frame);
  const char *hit = strstr(pvd, key);
  if (!hit) return NAN;
  const char *line = hit;
  while (line > pvd && line[-1] != '\n') --line;
  const char *ts = strstr(line, "timestep=\"");
  if (!ts || ts > hit) return NAN;
  return strtod(ts + 10, NULL);
}

static char *read_text(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  char *buf = NULL;
  long n = -1;
  if (fseek(f, 0, SEEK_END) == 0) n = ftell(f);
  if (n >= 0 && fseek(f, 0, SEEK_SET) == 0) buf = malloc((size_t)n + 1);
  if (buf && fread(buf, 1, (size_t)n, f) == (size_t)n)
    buf[n] = '\0';
  else {
    free(buf);
    buf = NULL;
  }
  fclose(f);
  return buf;
}

typedef struct loaded_frame {
  piola_render_frame *vtu; /* or */
  piola_tri_mesh obj;
  piola_render_mesh mesh;
} loaded_frame;

static void loaded_free(loaded_frame *lf) {
  piola_render_frame_destroy(lf->vtu);
  piola_tri_mesh_free(&lf->obj);
  memset(lf, 0, sizeof *lf);
}

/* Materials of the scene's solids, when stresses are computed from the frames. */
typedef struct stress_source {
  piola_material_def materials[256];
  int32_t count; /* 0: the frames are not given a stress field */
} stress_source;

/* Loads frame f (VTU or OBJ) and its mesh with the value field (may be NULL), computing the
 * von_mises_stress field first when stress has materials. */
static int load_frame(const char *dir, bool vtu, int f, const char *field, double time,
                      const stress_source *stress, loaded_frame *lf) {
  char path[4200];
  memset(lf, 0, sizeof *lf);
  if (vtu) {
    snprintf(path, sizeof path, "%s/frames/frame_%04d.vtu", dir, f);
    if (piola_render_frame_read(path, &lf->vtu) != PIOLA_OK ||
        (stress && stress->count > 0 &&
         piola_render_frame_add_stress(lf->vtu, stress->materials, stress->count) != PIOLA_OK) ||
        piola_render_frame_mesh(lf->vtu, field, time, &lf->mesh) != PIOLA_OK) {
      fprintf(stderr, "piola render: %s\n", piola_last_error());
      loaded_free(lf);
      return -1;
    }
  } else {
    snprintf(path, sizeof path, "%s/surface/frame_%04d.obj", dir, f);
    if (piola_tri_mesh_read(path, &lf->obj) != PIOLA_OK) {
      fprintf(stderr, "piola render: %s\n", piola_last_error());
      loaded_free(lf);
      return -1;
    }
    lf->mesh = (piola_render_mesh){lf->obj.vertex_count,
                                   lf->obj.positions,
                                   lf->obj.triangle_count,
                                   lf->obj.triangles,
                                   NULL,
                                   NULL,
                                   NULL,
                                   time};
  }
  return 0;
}

static void mesh_bounds(const piola_render_mesh *m, piola_vec3 *lo, piola_vec3 *hi) {
  for (int32_t i = 0; i < m->vertex_count; ++i) {
    const double *p = m->positions + 3 * (size_t)i;
    lo->x = fmin(lo->x, p[0]), lo->y = fmin(lo->y, p[1]), lo->z = fmin(lo->z, p[2]);
    hi->x = fmax(hi->x, p[0]), hi->y = fmax(hi->y, p[1]), hi->z = fmax(hi->z, p[2]);
  }
}

static int compare_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double percentile99(const double *v, int32_t n) {
  double *s = malloc((size_t)(n > 0 ? n : 1) * sizeof *s);
  if (!s) return NAN;
  int32_t m = 0;
  for (int32_t i = 0; i < n; ++i)
    if (isfinite(v[i])) s[m++] = v[i];
  double r = NAN;
  if (m > 0) {
    qsort(s, (size_t)m, sizeof *s, compare_double);
    r = s[(int32_t)floor(0.99 * (m - 1))];
  }
  free(s);
  return r;
}

static void remove_old_pngs(const char *folder) {
  int *old = NULL;
  int n = list_frames(folder, ".png", &old);
  char path[4300];
  for (int i = 0; i < n; ++i) {
    snprintf(path, sizeof path, "%s/frame_%04d.png", folder, old[i]);
    unlink(path);
  }
  free(old);
}

static bool find_in_path(const char *program) {
  const char *path = getenv("PATH");
  if (!path) return false;
  char buf[4096];
  for (const char *p = path; *p;) {
    const char *colon = strchr(p, ':');
    size_t len = colon ? (size_t)(colon - p) : strlen(p);
    snprintf(buf, sizeof buf, "%.*s/%s", (int)len, len ? p : ".", program);
    if (access(buf, X_OK) == 0) return true;
    if (!colon) break;
    p = colon + 1;
  }
  return false;
}

/* Runs ffmpeg in `cwd` with argv, output to log; returns its exit status (-1: not run). */
static int run_in(const char *cwd, char *const argv[], const char *log) {
  pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    FILE *l = fopen(log, "w");
    if (l) {
      dup2(fileno(l), STDOUT_FILENO);
      dup2(fileno(l), STDERR_FILENO);
    }
    if (chdir(cwd) != 0) _exit(127);
    execvp(argv[0], argv);
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* The rendered PNGs, linked as a gap-free sequence (ffmpeg's image reader needs one), are
 * encoded with H.264 (yuv420p, the format every player takes), or MPEG-4 part 2 when this
 * ffmpeg has no libx264. Returns 0 on success. */
static int make_movie(const char *render_dir, const int *frames, int count, double fps,
                      const char **encoder) {
  char seq[4300], path[4400], target[64], fps_s[32], log[4400], tmp[4400], final_path[4400];
  snprintf(seq, sizeof seq, "%s/.movie_frames", render_dir);
  snprintf(log, sizeof log, "%s/ffmpeg.log", render_dir);
  snprintf(tmp, sizeof tmp, "%s/movie.partial.mp4", render_dir);
  snprintf(final_path, sizeof final_path, "%s/movie.mp4", render_dir);
  mkdir(seq, 0777);
  int rc = 0;
  for (int i = 0; i < count && rc == 0; ++i) {
    snprintf(path, sizeof path, "%s/img_%06d.png", seq, i);
    snprintf(target, sizeof target, "../frame_%04d.png", frames[i]);
    unlink(path);
    if (symlink(target, path) != 0) rc = -1;
  }
  snprintf(fps_s, sizeof fps_s, "%g", fps);
  static const char *const encoders[2][6] = {{"libx264", "-preset", "medium", "-crf", "20", NULL},
                                             {"mpeg4", "-q:v", "3", NULL, NULL, NULL}};
  for (int e = 0; e < 2 && rc == 0; ++e) {
    char *argv[32];
    int a = 0;
    argv[a++] = "ffmpeg", argv[a++] = "-nostdin", argv[a++] = "-y", argv[a++] = "-loglevel";
    argv[a++] = "error", argv[a++] = "-framerate", argv[a++] = fps_s, argv[a++] = "-i";
    argv[a++] = "img_%06d.png", argv[a++] = "-vf", argv[a++] = "pad=ceil(iw/2)*2:ceil(ih/2)*2";
    argv[a++] = "-c:v";
    for (int k = 0; encoders[e][k]; ++k) argv[a++] = (char *)encoders[e][k];
    argv[a++] = "-pix_fmt", argv[a++] = "yuv420p", argv[a++] = "-f", argv[a++] = "mp4";
    argv[a++] = "../movie.partial.mp4", argv[a] = NULL;
    int status = run_in(seq, argv, log);
    if (status == 0 && rename(tmp, final_path) == 0) {
      *encoder = encoders[e][0];
      rc = 1;
    }
  }
  unlink(tmp);
  for (int i = 0; i < count; ++i) {
    snprintf(path, sizeof path, "%s/img_%06d.png", seq, i);
    unlink(path);
  }
  rmdir(seq);
  return rc == 1 ? 0 : -1;
}

static double now_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int cli_render(int argc, char **argv);
int cli_render(int argc, char **argv) {
  const char *dir = NULL, *color = "plain", *field = NULL, *scene = NULL;
  piola_render_def def = piola_default_render_def();
  bool have_pos = false, have_target = false, sheet = false, have_range = false;
  int movie = -1; /* -1: when ffmpeg is found */
  long every = 1, sheet_frames = 12, w = def.width, h = def.height;
  double fps = NAN, range[2] = {0, 0};
  piola_vec3 pos = {0, 0, 0}, target = {0, 0, 0};
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
      color = v;
    } else if (strcmp(a, "--field") == 0) {
      NEEDS(v[0], "a cell field name");
      field = v;
    } else if (strcmp(a, "--range") == 0) {
      char *comma = v ? strchr(v, ',') : NULL;
      bool ok = false;
      if (comma) {
        char lo[64];
        snprintf(lo, sizeof lo, "%.*s", (int)(comma - v), v);
        ok = cli_parse_double(lo, &range[0]) && cli_parse_double(comma + 1, &range[1]) &&
             range[1] > range[0];
      }
      NEEDS(ok, "MIN,MAX with MIN < MAX");
      have_range = true;
    } else if (strcmp(a, "--width") == 0) {
      NEEDS(cli_parse_long(v, 16, 16384, &w), "an integer in [16, 16384]");
    } else if (strcmp(a, "--height") == 0) {
      NEEDS(cli_parse_long(v, 16, 16384, &h), "an integer in [16, 16384]");
    } else if (strcmp(a, "--camera-position") == 0) {
      NEEDS(cli_parse_vec3(v, &pos), "X,Y,Z in metres");
      have_pos = true;
    } else if (strcmp(a, "--camera-target") == 0) {
      NEEDS(cli_parse_vec3(v, &target), "X,Y,Z in metres");
      have_target = true;
    } else if (strcmp(a, "--fov") == 0) {
      NEEDS(cli_parse_double(v, &def.fov_degrees) && def.fov_degrees > 1 && def.fov_degrees < 170,
            "degrees in (1, 170)");
    } else if (strcmp(a, "--up") == 0) {
      NEEDS(cli_parse_vec3(v, &def.up) && (def.up.x != 0 || def.up.y != 0 || def.up.z != 0),
            "a nonzero X,Y,Z");
    } else if (strcmp(a, "--every") == 0) {
      NEEDS(cli_parse_long(v, 1, 1000000, &every), "an integer >= 1");
    } else if (strcmp(a, "--scene") == 0) {
      NEEDS(v[0], "a scene file");
      scene = v;
    } else if (strcmp(a, "--no-ground") == 0) {
      def.ground = false;
    } else if (strcmp(a, "--no-shadows") == 0) {
      def.shadows = false;
    } else if (strcmp(a, "--antialias") == 0) {
      def.supersample = 2;
    } else if (strcmp(a, "--contact-sheet") == 0) {
      sheet = true;
    } else if (strcmp(a, "--sheet-frames") == 0) {
      NEEDS(cli_parse_long(v, 1, 100, &sheet_frames), "an integer in [1, 100]");
      sheet = true;
    } else if (strcmp(a, "--movie") == 0) {
      movie = 1;
    } else if (strcmp(a, "--no-movie") == 0) {
      movie = 0;
    } else if (strcmp(a, "--fps") == 0) {
      NEEDS(cli_parse_double(v, &fps) && fps > 0 && fps <= 1000, "frames per second in (0, 1000]");
    } else if (a[0] == '-' && a[1]) {
      fprintf(stderr, "piola render: unknown option '%s'\n", a);
      usage(stderr);
      return 2;
    } else if (!dir) {
      dir = a;
    } else {
      fprintf(stderr, "piola render: more than one folder given ('%s' and '%s')\n", dir, a);
      return 2;
    }
#undef NEEDS
  }
  if (!dir) {
    fprintf(stderr, "piola render: no folder given\n");
    usage(stderr);
    return 2;
  }
  if (!is_dir(dir)) {
    fprintf(stderr, "piola render: %s is not a folder\n", dir);
    return 2;
  }
  if (strlen(dir) > 3800) {
    fprintf(stderr, "piola render: folder path too long\n");
    return 2;
  }
  def.width = (int32_t)w, def.height = (int32_t)h;

  /* which frames */
  char folder[4200];
  int *frames = NULL;
  snprintf(folder, sizeof folder, "%s/frames", dir);
  int count = list_frames(folder, ".vtu", &frames);
  bool vtu = count > 0;
  if (count == 0) {
    snprintf(folder, sizeof folder, "%s/surface", dir);
    count = list_frames(folder, ".obj", &frames);
  }
  if (count < 0) {
    fprintf(stderr, "piola render: out of memory\n");
    return 1;
  }
  if (count == 0) {
    fprintf(stderr,
            "piola render: %s has no frames (frames/frame_NNNN.vtu or surface/frame_NNNN.obj)\n",
            dir);
    return 2;
  }
  int kept = 0;
  for (int i = 0; i < count; i += (int)every) frames[kept++] = frames[i];
  count = kept;

  /* colour mode and field */
  if (strcmp(color, "inverted") == 0) def.color = PIOLA_RENDER_COLOR_INVERTED;
  const char *value_field = field;
  char label[96] = "";
  if (!value_field && strcmp(color, "energy") == 0) {
    value_field = "energy_density";
    snprintf(label, sizeof label, "ENERGY DENSITY (J/M^3)");
  }
  if (value_field || strcmp(color, "stress") == 0) {
    if (!vtu) {
      fprintf(stderr, "piola render: colouring by a field needs the VTU frames in %s/frames\n",
              dir);
      free(frames);
      return 2;
    }
    def.color = PIOLA_RENDER_COLOR_VALUE;
  }
  int rc = 0;
  char *pvd = NULL;
  {
    char p[4200];
    snprintf(p, sizeof p, "%s/sim.pvd", dir);
    pvd = read_text(p);
  }
  /* Sample up to 16 frames (first and last included) for the camera's box and the colour
   * range, so the view and the colours hold still through the movie. */
  /* the scene (obstacles, and materials for stresses): --scene FILE, else the copy `piola run`
   * leaves in DIR */
  char scene_path[4200];
  if (scene)
    snprintf(scene_path, sizeof scene_path, "%s", scene);
  else
    snprintf(scene_path, sizeof scene_path, "%s/scene.json", dir);
  bool use_scene = scene || is_file(scene_path);
  static stress_source stress;
  stress.count = 0;
  piola_vec3 lo = {INFINITY, INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY, -INFINITY};
  double vmax = -INFINITY, vmin = INFINITY;
  int samples = count < 16 ? count : 16;
  for (int s = 0; s < samples; ++s) {
    int idx = samples > 1 ? (int)((long)s * (count - 1) / (samples - 1)) : 0;
    loaded_frame lf;
    if (s == 0 && strcmp(color, "stress") == 0 && !field) {
      if (load_frame(dir, vtu, frames[idx], NULL, 0, NULL, &lf) != 0) {
        rc = 2;
        break;
      }
      static const char *const names[] = {"von_mises_stress", "von_mises", "stress"};
      for (int k = 0; k < 3 && !value_field; ++k)
        if (piola_render_frame_has_field(lf.vtu, names[k])) value_field = names[k];
      bool has_displacement = lf.vtu && piola_render_frame_has_rest_positions(lf.vtu);
      loaded_free(&lf);
      if (!value_field) {
        /* compute it from the frames' displacements and the scene's materials */
        int32_t n = 0;
        if (!use_scene) {
          fprintf(stderr,
                  "piola render: stress colouring needs the scene's materials: %s/scene.json is "
                  "missing, give --scene FILE\n",
                  dir);
          rc = 2;
          break;
        }
        if (!has_displacement) {
          fprintf(stderr,
                  "piola render: the frames have neither a stress field nor displacements; "
                  "use --color energy\n");
          rc = 2;
          break;
        }
        if (piola_render_scene_materials(scene_path, stress.materials, 256, &n) != PIOLA_OK ||
            n < 1 || n > 256) {
          fprintf(stderr, "piola render: materials for stress colouring: %s\n",
                  n > 256 ? "more than 256 solids"
                  : n < 1 ? "the scene has no solids"
                          : piola_last_error());
          rc = 2;
          break;
        }
        stress.count = n;
        value_field = "von_mises_stress";
      }
      snprintf(label, sizeof label, "STRESS (PA)");
    }
    if (load_frame(dir, vtu, frames[idx], value_field, 0, &stress, &lf) != 0) {
      rc = 2;
      break;
    }
    mesh_bounds(&lf.mesh, &lo, &hi);
    if (value_field) {
      double p = percentile99(lf.mesh.values, lf.mesh.triangle_count);
      if (isfinite(p) && p > vmax) vmax = p;
      for (int32_t t = 0; t < lf.mesh.triangle_count; ++t)
        if (isfinite(lf.mesh.values[t]) && lf.mesh.values[t] < vmin) vmin = lf.mesh.values[t];
    }
    loaded_free(&lf);
  }
  if (rc != 0) {
    free(frames), free(pvd);
    return rc;
  }
  if (value_field) {
    if (!label[0]) snprintf(label, sizeof label, "%s", value_field);
    def.value_label = label;
    if (have_range)
      def.value_min = range[0], def.value_max = range[1];
    else {
      def.value_min = vmin < 0 ? vmin : 0;
      def.value_max = vmax > def.value_min ? vmax : def.value_min + 1;
    }
  }
  if (!(lo.x <= hi.x)) lo = hi = (piola_vec3){0, 0, 0}; /* empty surfaces */

  /* camera: the automatic one, with whatever the flags set replacing its parts */
  piola_renderer *r = NULL;
  for (int pass = 0; pass < 2; ++pass) {
    if (piola_renderer_create(&def, &r) != PIOLA_OK) {
      fprintf(stderr, "piola render: %s\n", piola_last_error());
      free(frames), free(pvd);
      return 2;
    }
    if (use_scene && piola_renderer_load_scene_obstacles(r, scene_path) != PIOLA_OK) {
      fprintf(stderr, "piola render: %s\n", piola_last_error());
      if (scene) {
        piola_renderer_destroy(r);
        free(frames), free(pvd);
        return 2;
      }
      fprintf(stderr, "piola render: drawing without the scene's obstacles\n");
      use_scene = false;
    }
    piola_renderer_fit_camera(r, lo, hi);
    if (pass == 1 || !(have_pos || have_target)) break;
    piola_vec3 auto_pos, auto_target;
    piola_renderer_camera(r, &auto_pos, &auto_target);
    piola_renderer_destroy(r);
    def.camera_set = true;
    def.camera_position = have_pos ? pos : auto_pos;
    def.camera_target = have_target ? target : auto_target;
  }

  char render_dir[4200];
  snprintf(render_dir, sizeof render_dir, "%s/render", dir);
  if (mkdir(render_dir, 0777) != 0 && errno != EEXIST) {
    fprintf(stderr, "piola render: cannot create %s: %s\n", render_dir, strerror(errno));
    piola_renderer_destroy(r);
    free(frames), free(pvd);
    return 1;
  }
  /* this command's earlier outputs go, so the folder matches what it writes now */
  remove_old_pngs(render_dir);
  {
    char old[4400];
    snprintf(old, sizeof old, "%s/contact_sheet.png", render_dir);
    unlink(old);
    snprintf(old, sizeof old, "%s/movie.mp4", render_dir);
    unlink(old);
  }

  int sheet_count = sheet ? (count < sheet_frames ? count : (int)sheet_frames) : 0;
  piola_image *sheet_images =
      calloc((size_t)(sheet_count > 0 ? sheet_count : 1), sizeof *sheet_images);
  char(*sheet_labels)[48] =
      calloc((size_t)(sheet_count > 0 ? sheet_count : 1), sizeof *sheet_labels);
  if (!sheet_images || !sheet_labels) rc = 1;
  fprintf(stderr, "piola render: %d frames of %s -> %s (%d x %d, %s%s%s)\n", count, dir, render_dir,
          (int)def.width, (int)def.height, color, value_field ? ": " : "",
          value_field ? value_field : "");
  double first_gap_time = NAN, first_time = NAN;
  piola_image img = {0};
  int next_sheet = 0, label_scale = def.height >= 600 ? 2 : 1;
  double t_start = now_seconds();
  for (int i = 0; rc == 0 && i < count; ++i) {
    double t = frame_time_from_pvd(pvd, frames[i]);
    if (!isfinite(t)) t = frames[i] / (isfinite(fps) ? fps : 30.0);
    if (i == 0) first_time = t;
    if (i == 1) first_gap_time = t - first_time;
    loaded_frame lf;
    if (load_frame(dir, vtu, frames[i], value_field, t, &stress, &lf) != 0) {
      rc = 1;
      break;
    }
    if (piola_renderer_render(r, &lf.mesh, &img) != PIOLA_OK) {
      fprintf(stderr, "piola render: frame %d: %s\n", frames[i], piola_last_error());
      loaded_free(&lf);
      rc = 1;
      break;
    }
    int inverted = lf.vtu ? (int)piola_render_frame_inverted_count(lf.vtu) : 0;
    loaded_free(&lf);
    char text[96];
    if (def.color == PIOLA_RENDER_COLOR_INVERTED)
      snprintf(text, sizeof text, "FRAME %d  T = %.3f S  INVERTED %d", frames[i], t, inverted);
    else
      snprintf(text, sizeof text, "FRAME %d  T = %.3f S", frames[i], t);
    piola_image_draw_label(&img, 8 * label_scale, 8 * label_scale, label_scale, text);
    char path[4400];
    snprintf(path, sizeof path, "%s/frame_%04d.png", render_dir, frames[i]);
    if (piola_image_write_png(path, &img) != PIOLA_OK) {
      fprintf(stderr, "piola render: %s\n", piola_last_error());
      rc = 1;
      break;
    }
    /* evenly spaced frames for the contact sheet */
    if (next_sheet < sheet_count) {
      int want = sheet_count > 1 ? (int)((long)next_sheet * (count - 1) / (sheet_count - 1)) : 0;
      if (i == want) {
        sheet_images[next_sheet] = img;
        img = (piola_image){0};
        snprintf(sheet_labels[next_sheet], sizeof sheet_labels[0], "FRAME %d  T = %.3f S",
                 frames[i], t);
        ++next_sheet;
      }
    }
  }
  double per_frame = count > 0 ? (now_seconds() - t_start) / count : 0;
  piola_image_free(&img);
  piola_renderer_destroy(r);
  free(pvd);
  if (rc == 0)
    fprintf(stderr, "piola render: %d PNGs written (%.3f s per frame)\n", count, per_frame);

  if (rc == 0 && sheet_count > 0) {
    const char *labels[100];
    for (int i = 0; i < sheet_count; ++i) labels[i] = sheet_labels[i];
    int columns = sheet_count <= 4 ? sheet_count : sheet_count <= 9 ? 3 : 4;
    if (sheet_count > 12) columns = 5;
    piola_image out = {0};
    char path[4400];
    snprintf(path, sizeof path, "%s/contact_sheet.png", render_dir);
    if (piola_image_contact_sheet(sheet_images, labels, sheet_count, columns, 480, &out) !=
            PIOLA_OK ||
        piola_image_write_png(path, &out) != PIOLA_OK) {
      fprintf(stderr, "piola render: contact sheet: %s\n", piola_last_error());
      rc = 1;
    } else {
      fprintf(stderr, "piola render: contact sheet of %d frames: %s\n", sheet_count, path);
    }
    piola_image_free(&out);
  }
  for (int i = 0; i < sheet_count; ++i) piola_image_free(&sheet_images[i]);
  free(sheet_images);
  free(sheet_labels);

  if (rc == 0 && movie != 0 && !isfinite(fps)) {
    /* real time: the simulation's frame spacing, times the thinning of --every */
    fps = 30;
    if (count >= 2 && first_gap_time > 0) fps = 1.0 / first_gap_time;
    if (!(fps >= 1)) fps = 1;
    if (fps > 120) fps = 120;
  }
  if (rc == 0 && movie != 0) {
    if (!find_in_path("ffmpeg")) {
      fprintf(stderr,
              "piola render: ffmpeg not found on PATH: no movie (scripts/install-deps.sh installs "
              "it)\n");
      if (movie == 1) rc = 1;
    } else {
      const char *encoder = NULL;
      if (make_movie(render_dir, frames, count, fps, &encoder) == 0) {
        fprintf(stderr, "piola render: movie of %d frames at %g fps (%s): %s/movie.mp4\n", count,
                fps, encoder, render_dir);
      } else {
        fprintf(stderr, "piola render: ffmpeg failed; see %s/ffmpeg.log\n", render_dir);
        rc = 1;
      }
    }
  }
  free(frames);
  return rc;
}
