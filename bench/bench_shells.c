/* Benchmark of the shell forces (triangles per second) and of a cloth step.
 *
 *   build/<dir>/bench_shells [repeats]
 *
 * Mesh: a generated 1 m square sheet of 224 x 224 cells (100,352 triangles, ~150K hinges),
 * crumpled by two waves plus noise, with ~1% of the triangles collapsed onto a line (as a
 * cloth has after contact). Reports the bench_median of `repeats` (default 7) timings, with 1 and
 * 2 threads, of
 *   - piola_shell_body_update without bending (in-plane only) and with bending,
 *   - piola_shell_body_damping_forces (in-plane and bending damping: the CG's operator),
 *   - one explicit cloth step: update, damping, velocity/position update and collision
 *     processing against a sphere and a plane,
 *   - one world step (piola_world_step: the Newmark scheme with the two implicit damping
 *     solves, collisions, plastic flow) of the same cloth falling on the sphere. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "piola/elastic_body.h"
#include "piola/obstacle.h"
#include "piola/shell_body.h"
#include "piola/world_shells.h"
#include "support/bench_support.h"

/* CPU time of the process (all threads): on a loaded machine the 1-thread rows' CPU time
 * is the cost of the work itself, while wall time includes waiting for a core. */
static piola_shell_body *make_body(const piola_tri_mesh *mesh, const piola_material *material,
                                   double bending) {
  piola_shell_body_def def = piola_default_shell_body_def();
  def.rest_mesh = mesh;
  def.materials = material;
  def.material_count = 1;
  def.thickness = 5e-4;
  def.density = 300;
  def.bending.stiffness = bending;
  def.bending.damping = bending * 1e-2;
  piola_shell_body *body = NULL;
  if (piola_shell_body_create(&def, &body) != PIOLA_OK) {
    fprintf(stderr, "bench_shells: %s\n", piola_last_error());
    exit(1);
  }
  return body;
}

typedef struct cloth {
  piola_shell_body *body;
  int32_t n;
  double *x, *v, *f, *fd;
  piola_obstacle *obstacles[2];
} cloth;

static void cloth_step(cloth *c, double t, double dt) {
  piola_shell_body_update(c->body, c->x, 1.0, c->f, NULL);
  piola_shell_body_damping_forces(c->body, c->v, 0.1, 0.1, c->fd);
  const double *mass = piola_shell_body_masses(c->body);
  for (int32_t i = 0; i < c->n; ++i)
    for (int k = 0; k < 3; ++k) {
      double a = (c->f[3 * i + k] + c->fd[3 * i + k]) / mass[i] - (k == 2 ? 9.81 : 0.0);
      c->v[3 * i + k] += dt * a;
      c->x[3 * i + k] += dt * c->v[3 * i + k];
    }
  piola_obstacles_collide(c->obstacles, 2, t + dt, dt, c->n, c->x, c->v, NULL, NULL);
}

