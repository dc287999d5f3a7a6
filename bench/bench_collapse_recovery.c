/* Whether bodies of real meshes recover from collapse to a point, a line and a plane, per
 * model and inversion extension: the collapse half of docs/materials.md "Defaults that
 * recover". Not a timing benchmark.
 *
 * Protocol (tests/support/recovery_runs.c): each mesh of ../shared/data scaled to a 1 m
 * bounding box, E = 10 kPa, nu = 0.3, 1000 kg/m^3 (models with their own moduli scaled to the
 * same rest shear modulus; fibres along x), every vertex moved to one point, onto a line or
 * onto a plane, then 12 s of elastic and damping forces (beta = 1000, alpha = 300 Pa s),
 * symplectic Euler at half the simulator's state-aware step bound and at most 1 / (1.1 c_max),
 * c_max the largest damping rate of M^-1 D (recovery_runs.c). Recovered: within 1e-3 m of the
 * rest shape after the best rigid alignment, every Fhat entry within 1e-3 of 1, nothing
 * inverted.
 *
 * usage: bench_collapse_recovery model mode|default threshold|default [mesh ...]
 *        (meshes relative to ../shared/data; default: the small real meshes below) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "support/bench_support.h"
#include "support/recovery_runs.h"
#include "piola/threads.h"

int main(int argc, char **argv) {
  static const char *default_meshes[] = {"gmsh/msh_tetra.msh", "gmsh/bar-186.msh",
                                         "gmsh/torus.msh", "medit/unit_ball.mesh",
                                         "tetgen/octahedron.node"};
  if (argc < 4) {
    fprintf(stderr, "usage: bench_collapse_recovery model mode|default threshold|default [mesh ...]\n");
    return 2;
  }
  piola_material_model model;
  if (!piola_material_model_from_name(argv[1], &model)) {
    fprintf(stderr, "bench_collapse_recovery: unknown model '%s'\n", argv[1]);
    return 1;
  }
  piola_material_def def = recovery_material_def(model);
  if (strcmp(argv[2], "default") != 0 && !piola_inversion_mode_from_name(argv[2], &def.inversion_mode)) {
    fprintf(stderr, "bench_collapse_recovery: unknown inversion mode '%s'\n", argv[2]);
    return 1;
  }
  if (strcmp(argv[3], "default") != 0) def.inversion_threshold = atof(argv[3]);
  piola_material material;
  if (piola_material_init(&def, &material) != PIOLA_OK) {
    fprintf(stderr, "bench_collapse_recovery: %s\n", piola_last_error());
    return 1;
  }
  piola_set_thread_count(1);
  const int mesh_count = argc > 4 ? argc - 4 : (int)(sizeof default_meshes / sizeof *default_meshes);
  printf("| model | extension | threshold | mesh | tets | start | result | position error m | max abs(fhat - 1) | steps | wall s |\n");
  printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  int failures = 0;
  for (int k = 0; k < mesh_count; ++k) {
    const char *name = argc > 4 ? argv[4 + k] : default_meshes[k];
    piola_tet_mesh mesh;
    if (recovery_read_unit_mesh(PIOLA_DATA_DIR, name, &mesh) != 0) {
      fprintf(stderr, "bench_collapse_recovery: %s: %s\n", name, piola_last_error());
      return 1;
    }
    for (int kind = COLLAPSE_TO_POINT; kind <= COLLAPSE_TO_PLANE; ++kind) {
      const double t0 = bench_wall_seconds();
      const recovery_collapse_outcome o =
          recovery_collapse_run(&mesh, &material, (recovery_collapse_kind)kind);
      failures += o.result != RECOVERY_RECOVERED;
      printf("| %s | %s | %.2g | %s | %d | %s | %s | %.2g | %.2g | %d | %.1f |\n",
             piola_material_model_name(material.model),
             piola_inversion_mode_name(material.inversion_mode), material.threshold, name,
             (int)mesh.tet_count, recovery_collapse_names[kind], recovery_result_names[o.result],
             o.position_error, o.fhat_error, o.steps, bench_wall_seconds() - t0);
      fflush(stdout);
    }
    piola_tet_mesh_free(&mesh);
  }
  printf("not recovered: %d of %d\n", failures, 3 * mesh_count);
  return 0;
}
