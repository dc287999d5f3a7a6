/* Cost of collision processing (BFA02: repulsion, continuous detection, impact zones) per
 * step against surface size: a square cloth grid folded over its middle line, its upper half
 * closing onto the lower one a little more every step (with some random velocity on top), so
 * that the layers come into contact along the fold and then over the whole overlap. Prints,
 * for each size, the median over the measured steps of the processing time (wall clock, and
 * CPU time of all threads, which is steadier on a shared machine), with contacts,
 * impacts and impact-zone vertices per step. A second table splits the time into the phases
 * of a call (CPU time of the calling thread, so all of it with OMP_NUM_THREADS=1): collecting
 * candidate pairs (boxes, trees, the tree descent), repulsion, the detection passes, impulses
 * and impact zones, with the number of candidate pairs and of tree descents per call.
 *
 *   build/NAME/bench_contact [max_triangles [closing]]   (OMP_NUM_THREADS sets the threads)
 *
 * closing: how many thicknesses the far edge moves towards the lower layer per step (default
 * 1: mostly repulsion; 8: the layers are driven through each other, impacts and zones). */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "contact/contact_internal.h"
#include "piola/collision_surface.h"
#include "support/bench_support.h"

static unsigned long long rng_state = 88172645463325252ull;
static double uniform(void) {
  rng_state ^= rng_state << 13, rng_state ^= rng_state >> 7, rng_state ^= rng_state << 17;
  return (double)(rng_state >> 11) * 0x1.0p-53;
}

/* Grid vertex (i, j) of an n x n sheet of side 1 m folded by angle theta about x = 0.5. */
static void folded(int n, int i, int j, double theta, double *p) {
  double x = (double)i / (n - 1), y = (double)j / (n - 1);
  if (x <= 0.5) {
    p[0] = x, p[1] = y, p[2] = 0.0;
  } else {
    double r = x - 0.5;
    p[0] = 0.5 + r * cos(theta), p[1] = y, p[2] = r * sin(theta);
  }
}