int main(int argc, char **argv) {
  int repeats = argc > 1 ? atoi(argv[1]) : 7;
  if (repeats < 1) repeats = 1;
  const int cells = 224;
  piola_tri_mesh mesh;
  if (piola_tri_mesh_rectangle(1.0, 1.0, cells, cells, &mesh) != PIOLA_OK) return 1;
  int32_t n = mesh.vertex_count, nt = mesh.triangle_count;
  double *x = malloc(sizeof(double) * 3 * (size_t)n), *f = malloc(sizeof(double) * 3 * (size_t)n);
  double *v = malloc(sizeof(double) * 3 * (size_t)n);
  const double h = 1.0 / cells;
  for (int32_t i = 0; i < n; ++i) {
    const double *p = mesh.positions + 3 * i;
    x[3 * i] = p[0] + 0.1 * h * bench_uniform(-1, 1);
    x[3 * i + 1] = p[1] + 0.1 * h * bench_uniform(-1, 1);
    x[3 * i + 2] = 0.02 * sin(9 * p[0]) * cos(7 * p[1]) + 0.1 * h * bench_uniform(-1, 1);
    for (int k = 0; k < 3; ++k) v[3 * i + k] = bench_uniform(-0.1, 0.1);
  }
  /* collapse ~1% of the triangles: corner 2 onto the midpoint of corners 0 and 1 */
  for (int32_t t = 0; t < nt; t += 100) {
    const int32_t *c = mesh.triangles + 3 * t;
    for (int k = 0; k < 3; ++k) x[3 * c[2] + k] = 0.5 * (x[3 * c[0] + k] + x[3 * c[1] + k]);
  }
  piola_material_def mdef = piola_default_material_def();
  mdef.model = PIOLA_MODEL_NEOHOOKEAN;
  mdef.youngs_modulus = 1e6;
  piola_material material;
  piola_material_init(&mdef, &material);
  piola_shell_body *membrane = make_body(&mesh, &material, 0.0);
  piola_shell_body *full = make_body(&mesh, &material, 1e-5);
  int32_t hinges = piola_shell_body_hinge_count(full);
  printf("sheet: %d triangles, %d hinges, %d vertices; bench_median of %d runs\n\n", (int)nt,
         (int)hinges, (int)n, repeats);
  printf("| measurement | threads | wall ms | triangles/s (wall) | CPU ms | triangles/s per CPU |\n"
         "|---|---|---|---|---|---|\n");
  double *times = malloc(sizeof(double) * (size_t)repeats);
  double *cpu = malloc(sizeof(double) * (size_t)repeats);
  for (int threads = 1; threads <= 2; ++threads) {
    piola_set_thread_count(threads);
    const char *names[3] = {"in-plane forces", "in-plane + bending forces",
                            "damping forces (in-plane + bending)"};
    for (int which = 0; which < 3; ++which) {
      piola_shell_body *body = which == 0 ? membrane : full;
      piola_shell_body_update(body, x, 1.0, f, NULL); /* warm up */
      for (int r = 0; r < repeats; ++r) {
        double t0 = bench_wall_seconds(), c0 = bench_cpu_seconds();
        if (which < 2)
          piola_shell_body_update(body, x, 1.0, f, NULL);
        else
          piola_shell_body_damping_forces(body, v, 0.1, 0.1, f);
        times[r] = bench_wall_seconds() - t0;
        cpu[r] = bench_cpu_seconds() - c0;
      }
      double m = bench_median(times, repeats), mc = bench_median(cpu, repeats);
      printf("| %s | %d | %.2f | %.3g | %.2f | %.3g |\n", names[which], threads, 1e3 * m, nt / m,
             1e3 * mc, nt / mc);
    }
  }

  /* cloth steps */
  cloth c;
  memset(&c, 0, sizeof c);
  c.body = full;
  c.n = n;
  c.x = malloc(sizeof(double) * 3 * (size_t)n);
  c.v = calloc(3 * (size_t)n, sizeof(double));
  c.f = f;
  c.fd = malloc(sizeof(double) * 3 * (size_t)n);
  for (int32_t i = 0; i < n; ++i) {
    c.x[3 * i] = mesh.positions[3 * i];
    c.x[3 * i + 1] = mesh.positions[3 * i + 1];
    c.x[3 * i + 2] = 0.3;
  }
  piola_obstacle_def sphere = piola_default_obstacle_def();
  sphere.type = PIOLA_OBSTACLE_SPHERE;
  sphere.radius = 0.25;
  sphere.friction = 0.3;
  piola_obstacle_def ground = piola_default_obstacle_def();
  ground.type = PIOLA_OBSTACLE_PLANE;
  ground.center = (piola_vec3){0, 0, -0.25};
  ground.axis = (piola_vec3){0, 0, 1};
  piola_obstacle_create(&sphere, &c.obstacles[0]);
  piola_obstacle_create(&ground, &c.obstacles[1]);
  printf("\n| cloth step (100K triangles, sphere + plane) | threads | wall ms/step | steps/s | "
         "CPU ms/step |\n|---|---|---|---|---|\n");
  double t = 0, dt = 2e-5;
  for (int threads = 1; threads <= 2; ++threads) {
    piola_set_thread_count(threads);
    for (int r = 0; r < repeats; ++r) {
      double t0 = bench_wall_seconds(), c0 = bench_cpu_seconds();
      for (int s = 0; s < 5; ++s, t += dt) cloth_step(&c, t, dt);
      times[r] = (bench_wall_seconds() - t0) / 5;
      cpu[r] = (bench_cpu_seconds() - c0) / 5;
    }
    double m = bench_median(times, repeats), mc = bench_median(cpu, repeats);
    printf("| explicit step | %d | %.2f | %.3g | %.2f |\n", threads, 1e3 * m, 1 / m, 1e3 * mc);
  }
  /* world steps: the same cloth, pinned at two corners, over the sphere */
  {
    piola_world_def wdef = piola_default_world_def();
    wdef.max_dt = 1e-3;
    piola_world *world = NULL;
    piola_world_create(&wdef, &world);
    piola_world_add_obstacle(world, &sphere, NULL);
    piola_world_add_obstacle(world, &ground, NULL);
    piola_tri_mesh lifted = mesh;
    lifted.positions = c.x;
    for (int32_t i = 0; i < n; ++i) {
      c.x[3 * i] = mesh.positions[3 * i];
      c.x[3 * i + 1] = mesh.positions[3 * i + 1];
      c.x[3 * i + 2] = 0.3;
    }
    piola_shell_def sdef = piola_default_shell_def();
    sdef.mesh = &lifted;
    sdef.material = mdef;
    sdef.thickness = 5e-4;
    sdef.density = 300;
    sdef.bending.stiffness = 1e-5;
    sdef.bending.damping = 1e-7;
    sdef.shear_viscosity.value = 0.1;
    sdef.bulk_viscosity.value = 0.1;
    if (piola_world_add_shell(world, &sdef, NULL) != PIOLA_OK) {
      fprintf(stderr, "bench_shells: %s\n", piola_last_error());
      return 1;
    }
    printf("\n| world step (100K triangles, Newmark, implicit damping) | threads | wall ms/step | "
           "steps/s | CPU ms/step | dt (s) | CG iterations/step |\n|---|---|---|---|---|---|---|\n");
    for (int threads = 1; threads <= 2; ++threads) {
      piola_set_thread_count(threads);
      int cg = 0, steps = 0;
      double last_dt = 0;
      for (int r = 0; r < repeats; ++r) {
        double t0 = bench_wall_seconds(), c0 = bench_cpu_seconds();
        piola_step_stats st;
        piola_world_step(world, 0, &st);
        times[r] = bench_wall_seconds() - t0;
        cpu[r] = bench_cpu_seconds() - c0;
        cg += st.cg_iterations;
        steps++;
        last_dt = st.last_dt;
      }
      double m = bench_median(times, repeats), mc = bench_median(cpu, repeats);
      printf("| world step | %d | %.1f | %.3g | %.1f | %.2g | %.1f |\n", threads, 1e3 * m, 1 / m,
             1e3 * mc, last_dt, (double)cg / steps);
    }
    piola_world_destroy(world);
  }
  piola_obstacle_destroy(c.obstacles[0]);
  piola_obstacle_destroy(c.obstacles[1]);
  piola_shell_body_destroy(membrane);
  piola_shell_body_destroy(full);
  piola_tri_mesh_free(&mesh);
  free(x);
  free(f);
  free(v);
  free(c.x);
  free(c.v);
  free(c.fd);
  free(times);
  free(cpu);
  return 0;
}
