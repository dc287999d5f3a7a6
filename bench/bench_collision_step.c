/* Collision handling against the rest of the step on the folding cloth (issue 7), with
 * collisions after every step and once per collision interval (BFA02's collision step,
 * piola_world_def.collision_interval, docs/contact.md).
 *
 *   build/<dir>/bench_collision_step [scene] [cells] [t_warm] [frames] [repeats]
 *
 * scene: default examples/cloth_folds.json (run from the source folder); its
 * "resolution": [48, 48] is replaced by [cells, cells] (default 48). Each repeat loads the
 * scene, advances to t_warm (s, default 0) with the scene's own collision interval, then
 * times `frames` frames (default 2) with the world's step timers (src/sim/step_profile.h)
 * twice from that same state: with collisions after every step (interval 0) and with the
 * scene's interval. "collision" is the world phase of the step (self-collision processing,
 * plus the stable-dt bound and plasticity, which are small here); "rest" is every other
 * phase (shell forces, the two damping solves, obstacles). Thread CPU time, medians over
 * repeats. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "piola/scene.h"
#include "sim/world_internal.h"
#include "support/bench_support.h"

enum { MAX_REPEATS = 32 };

static char *read_text(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  long size = ftell(f);
  fseek(f, 0, SEEK_SET);
  char *text = malloc((size_t)size + 64);
  if (text && fread(text, 1, (size_t)size, f) != (size_t)size) free(text), text = NULL;
  if (text) text[size] = 0;
  fclose(f);
  return text;
}

/* Loads the scene with cells x cells and advances it to t_warm with its own interval. */
static piola_scene *load(const char *text, int cells, double t_warm) {
  char *copy = malloc(strlen(text) + 64);
  if (!copy) return NULL;
  strcpy(copy, text);
  char *at = strstr(copy, "\"resolution\": [48, 48]");
  if (at) {
    char repl[64];
    snprintf(repl, sizeof repl, "\"resolution\": [%d, %d]", cells, cells);
    const size_t a = strlen("\"resolution\": [48, 48]");
    memmove(at + strlen(repl), at + a, strlen(at + a) + 1);
    memcpy(at, repl, strlen(repl));
  }
  piola_scene *scene = NULL;
  piola_status st = piola_scene_load_string(copy, ".", "bench", &scene);
  free(copy);
  if (st != PIOLA_OK || piola_world_advance_to(piola_scene_world(scene), t_warm, NULL) != PIOLA_OK) {
    fprintf(stderr, "bench_collision_step: %s\n", piola_last_error());
    return NULL;
  }
  return scene;
}

int main(int argc, char **argv) {
  const char *path = argc > 1 && argv[1][0] ? argv[1] : "examples/cloth_folds.json";
  int cells = argc > 2 ? atoi(argv[2]) : 48;
  double t_warm = argc > 3 ? atof(argv[3]) : 0;
  int frames = argc > 4 ? atoi(argv[4]) : 2;
  int repeats = argc > 5 ? atoi(argv[5]) : 3;
  if (cells < 1) cells = 48;
  if (frames < 1) frames = 1;
  if (repeats < 1) repeats = 1;
  if (repeats > MAX_REPEATS) repeats = MAX_REPEATS;
  char *text = read_text(path);
  if (!text) return fprintf(stderr, "bench_collision_step: cannot read %s\n", path), 1;
  /* [mode][what][repeat], what: collision ms/step, rest ms/step, steps, collision steps */
  static double samples[2][4][MAX_REPEATS];
  double interval = 0;
  for (int r = 0; r < repeats; ++r) {
    for (int mode = 0; mode < 2; ++mode) {
      piola_scene *scene = load(text, cells, t_warm);
      if (!scene) return 1;
      piola_world *w = piola_scene_world(scene);
      interval = w->def.collision_interval;
      if (mode == 0) w->def.collision_interval = 0;
      const double fps = piola_scene_fps(scene);
      piola__step_profile_reset(&w->profile, 1);
      piola_step_stats st = {0};
      for (int f = 1; f <= frames; ++f)
        if (piola_world_advance_to(w, t_warm + f / fps, &st) != PIOLA_OK) {
          fprintf(stderr, "bench_collision_step: %s\n", piola_last_error());
          return 1;
        }
      const step_profile *p = &w->profile;
      double rest = 0;
      for (int ph = 0; ph < STEP_PHASE_COUNT; ++ph)
        if (ph != STEP_PHASE_WORLD) rest += p->thread_cpu[ph];
      const double steps = (double)st.substeps;
      samples[mode][0][r] = 1e3 * p->thread_cpu[STEP_PHASE_WORLD] / steps;
      samples[mode][1][r] = 1e3 * rest / steps;
      samples[mode][2][r] = steps;
      samples[mode][3][r] = (double)st.collision_steps;
      piola_scene_destroy(scene);
    }
  }
  printf("bench_collision_step: %s at %d x %d cells, from t = %g s, %d frames, interval %.6g s, "
         "median of %d (thread CPU)\n",
         path, cells, cells, t_warm, frames, interval, repeats);
  printf("%-22s %8s %10s %14s %12s %12s %10s\n", "collisions", "steps", "coll steps",
         "coll ms/call", "coll ms/step", "rest ms/step", "coll/rest");
  for (int mode = 0; mode < 2; ++mode) {
    double c = bench_median(samples[mode][0], repeats), rest = bench_median(samples[mode][1], repeats);
    double steps = bench_median(samples[mode][2], repeats), calls = bench_median(samples[mode][3], repeats);
    printf("%-22s %8.0f %10.0f %14.2f %12.3f %12.3f %10.2f\n",
           mode == 0 ? "after every step" : "per interval", steps, calls, c * steps / calls, c, rest,
           c / rest);
  }
  free(text);
  return 0;
}
