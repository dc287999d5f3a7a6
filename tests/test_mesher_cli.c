/* `piola mesh generate` end to end: the written file reads back as a valid mesh of the
 * right volume, surfaces are read from files, and bad input is refused with exit code 2 and
 * a message naming the problem. */
#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "piola/mesh.h"
#include "piola/mesh_io.h"

static char tmpdir[256];

static int setup(void **state) {
  (void)state;
  return test_make_scratch_folder(tmpdir, sizeof tmpdir, "piola_mesher_cli");
}

static int teardown(void **state) {
  (void)state;
  return test_remove_scratch_folder(tmpdir);
}

/* Runs the CLI with arguments; stderr goes to tmpdir/err.txt. Returns the exit code. */
static int run_cli(const char *args) {
  char cmd[2048];
  snprintf(cmd, sizeof cmd, "'%s' mesh generate %s > '%s/out.txt' 2> '%s/err.txt'", PIOLA_CLI_PATH, args,
           tmpdir, tmpdir);
  int status = system(cmd);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

static const char *error_text(void) {
  static char buf[4096];
  char path[512];
  snprintf(path, sizeof path, "%s/err.txt", tmpdir);
  FILE *f = fopen(path, "r");
  size_t n = f ? fread(buf, 1, sizeof buf - 1, f) : 0;
  buf[n] = '\0';
  if (f) fclose(f);
  return buf;
}

static double mesh_volume(const piola_tet_mesh *m, double *min_volume) {
  double total = 0;
  *min_volume = INFINITY;
  for (int32_t t = 0; t < m->tet_count; ++t) {
    double v = piola_tet_mesh_signed_volume(m, t);
    total += v;
    *min_volume = fmin(*min_volume, v);
  }
  return total;
}

static void sphere_is_written_and_reads_back(void **state) {
  (void)state;
  char args[1024], path[512];
  snprintf(path, sizeof path, "%s/ball.msh", tmpdir);
  snprintf(args, sizeof args, "sphere --radius 0.5 --center 1,2,3 --cell-size 0.05 -o '%s'", path);
  assert_int_equal(run_cli(args), 0);
  piola_tet_mesh m;
  assert_int_equal(piola_tet_mesh_read(path, &m), PIOLA_OK);
  double min_volume, volume = mesh_volume(&m, &min_volume);
  double exact = 4.0 / 3.0 * M_PI * 0.125;
  assert_true(min_volume > 0);
  assert_true(fabs(volume - exact) < 0.01 * exact);
  /* Centred where asked. */
  double c[3] = {0, 0, 0};
  for (int32_t v = 0; v < m.vertex_count; ++v)
    for (int k = 0; k < 3; ++k) c[k] += m.positions[3 * v + k] / m.vertex_count;
  assert_close(c[0], 1, 0.02);
  assert_close(c[1], 2, 0.02);
  assert_close(c[2], 3, 0.02);
  piola_tet_mesh_free(&m);
}

static void torus_with_refinement_is_written(void **state) {
  (void)state;
  char args[1024], path[512];
  snprintf(path, sizeof path, "%s/ring.vtu", tmpdir);
  snprintf(args, sizeof args,
           "torus --radius 1 --minor-radius 0.35 --axis 1,0,0 --cell-size 0.2 --refine 1 -o '%s'", path);
  assert_int_equal(run_cli(args), 0);
  snprintf(path, sizeof path, "%s/ring.msh", tmpdir);
  snprintf(args, sizeof args,
           "torus --radius 1 --minor-radius 0.35 --axis 1,0,0 --cell-size 0.2 --refine 1 -o '%s'", path);
  assert_int_equal(run_cli(args), 0);
  piola_tet_mesh m;
  assert_int_equal(piola_tet_mesh_read(path, &m), PIOLA_OK);
  double min_volume, volume = mesh_volume(&m, &min_volume);
  double exact = 2 * M_PI * M_PI * 1.0 * 0.35 * 0.35;
  assert_true(min_volume > 0);
  assert_true(fabs(volume - exact) < 0.01 * exact);
  piola_tri_mesh b;
  assert_int_equal(piola_tet_mesh_boundary(&m, &b), PIOLA_OK);
  /* Torus: Euler characteristic V - E + F = 0, with E = 3F/2 on a closed surface. */
  int32_t used = 0;
  char *seen = calloc((size_t)m.vertex_count, 1);
  for (int32_t i = 0; i < b.triangle_count * 3; ++i)
    if (!seen[b.triangles[i]]) {
      seen[b.triangles[i]] = 1;
      used++;
    }
  free(seen);
  assert_int_equal(used - b.triangle_count * 3 / 2 + b.triangle_count, 0);
  piola_tri_mesh_free(&b);
  piola_tet_mesh_free(&m);
}

static void surface_file_is_meshed(void **state) {
  (void)state;
  char args[1024], path[512];
  snprintf(path, sizeof path, "%s/sphere_surface.mesh", tmpdir);
  snprintf(args, sizeof args, "'%s' --cell-size 0.125 -o '%s'", test_data_path("surface/sphere.obj"), path);
  assert_int_equal(run_cli(args), 0);
  piola_tet_mesh m;
  assert_int_equal(piola_tet_mesh_read(path, &m), PIOLA_OK);
  double min_volume, volume = mesh_volume(&m, &min_volume);
  assert_true(min_volume > 0);
  assert_true(fabs(volume - 4.09487) < 0.01 * 4.09487); /* the OBJ's enclosed volume */
  piola_tet_mesh_free(&m);
}

static void bad_input_is_refused(void **state) {
  (void)state;
  char args[1024], path[512];
  /* An open surface: a tetrahedron missing its face (2, 3, 4) (1-based in the file). */
  snprintf(path, sizeof path, "%s/open.obj", tmpdir);
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  fprintf(f, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n");
  fclose(f);
  snprintf(args, sizeof args, "'%s' -o '%s/x.msh'", path, tmpdir);
  assert_int_equal(run_cli(args), 2);
  assert_non_null(strstr(error_text(), "open"));
  assert_non_null(strstr(error_text(), "edge ("));
  snprintf(args, sizeof args, "cube -o '%s/x.msh'", tmpdir);
  assert_int_equal(run_cli(args), 2);
  snprintf(args, sizeof args, "sphere --radius -1 -o '%s/x.msh'", tmpdir);
  assert_int_equal(run_cli(args), 2);
  assert_non_null(strstr(error_text(), "radius"));
  snprintf(args, sizeof args, "sphere --center 1,2 -o '%s/x.msh'", tmpdir);
  assert_int_equal(run_cli(args), 2);
  assert_non_null(strstr(error_text(), "--center"));
  assert_int_equal(run_cli("sphere"), 2);
  snprintf(args, sizeof args, "sphere --frobnicate -o '%s/x.msh'", tmpdir);
  assert_int_equal(run_cli(args), 2);
  assert_int_equal(run_cli("--help"), 0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(sphere_is_written_and_reads_back),
      cmocka_unit_test(torus_with_refinement_is_written),
      cmocka_unit_test(surface_file_is_meshed),
      cmocka_unit_test(bad_input_is_refused),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
