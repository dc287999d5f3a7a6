/* Cost of section-9 collision processing per node, for each obstacle shape: 200000 random
 * nodes in a cube 1.2 m wide around an obstacle about 0.6 m across (turning, friction 0.3);
 * for the mesh, the bunny_10k surface and nodes in a box 1.5 times its bounding box. Prints
 * the median of 7 runs in ns per node, with the fraction of nodes inside.
 *
 *   build/NAME/bench_collisions [nodes]     (OMP_NUM_THREADS sets the threads) */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "piola/mesh_io.h"
#include "piola/obstacle.h"
#include "support/bench_support.h"

int main(int argc, char **argv) {
  const int n = argc > 1 ? atoi(argv[1]) : 200000;
  if (n <= 0) return 1;
  double *x0 = malloc(sizeof(double) * 3 * (size_t)n), *x = malloc(sizeof(double) * 3 * (size_t)n);
  double *v = malloc(sizeof(double) * 3 * (size_t)n);
  if (!x0 || !x || !v) return 1;
  piola_tri_mesh bunny = {0};
  piola_status read = piola_tri_mesh_read(PIOLA_DATA_DIR "/surface/bunny_10k.obj", &bunny);
  static const char *const names[] = {"plane",           "sphere",          "box",
                                      "cylinder",        "capsule",         "torus",
                                      "gear (24 teeth)", "mesh (bunny_10k)"};
  printf("%d nodes, %d threads, median of 7 runs\n", n, omp_get_max_threads());
  printf("| obstacle | ns/node | nodes inside |\n|---|---|---|\n");
  for (int type = 0; type < PIOLA_OBSTACLE_TYPE_COUNT; ++type) {
    piola_obstacle_def d = piola_default_obstacle_def();
    d.type = (piola_obstacle_type)type;
    d.radius = 0.3;
    d.minor_radius = 0.1;
    d.half_length = 0.1;
    d.half_extents = (piola_vec3){0.2, 0.2, 0.2};
    d.tooth_count = 24;
    d.tooth_depth = 0.05;
    d.friction = 0.3;
    d.motion.angular_speed = piola_track_constant(1.0);
    double lo[3] = {-0.6, -0.6, -0.6}, hi[3] = {0.6, 0.6, 0.6};
    if (type == PIOLA_OBSTACLE_MESH) {
      if (read != PIOLA_OK) {
        printf("| %s | (%s) | |\n", names[type], piola_last_error());
        continue;
      }
      d.mesh = &bunny;
      for (int k = 0; k < 3; ++k) lo[k] = 1e300, hi[k] = -1e300;
      for (int32_t i = 0; i < bunny.vertex_count; ++i)
        for (int k = 0; k < 3; ++k) {
          double p = bunny.positions[3 * i + k];
          lo[k] = p < lo[k] ? p : lo[k];
          hi[k] = p > hi[k] ? p : hi[k];
        }
      for (int k = 0; k < 3; ++k) {
        double pad = 0.25 * (hi[k] - lo[k]);
        lo[k] -= pad, hi[k] += pad;
      }
    }
    piola_obstacle *o = NULL;
    if (piola_obstacle_create(&d, &o) != PIOLA_OK) {
      printf("| %s | (%s) | |\n", names[type], piola_last_error());
      continue;
    }
    unsigned long long state = 88172645463325252ull;
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) {
        state ^= state << 13, state ^= state >> 7, state ^= state << 17;
        x0[3 * i + k] = lo[k] + (hi[k] - lo[k]) * (double)(state >> 11) * 0x1.0p-53;
      }
    double runs[7];
    int hits = 0;
    for (int r = 0; r < 7; ++r) {
      for (int i = 0; i < 3 * n; ++i) x[i] = x0[i], v[i] = 0.0;
      double t0 = bench_wall_seconds();
      hits = piola_obstacles_collide(&o, 1, 0.5, 0.01, n, x, v, NULL, NULL);
      runs[r] = bench_wall_seconds() - t0;
    }
    qsort(runs, 7, sizeof(double), bench_compare_doubles);
    printf("| %s | %.1f | %.1f %% |\n", names[type], runs[3] / n * 1e9, 100.0 * hits / n);
    piola_obstacle_destroy(o);
  }
  free(bunny.positions);
  free(bunny.triangles);
  free(x0);
  free(x);
  free(v);
  return 0;
}
