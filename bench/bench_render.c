/* Preview rendering speed: a torus of about 100K triangles (built in code) at 1280x720,
 * filling about a third of the view, over a plane ground and next to a sphere obstacle, in
 * plain and inverted colouring, plus the cost of writing the PNG. Prints the median of 9
 * renders in ms per frame.
 *
 *   build/NAME/bench_render [triangles] [width height]   (OMP_NUM_THREADS sets the threads) */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

#include "piola/render.h"
#include "support/bench_support.h"

int main(int argc, char **argv) {
  long want = argc > 1 ? atol(argv[1]) : 100000;
  int width = argc > 3 ? atoi(argv[2]) : 1280, height = argc > 3 ? atoi(argv[3]) : 720;
  if (want < 100 || width < 16 || height < 16) return 1;
  /* torus: u around the ring (n), v around the tube (m = n / 2), 2 n m triangles */
  int n = (int)ceil(sqrt((double)want)), m = n / 2;
  int32_t nv = n * m, nt = 2 * n * m;
  double *x = malloc(3 * (size_t)nv * sizeof *x);
  int32_t *tri = malloc(3 * (size_t)nt * sizeof *tri);
  uint8_t *flags = malloc((size_t)nt);
  if (!x || !tri || !flags) return 1;
  const double R = 0.3, r = 0.1;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      double u = 2 * M_PI * i / n, v = 2 * M_PI * j / m;
      double *p = x + 3 * ((size_t)i * (size_t)m + (size_t)j);
      p[0] = (R + r * cos(v)) * cos(u);
      p[1] = (R + r * cos(v)) * sin(u);
      p[2] = 0.15 + r * sin(v);
    }
  int32_t k = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      int32_t a = i * m + j, b = ((i + 1) % n) * m + j, c = ((i + 1) % n) * m + (j + 1) % m,
              d = i * m + (j + 1) % m;
      tri[3 * k] = a, tri[3 * k + 1] = b, tri[3 * k + 2] = c, flags[k] = (i % 17) == 0, ++k;
      tri[3 * k] = a, tri[3 * k + 1] = c, tri[3 * k + 2] = d, flags[k] = (i % 17) == 0, ++k;
    }
  piola_render_mesh mesh = {nv, x, nt, tri, flags, NULL, NULL, 0};
  piola_obstacle_def plane = piola_default_obstacle_def();
  plane.type = PIOLA_OBSTACLE_PLANE;
  piola_obstacle_def ball = piola_default_obstacle_def();
  ball.type = PIOLA_OBSTACLE_SPHERE;
  ball.center = (piola_vec3){0.55, 0.2, 0.1};
  ball.radius = 0.1;
  printf("torus of %d triangles at %d x %d, %d threads, median of 9 renders\n", (int)nt, width,
         height, omp_get_max_threads());
  printf("| case | ms/frame |\n|---|---|\n");
  enum { RUNS = 9 };
  for (int mode = 0; mode < 4; ++mode) {
    piola_render_def def = piola_default_render_def();
    def.width = width;
    def.height = height;
    def.color = mode == 1 ? PIOLA_RENDER_COLOR_INVERTED : PIOLA_RENDER_COLOR_PLAIN;
    def.shadows = mode != 3;
    piola_renderer *rd;
    if (piola_renderer_create(&def, &rd) != PIOLA_OK) {
      printf("%s\n", piola_last_error());
      return 1;
    }
    if (mode != 2) {
      piola_renderer_add_obstacle(rd, &plane);
      piola_renderer_add_obstacle(rd, &ball);
    }
    piola_renderer_fit_camera(rd, (piola_vec3){-0.4, -0.4, 0.05}, (piola_vec3){0.4, 0.4, 0.25});
    piola_image img = {0};
    double t[RUNS], tpng[RUNS];
    char png[64];
    snprintf(png, sizeof png, "/tmp/piola_bench_render_%d.png", (int)getpid());
    for (int run = 0; run < RUNS; ++run) {
      double t0 = bench_wall_seconds();
      if (piola_renderer_render(rd, &mesh, &img) != PIOLA_OK) return 1;
      double t1 = bench_wall_seconds();
      if (mode == 0 && piola_image_write_png(png, &img) != PIOLA_OK) return 1;
      tpng[run] = bench_wall_seconds() - t1;
      t[run] = t1 - t0;
    }
    qsort(t, RUNS, sizeof t[0], bench_compare_doubles);
    qsort(tpng, RUNS, sizeof tpng[0], bench_compare_doubles);
    static const char *const names[] = {"plain, plane ground + sphere obstacle",
                                        "inverted colouring, same scene",
                                        "plain, fallback ground only", "plain, obstacles, no shadows"};
    printf("| %s | %.1f |\n", names[mode], 1e3 * t[RUNS / 2]);
    if (mode == 0) printf("| PNG write (level 3) of that frame | %.1f |\n", 1e3 * tpng[RUNS / 2]);
    unlink(png);
    piola_image_free(&img);
    piola_renderer_destroy(rd);
  }
  free(x), free(tri), free(flags);
  return 0;
}
