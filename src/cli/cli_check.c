/* `piola check SCENE.json`: everything `piola run` does before its first frame, and an
 * estimate of the run, without writing anything.
 *
 * Validates the scene, reads or generates its meshes and builds the world (the same code as
 * `piola run`, so a scene that passes here starts there), then prints the bodies with their
 * counts, the step the CFL bound allows, the worst elements of each solid, and the expected
 * number of steps and wall time per frame from a short timing of real steps. Uses only the
 * public API. Exit codes: 0 the scene is valid, 2 it is not (the message names the key
 * path), 1 a failure while stepping (the timing steps turned NaN). */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli/cli_numbers.h"
#include "cli/commands.h"
#include "cli/run_budget.h"
#include "piola/elastic_body.h"
#include "piola/mesh_quality.h"
#include "piola/scene.h"
#include "piola/shell_body.h"
#include "piola/threads.h"
#include "piola/world.h"
#include "piola/world_shells.h"

static void usage(FILE *out) {
  fprintf(out,
          "usage: piola check SCENE.json [--threads N] [--timing-seconds S] [--max-steps N]\n"
          "\n"
          "Validates the scene, reads or generates its meshes and builds it as `piola run` would,\n"
          "then prints its bodies, counts, the step the CFL bound allows, the worst elements\n"
          "and an estimate of the run's steps and wall time from a short timing. Writes nothing.\n"
          "  --threads N          worker threads for the timing (default: all cores)\n"
          "  --timing-seconds S   wall time spent on timing steps, 0 for none (default 1)\n"
          "  --max-steps N        refuse, as piola run would, past N estimated steps (1e7)\n"
          "  -h, --help           this text\n");
}

static double now_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Altitude of a tet (m): 3 |volume| / its largest face area. */
static double tet_altitude(const double *a, const double *b, const double *c, const double *d) {
  const double *p[4] = {a, b, c, d};
  double e[3][3];
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) e[i][k] = p[i + 1][k] - p[0][k];
  double volume6 = fabs(e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                        e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                        e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]));
  static const int faces[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  double max_area2 = 0;
  for (int f = 0; f < 4; ++f) {
    const double *x = p[faces[f][0]], *y = p[faces[f][1]], *z = p[faces[f][2]];
    double u[3] = {y[0] - x[0], y[1] - x[1], y[2] - x[2]};
    double v[3] = {z[0] - x[0], z[1] - x[1], z[2] - x[2]};
    double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    max_area2 = fmax(max_area2, sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]));
  }
  return max_area2 > 0 ? volume6 / max_area2 : 0;
}

enum { WORST = 3 };

/* One solid's line, and its WORST tets by aspect ratio (of the rest shape, the one the
 * step bound sees). */
static void print_solid(const piola_world *world, int32_t s) {
  const piola_elastic_body *b = piola_world_solid_body(world, s);
  int32_t nv = piola_elastic_body_vertex_count(b), nt = piola_elastic_body_tet_count(b);
  const int32_t *tets = piola_elastic_body_tets(b);
  const double *x = piola_elastic_body_rest_positions(b);
  double h = piola_elastic_body_min_rest_altitude(b), c = piola_elastic_body_max_wave_speed(b);
  printf("  solid %d \"%s\": %d vertices, %d tets; min rest altitude %.4g m, wave speed %.4g m/s, "
         "h / c = %.4g s\n",
         (int)s, piola_world_solid_name(world, s), (int)nv, (int)nt, h, c, c > 0 ? h / c : INFINITY);
  int32_t worst[WORST];
  double aspect[WORST];
  int count = 0;
  int32_t thinnest = -1;
  double thinnest_h = INFINITY;
  for (int32_t t = 0; t < nt; ++t) {
    const double *p[4];
    for (int k = 0; k < 4; ++k) p[k] = x + 3 * (size_t)tets[4 * (size_t)t + (size_t)k];
    double a = piola_tet_aspect_ratio(p[0], p[1], p[2], p[3]);
    double alt = tet_altitude(p[0], p[1], p[2], p[3]);
    if (alt < thinnest_h) thinnest_h = alt, thinnest = t;
    if (!(a == a)) a = INFINITY; /* a degenerate tet ranks worst */
    int i = count < WORST ? count++ : WORST;
    if (i == WORST && !(a > aspect[WORST - 1])) continue;
    if (i == WORST) i = WORST - 1;
    while (i > 0 && a > aspect[i - 1]) {
      aspect[i] = aspect[i - 1], worst[i] = worst[i - 1];
      --i;
    }
    aspect[i] = a, worst[i] = t;
  }
  printf("    worst aspect:");
  for (int i = 0; i < count; ++i)
    printf(" tet %d: %.3g%s", (int)worst[i], aspect[i], i + 1 < count ? "," : "");
  printf(" (1 = regular)");
  if (thinnest >= 0) printf("; thinnest: tet %d (altitude %.4g m)", (int)thinnest, thinnest_h);
  printf("\n");
}

