/* What fracture costs (docs/fracture.md): a cut event (cutting k tets, then the body's
 * rebuild) and a step of a body with about 10% of its tets cut against the same body uncut.
 *
 *   build/<dir>/bench_fracture [cubes along x] [steps per sample] [samples] [--default-allocator]
 *
 * The body is a grid of nx x nx/3 x nx/3 cubes (6 tets each), stretched and spinning in free
 * flight with damping. Parallel, slightly tilted planes cut it until at least 10% of its
 * tets are cut; each cut's time and tet count are printed. Then the uncut and the cut body
 * are stepped in turns at the same fixed step (thread CPU time, samples interleaved A/B so
 * the machine's load falls on both alike); the medians and their ratio are printed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "piola/elastic_body.h"
#include "piola/mesh.h"
#include "piola/threads.h"
#include "piola/world.h"
#include "piola/world_fracture.h"
#include "support/bench_fracture_body.h"
#include "support/bench_support.h"

int main(int argc, char **argv) {
  bench_allocator(&argc, argv);
  const int nx = argc > 1 ? atoi(argv[1]) : 45;
  const int steps = argc > 2 ? atoi(argv[2]) : 20;
  const int samples = argc > 3 ? atoi(argv[3]) : 7;
  if (nx < 6 || steps < 1 || samples < 1) {
    fprintf(stderr, "usage: bench_fracture [cubes along x >= 6] [steps] [samples]\n");
    return 2;
  }
  piola_set_thread_count(1);
  const double h = 0.01;
  piola_tet_mesh mesh;
  if (piola_tet_mesh_box_grid(nx, nx / 3, nx / 3, (piola_vec3){h, h, h}, &mesh) != PIOLA_OK) return 1;
  const piola_vec3 velocity = (piola_vec3){0.1, 0, 0};
  piola_world *uncut = bench_fracture_world(&mesh, velocity), *cut = bench_fracture_world(&mesh, velocity);
  if (!uncut || !cut) return 1;
  const int32_t tets = mesh.tet_count;
  printf("grid %d x %d x %d cubes: %d tets, %d nodes, 1 thread\n", nx, nx / 3, nx / 3, (int)tets,
         (int)mesh.vertex_count);
  /* planes across x, tilted so they cross tets, not faces, until 10% of the tets are cut */
  double event_seconds[64];
  int events = 0;
  for (int k = 1; k < 64 && piola_world_solid_cut_tet_count(cut, 0) < tets / 10; ++k) {
    const double x = (k * 7.3 * h);
    if (x > nx * h) break;
    const double point[3] = {x, 0.5 * h * (nx / 3), 0.5 * h * (nx / 3)}, normal[3] = {1, 0.13, 0.07};
    int32_t count = 0;
    double t0 = bench_thread_cpu_seconds();
    if (piola_world_solid_cut(cut, 0, point, normal, &count) != PIOLA_OK) {
      fprintf(stderr, "bench_fracture: %s\n", piola_last_error());
      return 1;
    }
    event_seconds[events] = bench_thread_cpu_seconds() - t0;
    printf("cut %d: %d tets cut in %.1f ms (%.2f us per cut tet)\n", events + 1, (int)count,
           1e3 * event_seconds[events], 1e6 * event_seconds[events] / (count > 0 ? count : 1));
    ++events;
  }
  const int32_t cut_tets = piola_world_solid_cut_tet_count(cut, 0);
  printf("after %d cuts: %d of %d tets cut (%.1f%%), %d fragments, %d tets in the mesh\n", events,
         (int)cut_tets, (int)tets, 100.0 * cut_tets / tets, (int)piola_world_solid_fragment_count(cut, 0),
         (int)piola_elastic_body_tet_count(piola_world_solid_body(cut, 0)));
  printf("median cut event: %.1f ms\n", 1e3 * bench_median(event_seconds, events));
  /* the same fixed step for both, below either's bound */
  double dt = fmin(piola_world_stable_dt(uncut), piola_world_stable_dt(cut));
  /* warm up (damping assembly) */
  bench_fracture_time_steps(uncut, 2, dt), bench_fracture_time_steps(cut, 2, dt);
  double *a = malloc(sizeof(double) * (size_t)samples), *b = malloc(sizeof(double) * (size_t)samples);
  double *ratio = malloc(sizeof(double) * (size_t)samples);
  for (int s = 0; s < samples; ++s) {
    a[s] = bench_fracture_time_steps(uncut, steps, dt);
    b[s] = bench_fracture_time_steps(cut, steps, dt);
    ratio[s] = b[s] / a[s];
  }
  printf("step (dt %.3g s, %d steps x %d samples, thread CPU time): uncut %.3f ms, cut %.3f ms, "
         "median ratio %.3f (target <= 1.5)\n",
         dt, steps, samples, 1e3 * bench_median(a, samples), 1e3 * bench_median(b, samples),
         bench_median(ratio, samples));
  free(a), free(b), free(ratio);
  free(mesh.positions), free(mesh.tets);
  piola_world_destroy(uncut);
  piola_world_destroy(cut);
  return 0;
}
