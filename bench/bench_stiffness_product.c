/* Benchmark of the implicit step's system matrix (force/stiffness_matrix.h): its assembly
 * (the projected stiffness of every tet, the slots, the diagonal blocks) and its product, the
 * operator every CG iteration of a Newton system applies; and the multigrid preconditioner
 * built on it (force/stiffness_multigrid.h): its setup, which backward Euler runs at the
 * first Newton iteration of every step, and one V-cycle, which every CG iteration applies.
 *
 *   build/<dir>/bench_stiffness_product [repeats=7] [mesh] [threads=2] [--default-allocator]
 *
 * Mesh: Vega's torus-easy.veg (97,878 tets) unless another is given, as a neo-Hookean solid
 * (E 1 MPa, nu 0.45, the default inversion handling) at bench_deformed_positions (a few
 * percent of the tets inverted); the matrix is M + dt^2 K at dt = 1/30 s, as backward Euler
 * assembles it. Each repeat times one assembly, 20 products, one multigrid setup (free body: no
 * constraint) and 20 V-cycles. Reports medians over the repeats of process CPU time (all
 * threads) and wall time, the least CPU time seen, and checksums of the last product and
 * V-cycle (equal before and after a change that keeps the bits). Uses
 * only internal functions that older versions have, so an old build runs it for an A/B pair.
 * Freed memory is kept as `piola run` keeps it unless --default-allocator is given
 * (bench_allocator). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "force/elastic_body_internal.h"
#include "force/stiffness_matrix.h"
#include "force/stiffness_multigrid.h"
#include "piola/mesh_io.h"
#include "piola/threads.h"
#include "support/bench_deform.h"
#include "support/bench_support.h"

enum { PRODUCTS = 20 };

int main(int argc, char **argv) {
  bench_allocator(&argc, argv);
  int repeats = argc > 1 ? atoi(argv[1]) : 7;
  const char *path = argc > 2 ? argv[2] : PIOLA_DATA_DIR "/vega/torus-easy.veg";
  const int threads = argc > 3 ? atoi(argv[3]) : 2;
  if (repeats < 1) repeats = 1;
  piola_set_thread_count(threads);
  piola_tet_mesh mesh;
  if (piola_tet_mesh_read(path, &mesh) != PIOLA_OK) {
    fprintf(stderr, "bench_stiffness_product: %s\n", piola_last_error());
    return 1;
  }
  piola_material_def mdef = piola_default_material_def();
  mdef.model = PIOLA_MODEL_NEOHOOKEAN;
  mdef.youngs_modulus = 1e6;
  mdef.poisson_ratio = 0.45;
  piola_material material;
  piola_elastic_body_def def = piola_default_elastic_body_def();
  def.rest_mesh = &mesh;
  def.materials = &material;
  def.material_count = 1;
  piola_elastic_body *body = NULL;
  if (piola_material_init(&mdef, &material) != PIOLA_OK ||
      piola_elastic_body_create(&def, &body) != PIOLA_OK) {
    fprintf(stderr, "bench_stiffness_product: %s\n", piola_last_error());
    return 1;
  }
  const size_t n = 3 * (size_t)mesh.vertex_count;
  double *x = bench_deformed_positions(body);
  double *f = malloc(sizeof(double) * n), *p = malloc(sizeof(double) * n);
  double *out = malloc(sizeof(double) * n);
  for (size_t j = 0; j < n; ++j) p[j] = bench_uniform(-1, 1);
  piola__stiffness_matrix m;
  piola__multigrid mg;
  if (piola_elastic_body_update(body, x, 1.0, f, NULL) != PIOLA_OK ||
      piola__stiffness_matrix_init(&m, body) != PIOLA_OK ||
      piola__multigrid_init(&mg, body) != PIOLA_OK) {
    fprintf(stderr, "bench_stiffness_product: %s\n", piola_last_error());
    return 1;
  }
  const double dt = 1.0 / 30;
  enum { PHASES = 4 };
  double *cpu[PHASES], *wall[PHASES]; /* assembly, product, multigrid setup, V-cycle */
  for (int k = 0; k < PHASES; ++k) {
    cpu[k] = malloc(sizeof(double) * (size_t)repeats);
    wall[k] = malloc(sizeof(double) * (size_t)repeats);
  }
  for (int r = 0; r < repeats; ++r) {
    double w0 = bench_wall_seconds(), c0 = bench_cpu_seconds();
    piola__stiffness_matrix_assemble(&m, body, dt * dt, 0.0, body->masses, 1.0);
    wall[0][r] = bench_wall_seconds() - w0, cpu[0][r] = bench_cpu_seconds() - c0;
    w0 = bench_wall_seconds(), c0 = bench_cpu_seconds();
    for (int q = 0; q < PRODUCTS; ++q)
      piola__stiffness_matrix_apply(&m, body, body->masses, 1.0, p, out);
    wall[1][r] = (bench_wall_seconds() - w0) / PRODUCTS;
    cpu[1][r] = (bench_cpu_seconds() - c0) / PRODUCTS;
    w0 = bench_wall_seconds(), c0 = bench_cpu_seconds();
    if (piola__multigrid_setup(&mg, &m, body, NULL, NULL) != PIOLA_OK) {
      fprintf(stderr, "bench_stiffness_product: %s\n", piola_last_error());
      return 1;
    }
    wall[2][r] = bench_wall_seconds() - w0, cpu[2][r] = bench_cpu_seconds() - c0;
    w0 = bench_wall_seconds(), c0 = bench_cpu_seconds();
    for (int q = 0; q < PRODUCTS; ++q) piola__multigrid_apply(&mg, body, p, f);
    wall[3][r] = (bench_wall_seconds() - w0) / PRODUCTS;
    cpu[3][r] = (bench_cpu_seconds() - c0) / PRODUCTS;
  }
  double checksum = 0, cycle_checksum = 0;
  for (size_t j = 0; j < n; ++j) checksum += fabs(out[j]), cycle_checksum += fabs(f[j]);
  printf("bench_stiffness_product: %s, %d vertices, %d tets, %d edges, %d threads\n", path,
         (int)mesh.vertex_count, (int)mesh.tet_count, (int)body->damping.edge_count, threads);
  printf("multigrid: %d levels\n", mg.level_count);
  static const char *const NAMES[PHASES] = {"assembly", "product", "multigrid setup", "V-cycle"};
  printf("%16s %14s %14s %14s\n", "", "CPU ms", "min CPU ms", "wall ms");
  for (int k = 0; k < PHASES; ++k) {
    const double c = bench_median(cpu[k], repeats); /* sorts: cpu[k][0] is the least */
    printf("%16s %14.3f %14.3f %14.3f\n", NAMES[k], 1e3 * c, 1e3 * cpu[k][0],
           1e3 * bench_median(wall[k], repeats));
  }
  printf("checksum of the product: %.17g\n", checksum);
  printf("checksum of the V-cycle: %.17g\n", cycle_checksum);
  for (int k = 0; k < PHASES; ++k) free(cpu[k]), free(wall[k]);
  piola__multigrid_free(&mg);
  piola__stiffness_matrix_free(&m);
  free(x), free(f), free(p), free(out);
  piola_elastic_body_destroy(body);
  piola_tet_mesh_free(&mesh);
  return 0;
}