/* Prints on stderr each warning the world has raised that warned[] does not mark yet, and
 * marks it. */
static void print_new_warnings(const piola_world *world, bool warned[]) {
  for (int k = 0; k < PIOLA_WARNING_KIND_COUNT; ++k) {
    const char *text = piola_world_warning(world, (piola_warning_kind)k);
    if (text && !warned[k]) fprintf(stderr, "piola check: warning: %s\n", text), warned[k] = true;
  }
}

int cli_check(int argc, char **argv) {
  const char *scene_path = NULL;
  long threads = 0;
  double timing_seconds = 1;
  double max_steps = 1e7; /* piola run's default limit */
  for (int i = 1; i < argc; ++i) {
    const char *a = argv[i];
    if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
      usage(stdout);
      return 0;
    } else if (strcmp(a, "--threads") == 0) {
      char *end = NULL;
      threads = ++i < argc ? strtol(argv[i], &end, 10) : 0;
      if (i >= argc || !argv[i][0] || *end || threads < 1 || threads > 1024)
        return fprintf(stderr, "piola check: --threads needs an integer in [1, 1024]\n"), 2;
    } else if (strcmp(a, "--timing-seconds") == 0) {
      char *end = NULL;
      timing_seconds = ++i < argc ? strtod(argv[i], &end) : NAN;
      if (i >= argc || !argv[i][0] || *end || !(timing_seconds >= 0 && timing_seconds <= 3600))
        return fprintf(stderr, "piola check: --timing-seconds needs seconds in [0, 3600]\n"), 2;
    } else if (strcmp(a, "--max-steps") == 0) {
      if (++i >= argc || !cli_parse_double(argv[i], &max_steps) || !(max_steps >= 1) ||
          max_steps > 1e18)
        return fprintf(stderr, "piola check: --max-steps needs a number in [1, 1e18]\n"), 2;
    } else if (a[0] == '-' && a[1]) {
      fprintf(stderr, "piola check: unknown option '%s'\n", a);
      usage(stderr);
      return 2;
    } else if (!scene_path) {
      scene_path = a;
    } else {
      fprintf(stderr, "piola check: more than one scene given ('%s' and '%s')\n", scene_path, a);
      return 2;
    }
  }
  if (!scene_path) {
    fprintf(stderr, "piola check: no scene file given\n");
    usage(stderr);
    return 2;
  }
  if (threads > 0) piola_set_thread_count((int)threads);
  double t0 = now_seconds();
  piola_scene *scene = NULL;
  if (piola_scene_load(scene_path, &scene) != PIOLA_OK) {
    fprintf(stderr, "piola check: %s\n", piola_last_error());
    return 2;
  }
  double build_seconds = now_seconds() - t0;
  piola_world *world = piola_scene_world(scene);
  double fps = piola_scene_fps(scene);
  int32_t frames = piola_scene_frames(scene);
  int32_t solids = piola_world_solid_count(world), shells = piola_world_shell_count(world);
  long long vertices = 0, tets = 0, triangles = 0;
  printf("scene:     %s: valid, built in %.2f s\n", scene_path, build_seconds);
  printf("output:    %d frames after frame 0 at %g fps (%.4g s simulated)\n", (int)frames, fps,
         frames / fps);
  printf("bodies:\n");
  for (int32_t s = 0; s < solids; ++s) {
    const piola_elastic_body *b = piola_world_solid_body(world, s);
    vertices += piola_elastic_body_vertex_count(b);
    tets += piola_elastic_body_tet_count(b);
    print_solid(world, s);
  }
  for (int32_t s = 0; s < shells; ++s) {
    const piola_shell_body *b = piola_world_shell_body(world, s);
    int32_t nv = piola_shell_body_vertex_count(b), nt = piola_shell_body_triangle_count(b);
    vertices += nv, triangles += nt;
    printf("  shell %d \"%s\": %d vertices, %d triangles\n", (int)s,
           piola_world_shell_name(world, s), (int)nv, (int)nt);
  }
  printf("counts:    %d solids, %d shells, %d obstacles (bones included); %lld vertices, %lld "
         "tets, %lld triangles\n",
         (int)solids, (int)shells, (int)piola_world_obstacle_count(world), vertices, tets,
         triangles);
  double dt = piola_world_stable_dt(world);
  double frame_dt = 1.0 / fps;
  double steps_per_frame = ceil(frame_dt / dt - 1e-9);
  printf("step:      %.4g s (\"newmark\": the smaller of integrator.max_dt and the CFL bound at "
         "the start; \"backward_euler\", \"quasistatic\": integrator.dt)\n",
         dt);
  printf("estimate:  %.0f steps per frame, %.0f steps in all (at the starting step; contact and "
         "keyframed stiffness can change it)\n",
         steps_per_frame, steps_per_frame * frames);
  /* what the world warned of while it was built (slivers, empty selections, cfl) */
  bool warned[PIOLA_WARNING_KIND_COUNT] = {false};
  print_new_warnings(world, warned);
  /* the run piola run would refuse is no valid run */
  if (!run_budget_ok("piola check", scene_path, world, frames, fps, max_steps, false)) {
    piola_scene_destroy(scene);
    return 2;
  }
  int rc = 0;
  if (timing_seconds > 0) {
    /* a few real steps, up to the scene's end: past it a body the scene leaves at rest
     * costs an implicit integrator nothing (a quasistatic muscle's 20 frames timed over 496
     * steps read 0.04 s for a run of 0.58 s). With Newmark the first step includes one-time
     * setup, so time after it; an implicit integrator's first step is the run's first
     * Newton solve (a quasistatic scene's first equilibrium, a landing), and counts */
    const double end = frames / fps;
    const int untimed = piola_world_integrator(world) == PIOLA_INTEGRATOR_NEWMARK ? 1 : 0;
    int steps = 0;
    double start = now_seconds(), spent = 0;
    piola_step_stats st;
    while (steps < 1000) {
      if (steps == untimed) start = now_seconds();
      if (piola_world_step(world, INFINITY, &st) != PIOLA_OK) {
        fprintf(stderr, "piola check: step %d of the timing failed: %s\n", steps + 1,
                piola_last_error());
        rc = 1;
        break;
      }
      ++steps;
      if (steps > untimed) {
        spent = now_seconds() - start;
        if (spent >= timing_seconds || piola_world_time(world) >= end) break;
      }
    }
    /* and what its first steps found (a start inside an obstacle, a tangle, bodies through
     * each other or within their thickness), as piola run would say */
    print_new_warnings(world, warned);
    if (rc == 0 && steps > untimed) {
      double per_step = spent / (steps - untimed);
      double per_frame = per_step * steps_per_frame;
      printf("timing:    %d steps, %.4g s wall per step: about %.3g s per frame, %.3g s for the "
             "run (%s; the machine's load counts)\n",
             steps - untimed, per_step, per_frame, per_frame * frames,
             threads > 0 ? "--threads" : "all cores");
    }
  }
  piola_scene_destroy(scene);
  return rc;
}
