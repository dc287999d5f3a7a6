/* Where `piola render` finds its frames: the frame files of an output folder, their times in
 * sim.pvd, and one frame loaded as a surface to draw. */
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/render_cli.h"

static int compare_int(const void *a, const void *b) {
  int x = *(const int *)a, y = *(const int *)b;
  return (x > y) - (x < y);
}

int render_cli_list_frames(const char *folder, const char *suffix, int **out) {
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

double render_cli_frame_time(const char *pvd, int frame) {
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

char *render_cli_read_text(const char *path) {
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

void render_cli_frame_free(render_cli_frame *lf) {
  piola_render_frame_destroy(lf->vtu);
  piola_tri_mesh_free(&lf->obj);
  memset(lf, 0, sizeof *lf);
}

int render_cli_load_frame(const char *dir, bool vtu, int f, const char *field, double time,
                          const render_cli_stress *stress, render_cli_frame *lf) {
  char path[4200];
  memset(lf, 0, sizeof *lf);
  if (vtu) {
    snprintf(path, sizeof path, "%s/frames/frame_%04d.vtu", dir, f);
    if (piola_render_frame_read(path, &lf->vtu) != PIOLA_OK) { /* its message names the file */
      fprintf(stderr, "piola render: %s\n", piola_last_error());
      render_cli_frame_free(lf);
      return -1;
    }
    if ((stress && stress->count > 0 &&
         piola_render_frame_add_stress(lf->vtu, stress->materials, stress->count) != PIOLA_OK) ||
        piola_render_frame_mesh(lf->vtu, field, time, &lf->mesh) != PIOLA_OK) {
      fprintf(stderr, "piola render: %s: %s\n", path, piola_last_error());
      render_cli_frame_free(lf);
      return -1;
    }
  } else {
    snprintf(path, sizeof path, "%s/surface/frame_%04d.obj", dir, f);
    if (piola_tri_mesh_read(path, &lf->obj) != PIOLA_OK) {
      fprintf(stderr, "piola render: %s\n", piola_last_error());
      render_cli_frame_free(lf);
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
