/* Benchmark of the backward Euler integrator against Newmark on one scene: a mesh (default
 * torus-easy.veg, 97,878 tets; BENCHMARKS.md also runs the paper's Figure 2 torus, 113,512
 * tets from `piola mesh generate`) as a neo-Hookean solid (E and nu from the command line,
 * default 1 MPa and 0.45, 1000 kg/m^3, shear viscosity 1 Pa s) dropped from 1 cm onto a
 * plane (friction 0.5) under gravity.
 *
 * Backward Euler: `frames` frames of 1/30 s at one step per frame: median wall time per
 * frame, Newton and CG iterations per frame, and the time of one Newton iteration proper,
 * the assembly of the projected stiffness (and the IC(0) factorization or the multigrid
 * setup/refresh) plus the preconditioned CG (to 1e-3 with fixed forcing) (the world's
 * step profile, src/sim/step_profile.h; the line search's force evaluations are not in it),
 * in wall time and in process CPU time (all threads: on a loaded machine the steadier
 * figure); per frame also the steps taken and the process CPU split into the profile's
 * update phase (force evaluations of the line search, residuals, contact passes), assembly,
 * linear solve and the rest. Newmark: the CFL step of the same scene and the median wall time of a step over
 * `newmark_steps` steps, so the time of one frame is steps per frame times that.
 *
 * With reference = 1 (issue 14's "speed-up at equal visual result"), Newmark instead runs
 * all `frames` frames at its CFL step, the explicit reference (the tiny step it needs
 * anyway), timed in process CPU; printed: the largest distance between a node of the two
 * final shapes as a fraction of the diagonal of the reference shape's bounding box ("equal
 * visual result": below 1%), and the CPU-time ratio of the two runs.
 *
 * usage: bench_newton [frames=3] [newmark_steps=20] [mesh] [E] [nu] [threads=2]
 *                     [preconditioner=block_jacobi|incomplete_cholesky|multigrid]
 *                     [forcing=eisenstat_walker|fixed] [reference=0|1]
 *                     [newton_tolerance=1e-5 (the default of integrator.newton_tolerance)]
 *                     [repeats=1] [--default-allocator]
 * With the reference, the backward Euler frames run `repeats` times (fresh worlds; every run
 * must end on the same bits) and the speed-up divides the reference's CPU time by their
 * median: a run of under a second varied by 30% between runs on the project's shared
 * machine, the 30 s reference by a few percent.
 * Freed memory is kept as `piola run` keeps it (src/cli/allocator_policy.h), unless
 * --default-allocator is given: the multigrid setup of every step allocates tens of MB, and
 * with the C library's defaults their pages were faulted in afresh at every step (12% of a
 * Figure 2 torus frame on the project's virtual machine).
 * (block_jacobi fixed is the solver as it was before issue 14's preconditioner and forcing
 * work; "one Newton iteration" is the target only with fixed forcing, where every
 * CG runs to linear_tolerance = 1e-3.) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "piola/mesh_io.h"
#include "piola/threads.h"
#include "piola/world.h"
#include "sim/world_internal.h"
#include "support/bench_support.h"

static piola_preconditioner_type preconditioner = PIOLA_PRECONDITIONER_BLOCK_JACOBI;
static piola_linear_forcing forcing = PIOLA_FORCING_EISENSTAT_WALKER;
static double newton_tolerance = 0; /* 0: the default */

static piola_world *make_world(const piola_tet_mesh *mesh, piola_integrator_type type, double e,
                               double nu, double zmin) {
  piola_world_def wd = piola_default_world_def();
  wd.integrator = type;
  wd.implicit_dt = 1.0 / 30;
  wd.max_dt = 1.0 / 30;
  wd.cfl = 0.5;
  wd.preconditioner = preconditioner;
  wd.linear_forcing = forcing;
  if (newton_tolerance > 0) wd.newton_tolerance = newton_tolerance;
  piola_world *w = NULL;
  if (piola_world_create(&wd, &w) != PIOLA_OK) return NULL;
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = mesh;
  sd.material.model = PIOLA_MODEL_NEOHOOKEAN;
  sd.material.youngs_modulus = e;
  sd.material.poisson_ratio = nu;
  sd.shear_viscosity = piola_track_constant(1);
  piola_obstacle_def g = piola_default_obstacle_def();
  g.type = PIOLA_OBSTACLE_PLANE;
  g.center = (piola_vec3){0, 0, zmin - 0.01};
  g.axis = (piola_vec3){0, 0, 1};
  g.friction = 0.5;
  if (piola_world_add_solid(w, &sd, NULL) != PIOLA_OK || piola_world_add_obstacle(w, &g, NULL) != PIOLA_OK) {
    piola_world_destroy(w);
    return NULL;
  }
  return w;
}

