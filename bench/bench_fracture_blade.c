/* What a moving blade costs (docs/fracture.md, "A moving blade"): a step during which the
 * blade cuts, against the same step of the body never cut.
 *
 *   build/<dir>/bench_fracture_blade [cubes along x] [sweep steps] [--default-allocator]
 *
 * The body is a grid of nx x nx/3 x nx/3 cubes (6 tets each) of 1 cm, stretched and flying
 * with damping, as in bench_fracture. A flat, slightly tilted blade across the middle of its
 * length slides down through it in `sweep steps` steps of a fixed dt, cutting the tets it
 * passes through before each step. Each step of the cut body is timed against a step of the
 * uncut one taken just before it (thread CPU time, interleaved A/B); the medians of the
 * steps that cut, their ratio, and the tets cut per such step are printed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "piola/mesh.h"
#include "piola/threads.h"
#include "piola/world.h"
#include "piola/world_fracture.h"
#include "support/bench_fracture_body.h"
#include "support/bench_support.h"

int main(int argc, char **argv) {
  bench_allocator(&argc, argv);
  const int nx = argc > 1 ? atoi(argv[1]) : 30;
  const int sweep = argc > 2 ? atoi(argv[2]) : 40;
  if (nx < 6 || sweep < 2) {
    fprintf(stderr, "usage: bench_fracture_blade [cubes along x >= 6] [sweep steps >= 2]\n");
    return 2;
  }
  piola_set_thread_count(1);
  const double h = 0.01, length = nx * h, side = (nx / 3) * h;
  piola_tet_mesh mesh;
  if (piola_tet_mesh_box_grid(nx, nx / 3, nx / 3, (piola_vec3){h, h, h}, &mesh) != PIOLA_OK) return 1;
  const piola_vec3 velocity = (piola_vec3){0, 0.1, 0};
  piola_world *uncut = bench_fracture_world(&mesh, velocity), *cut = bench_fracture_world(&mesh, velocity);
  if (!uncut || !cut) return 1;
  printf("grid %d x %d x %d cubes: %d tets, %d nodes, 1 thread\n", nx, nx / 3, nx / 3, (int)mesh.tet_count,
         (int)mesh.vertex_count);
  const double dt = fmin(piola_world_stable_dt(uncut), piola_world_stable_dt(cut));
  /* the blade: the plane x + 0.13 y = mid, wide in y, its lower edge above the body at t = 0,
   * sliding down (along its plane) past the body's bottom in `sweep` steps */
  const double mid = 0.5 * length + 0.37 * h, top = 1.6 * side, drop = 2.2 * side;
  const double corners[4][2] = {{-side, top}, {2 * side, top}, {2 * side, top + side}, {-side, top + side}};
  double positions[12];
  for (int i = 0; i < 4; ++i)
    positions[3 * i] = mid - 0.13 * corners[i][0], positions[3 * i + 1] = corners[i][0], positions[3 * i + 2] = corners[i][1];
  int32_t triangles[6] = {0, 1, 2, 0, 2, 3};
  piola_tri_mesh blade = {.vertex_count = 4, .positions = positions, .triangle_count = 2, .triangles = triangles};
  piola_fracture_cut c = {.time = 0, .blade = &blade, .end_time = sweep * dt, .velocity = {0, 0, -drop / (sweep * dt)}};
  piola_fracture_def def = piola_default_fracture_def();
  def.cuts = &c, def.cut_count = 1;
  if (piola_world_solid_set_fracture(cut, 0, &def) != PIOLA_OK) {
    fprintf(stderr, "bench_fracture_blade: %s\n", piola_last_error());
    return 1;
  }
  bench_fracture_time_steps(uncut, 1, dt); /* warm up (damping assembly) */
  double *a = malloc(sizeof(double) * (size_t)sweep), *b = malloc(sizeof(double) * (size_t)sweep);
  double *ratio = malloc(sizeof(double) * (size_t)sweep);
  int cutting = 0;
  int32_t before = piola_world_solid_cut_tet_count(cut, 0);
  for (int s = 0; s <= sweep; ++s) {
    const double ta = bench_fracture_time_steps(uncut, 1, dt), tb = bench_fracture_time_steps(cut, 1, dt);
    const int32_t now = piola_world_solid_cut_tet_count(cut, 0);
    if (now > before) a[cutting] = ta, b[cutting] = tb, ratio[cutting] = tb / ta, ++cutting;
    before = now;
  }
  const int32_t cut_tets = piola_world_solid_cut_tet_count(cut, 0);
  printf("sweep of %d steps (dt %.3g s): %d steps cut, %d tets in all (%.1f per cutting step), %d fragments\n",
         sweep, dt, cutting, (int)cut_tets, cutting ? (double)cut_tets / cutting : 0.0,
         (int)piola_world_solid_fragment_count(cut, 0));
  if (cutting > 0)
    printf("steps that cut (thread CPU time, medians): uncut %.3f ms, with the blade's cut %.3f ms, "
           "ratio %.2f\n",
           1e3 * bench_median(a, cutting), 1e3 * bench_median(b, cutting), bench_median(ratio, cutting));
  free(a), free(b), free(ratio);
  free(mesh.positions), free(mesh.tets);
  piola_world_destroy(uncut);
  piola_world_destroy(cut);
  return 0;
}