int main(int argc, char **argv) {
  const int max_triangles = argc > 1 ? atoi(argv[1]) : 200000;
  static const int targets[] = {10000, 25000, 50000, 100000, 200000};
  const double closing = argc > 2 ? atof(argv[2]) : 1.0;
  if (!(closing > 0.0)) return 1;
  printf(
      "folding cloth closing by %g thickness per step, 8 steps measured after 2 warm-up "
      "steps, %d threads, median per step\n",
      closing, omp_get_max_threads());
  printf(
      "| triangles | vertices | wall ms/step | CPU ms/step | CPU ns/triangle | contacts | impacts "
      "| zone vertices |\n");
  printf("|---|---|---|---|---|---|---|---|\n");
  double phase_ms[5][7];
  int sizes[5], measured = 0;
  for (size_t t = 0; t < sizeof targets / sizeof targets[0]; ++t) {
    if (targets[t] > max_triangles) break;
    const int n = (int)lround(sqrt(targets[t] / 2.0)) + 1;
    const int nv = n * n, nt = 2 * (n - 1) * (n - 1);
    int32_t *tris = malloc(sizeof(int32_t) * 3 * (size_t)nt);
    double *x = malloc(sizeof(double) * 3 * (size_t)nv),
           *v = malloc(sizeof(double) * 3 * (size_t)nv);
    double *m = malloc(sizeof(double) * (size_t)nv);
    if (!tris || !x || !v || !m) return 1;
    int k = 0;
    for (int j = 0; j + 1 < n; ++j)
      for (int i = 0; i + 1 < n; ++i) {
        int32_t a = j * n + i, b = a + 1, c = a + n, d = c + 1;
        tris[k++] = a, tris[k++] = b, tris[k++] = d, tris[k++] = a, tris[k++] = d, tris[k++] = c;
      }
    const double spacing = 1.0 / (n - 1), h = 0.25 * spacing, dt = 1e-3;
    piola_collision_body_def body = piola_default_collision_body_def();
    body.thickness = h, body.friction = 0.3;
    piola_collision_surface_def def = piola_default_collision_surface_def();
    def.vertex_count = nv, def.triangle_count = nt, def.triangles = tris, def.body_count = 1;
    def.bodies = &body;
    piola_collision_surface *surface = NULL;
    if (piola_collision_surface_create(&def, &surface) != PIOLA_OK) return 1;
    /* Start folded to within 4 thicknesses at the far edge; close by one thickness a step. */
    double theta = M_PI - 4.0 * h / 0.5;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) folded(n, i, j, theta, x + 3 * (j * n + i));
    for (int i = 0; i < nv; ++i) m[i] = 1e-4;
    double times[8], cpu[8], phase[5][8], candidates[8], collections[8];
    long long contacts = 0, impacts = 0, zone_vertices = 0;
    for (int step = 0; step < 10; ++step) {
      const double dtheta = closing * h / 0.5;
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          double next[3], *u = v + 3 * (j * n + i);
          folded(n, i, j, theta + dtheta, next);
          double here[3];
          folded(n, i, j, theta, here);
          for (int c = 0; c < 3; ++c)
            u[c] = (next[c] - here[c]) / dt + 0.2 * spacing / dt * (uniform() - 0.5);
        }
      piola_collision_stats st;
      double t0 = bench_wall_seconds(), c0 = bench_cpu_seconds();
      if (piola_collision_surface_process(surface, x, v, m, dt, NULL, &st) != PIOLA_OK) return 1;
      double elapsed = bench_wall_seconds() - t0, cpu_elapsed = bench_cpu_seconds() - c0;
      if (getenv("BENCH_TRACE"))
        fprintf(stderr,
                "step %d: %.1f ms contacts %lld impacts %lld passes %d zone passes %d escaped %d "
                "descents %d\n",
                step, 1e3 * elapsed, (long long)st.contacts, (long long)st.impacts,
                st.collision_passes, st.zone_passes, surface->profile.escaped,
                surface->profile.collections);
      for (int i = 0; i < 3 * nv; ++i) x[i] += dt * v[i];
      theta += dtheta;
      if (step >= 2) {
        times[step - 2] = elapsed, cpu[step - 2] = cpu_elapsed;
        contacts += st.contacts, impacts += st.impacts, zone_vertices += st.zone_vertices;
        const piola__contact_profile *p = &surface->profile;
        phase[0][step - 2] = p->collect, phase[1][step - 2] = p->repulsion;
        phase[2][step - 2] = p->detection, phase[3][step - 2] = p->impulses;
        phase[4][step - 2] = p->zones, candidates[step - 2] = (double)p->candidates;
        collections[step - 2] = p->collections;
      }
    }
    qsort(times, 8, sizeof(double), bench_compare_doubles);
    qsort(cpu, 8, sizeof(double), bench_compare_doubles);
    double median = 0.5 * (times[3] + times[4]), cpu_median = 0.5 * (cpu[3] + cpu[4]);
    printf("| %d | %d | %.1f | %.1f | %.0f | %lld | %lld | %lld |\n", nt, nv, 1e3 * median,
           1e3 * cpu_median, 1e9 * cpu_median / nt, contacts / 8, impacts / 8, zone_vertices / 8);
    for (int ph = 0; ph < 5; ++ph) phase_ms[t][ph] = 1e3 * bench_median(phase[ph], 8);
    phase_ms[t][5] = bench_median(candidates, 8), phase_ms[t][6] = bench_median(collections, 8);
    sizes[t] = nt, measured = (int)t + 1;
    fflush(stdout);
    piola_collision_surface_destroy(surface);
    free(tris), free(x), free(v), free(m);
  }
  printf(
      "\nphases, median CPU ms per step of the calling thread\n"
      "| triangles | collect | repulsion | detection | impulses | zones | candidates | "
      "descents |\n|---|---|---|---|---|---|---|---|\n");
  for (int t = 0; t < measured; ++t)
    printf("| %d | %.1f | %.1f | %.1f | %.1f | %.1f | %.0f | %.0f |\n", sizes[t], phase_ms[t][0],
           phase_ms[t][1], phase_ms[t][2], phase_ms[t][3], phase_ms[t][4], phase_ms[t][5],
           phase_ms[t][6]);
  return 0;
}