int main(int argc, char **argv) {
  bench_allocator(&argc, argv);
  int frames = argc > 1 ? atoi(argv[1]) : 3;
  int newmark_steps = argc > 2 ? atoi(argv[2]) : 20;
  const char *path = argc > 3 ? argv[3] : PIOLA_DATA_DIR "/vega/torus-easy.veg";
  double e = argc > 4 ? atof(argv[4]) : 1e6, nu = argc > 5 ? atof(argv[5]) : 0.45;
  int threads = argc > 6 ? atoi(argv[6]) : 2;
  if (argc > 7 && !piola_preconditioner_type_from_name(argv[7], &preconditioner)) {
    fprintf(stderr, "bench_newton: unknown preconditioner '%s'\n", argv[7]);
    return 2;
  }
  if (argc > 8 && !piola_linear_forcing_from_name(argv[8], &forcing)) {
    fprintf(stderr, "bench_newton: unknown linear forcing '%s'\n", argv[8]);
    return 2;
  }
  const int reference = argc > 9 && atoi(argv[9]) != 0;
  if (argc > 10) newton_tolerance = atof(argv[10]);
  int repeats = argc > 11 ? atoi(argv[11]) : 1;
  if (repeats < 1) repeats = 1;
  if (frames < 1) frames = 1;
  if (newmark_steps < 1) newmark_steps = 1;
  piola_set_thread_count(threads);
  piola_tet_mesh mesh;
  if (piola_tet_mesh_read(path, &mesh) != PIOLA_OK) {
    fprintf(stderr, "bench_newton: %s\n", piola_last_error());
    return 1;
  }
  double zmin = INFINITY;
  for (int32_t i = 0; i < mesh.vertex_count; ++i) zmin = fmin(zmin, mesh.positions[3 * i + 2]);
  printf("bench_newton: %s, %d tets, E = %g Pa, nu = %g, %d threads, %s, %s forcing\n", path,
         (int)mesh.tet_count, e, nu, threads, piola_preconditioner_type_name(preconditioner),
         piola_linear_forcing_name(forcing));

  piola_world *w = make_world(&mesh, PIOLA_INTEGRATOR_BACKWARD_EULER, e, nu, zmin);
  if (!w) {
    fprintf(stderr, "bench_newton: %s\n", piola_last_error());
    return 1;
  }
  double *frame_ms = malloc(sizeof(double) * (size_t)frames);
  double *iter_ms = malloc(sizeof(double) * (size_t)frames);
  double *assemble_ms = malloc(sizeof(double) * (size_t)frames);
  double *solve_ms = malloc(sizeof(double) * (size_t)frames);
  double *iter_cpu_ms = malloc(sizeof(double) * (size_t)frames);
  double *frame_cpu_ms = malloc(sizeof(double) * (size_t)frames);
  long newton = 0, linear = 0, failures = 0;
  for (int f = 1; f <= frames; ++f) {
    piola_step_stats st;
    memset(&st, 0, sizeof st);
    piola__step_profile_reset(&w->profile, 1);
    double t0 = bench_wall_seconds(), c0 = bench_cpu_seconds();
    if (piola_world_advance_to(w, f / 30.0, &st) != PIOLA_OK) {
      fprintf(stderr, "bench_newton: frame %d: %s\n", f, piola_last_error());
      return 1;
    }
    frame_ms[f - 1] = 1e3 * (bench_wall_seconds() - t0);
    frame_cpu_ms[f - 1] = 1e3 * (bench_cpu_seconds() - c0);
    const double per = st.newton_iterations > 0 ? 1e3 / (double)st.newton_iterations : 0;
    assemble_ms[f - 1] = per * w->profile.wall[STEP_PHASE_ASSEMBLE];
    solve_ms[f - 1] = per * w->profile.wall[STEP_PHASE_LINEAR];
    iter_ms[f - 1] = assemble_ms[f - 1] + solve_ms[f - 1];
    iter_cpu_ms[f - 1] =
        per * (w->profile.cpu[STEP_PHASE_ASSEMBLE] + w->profile.cpu[STEP_PHASE_LINEAR]);
    newton += st.newton_iterations, linear += st.linear_iterations, failures += st.newton_failures;
    printf("  backward Euler frame %d: %.1f ms (%.1f ms process CPU), %d steps, %d Newton, %d CG, %d failures; per Newton iteration "
           "%.1f ms assembly + %.1f ms linear solve\n",
           f, frame_ms[f - 1], frame_cpu_ms[f - 1], (int)st.substeps, (int)st.newton_iterations,
           (int)st.linear_iterations, (int)st.newton_failures, assemble_ms[f - 1], solve_ms[f - 1]);
    /* where the frame's CPU goes: "forces" is the profile's update phase, which in the
     * implicit step holds the line search's force evaluations and residuals and the
     * contact passes; "other" is the rest of the frame (set-up, first guess, world phases) */
    const double *pc = w->profile.cpu;
    printf("    process CPU: %.1f ms forces and line search, %.1f ms assembly, %.1f ms linear solve, "
           "%.1f ms other\n",
           1e3 * pc[STEP_PHASE_UPDATE], 1e3 * pc[STEP_PHASE_ASSEMBLE], 1e3 * pc[STEP_PHASE_LINEAR],
           frame_cpu_ms[f - 1] -
               1e3 * (pc[STEP_PHASE_UPDATE] + pc[STEP_PHASE_ASSEMBLE] + pc[STEP_PHASE_LINEAR]));
  }
  double be_frame = bench_median(frame_ms, frames), be_iter = bench_median(iter_ms, frames);
  double be_assemble = bench_median(assemble_ms, frames), be_solve = bench_median(solve_ms, frames);
  double be_iter_cpu = bench_median(iter_cpu_ms, frames);
  double be_frame_cpu = bench_median(frame_cpu_ms, frames);
  double be_total_cpu = 0;
  for (int f = 0; f < frames; ++f) be_total_cpu += frame_cpu_ms[f];
  const size_t v3 = sizeof(double) * 3 * (size_t)mesh.vertex_count;
  double *be_final = malloc(v3);
  memcpy(be_final, piola_world_solid_positions(w, 0), v3);
  piola_world_destroy(w);
  double *be_runs_cpu = malloc(sizeof(double) * (size_t)repeats);
  be_runs_cpu[0] = be_total_cpu;
  for (int r = 1; r < repeats && reference; ++r) {
    w = make_world(&mesh, PIOLA_INTEGRATOR_BACKWARD_EULER, e, nu, zmin);
    if (!w) {
      fprintf(stderr, "bench_newton: %s\n", piola_last_error());
      return 1;
    }
    const double c0 = bench_cpu_seconds();
    for (int f = 1; f <= frames; ++f)
      if (piola_world_advance_to(w, f / 30.0, NULL) != PIOLA_OK) {
        fprintf(stderr, "bench_newton: repeat %d, frame %d: %s\n", r, f, piola_last_error());
        return 1;
      }
    be_runs_cpu[r] = 1e3 * (bench_cpu_seconds() - c0);
    if (memcmp(be_final, piola_world_solid_positions(w, 0), v3) != 0) {
      fprintf(stderr, "bench_newton: repeat %d did not end where the first run did\n", r);
      return 1;
    }
    piola_world_destroy(w);
  }
  if (reference) be_total_cpu = bench_median(be_runs_cpu, repeats);

  w = make_world(&mesh, PIOLA_INTEGRATOR_NEWMARK, e, nu, zmin);
  const double dt = piola_world_stable_dt(w);
  if (reference) {
    long steps = 0;
    const double c0 = bench_cpu_seconds();
    for (int f = 1; f <= frames; ++f) {
      piola_step_stats st;
      memset(&st, 0, sizeof st);
      if (piola_world_advance_to(w, f / 30.0, &st) != PIOLA_OK) {
        fprintf(stderr, "bench_newton: newmark frame %d: %s\n", f, piola_last_error());
        return 1;
      }
      steps += st.substeps;
    }
    const double nm_cpu = bench_cpu_seconds() - c0;
    const double *x = piola_world_solid_positions(w, 0);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double worst = 0;
    for (int32_t i = 0; i < mesh.vertex_count; ++i) {
      double d2 = 0;
      for (int k = 0; k < 3; ++k) {
        const double r = x[3 * i + k], d = be_final[3 * i + k] - r;
        lo[k] = fmin(lo[k], r), hi[k] = fmax(hi[k], r), d2 += d * d;
      }
      worst = fmax(worst, sqrt(d2));
    }
    const double diagonal = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) +
                                 (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                 (hi[2] - lo[2]) * (hi[2] - lo[2]));
    printf("backward Euler: %d frames in %.2f s process CPU (median of %d runs", frames,
           be_total_cpu / 1e3, repeats);
    for (int r = 0; r < repeats; ++r) printf("%s%.2f", r ? ", " : ": ", be_runs_cpu[r] / 1e3);
    printf(")\n");
    printf("Newmark reference: %ld steps (dt %.3g s) in %.2f s process CPU\n", steps, dt, nm_cpu);
    printf("final shapes: largest node distance %.3g m = %.3g%% of the bounding-box diagonal "
           "(%.3g m)\n",
           worst, 100 * worst / diagonal, diagonal);
    printf("speed-up (process CPU, Newmark reference / backward Euler): %.1f\n",
           nm_cpu / (be_total_cpu / 1e3));
    piola_world_destroy(w);
    free(be_final), free(frame_ms), free(iter_ms), free(assemble_ms), free(solve_ms);
    free(iter_cpu_ms), free(frame_cpu_ms), free(be_runs_cpu);
    free(mesh.positions), free(mesh.tets), free(mesh.tet_regions);
    return 0;
  }
  double *step_ms = malloc(sizeof(double) * (size_t)newmark_steps);
  for (int s = 0; s < newmark_steps; ++s) {
    double t0 = bench_wall_seconds();
    if (piola_world_step(w, 0, NULL) != PIOLA_OK) {
      fprintf(stderr, "bench_newton: newmark step %d: %s\n", s, piola_last_error());
      return 1;
    }
    step_ms[s] = 1e3 * (bench_wall_seconds() - t0);
  }
  double nm_step = bench_median(step_ms, newmark_steps);
  double steps_per_frame = ceil((1.0 / 30) / dt);
  piola_world_destroy(w);
  printf("backward Euler: %.1f ms per frame, %.1f ms process CPU (medians of %d), %.1f Newton and %.0f CG iterations per "
         "frame, %ld failed steps\n",
         be_frame, be_frame_cpu, frames, (double)newton / frames, (double)linear / frames, failures);
  printf("one Newton iteration (assembly + linear solve): %.1f ms wall (%.1f + %.1f), %.1f ms "
         "process CPU (all threads; medians over the frames)\n",
         be_iter, be_assemble, be_solve, be_iter_cpu);
  printf("Newmark: dt %.3g s (%.0f steps per frame), %.2f ms per step (median of %d), so %.0f ms "
         "per frame\n",
         dt, steps_per_frame, nm_step, newmark_steps, steps_per_frame * nm_step);
  printf("speed-up per frame: %.1f\n", steps_per_frame * nm_step / be_frame);
  free(frame_ms), free(iter_ms), free(assemble_ms), free(solve_ms), free(iter_cpu_ms);
  free(frame_cpu_ms), free(be_final), free(be_runs_cpu);
  free(step_ms);
  free(mesh.positions), free(mesh.tets), free(mesh.tet_regions);
  return 0;
}
