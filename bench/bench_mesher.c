/* Benchmark of the built-in mesher: a sphere and the bunny surface at resolutions giving
 * about a million tets or more. Prints tets, seconds (median of 3 runs), tets per second
 * (wall clock), the CPU seconds of all threads (median), and the extreme dihedral angles.
 *
 *   build/bench/bench_mesher [runs]        (PIOLA_DATA_DIR locates the bunny) */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "piola/mesher.h"

static double now(void) { return omp_get_wtime(); }

static int compare_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : (x > y);
}

/* Only v and f lines (f a/b/c forms accepted); enough for the bunny. */
static int read_obj(const char *path, piola_tri_mesh *m) {
  FILE *f = fopen(path, "r");
  if (!f) return 0;
  memset(m, 0, sizeof(*m));
  size_t vcap = 1024, tcap = 1024;
  m->positions = malloc(3 * sizeof(double) * vcap);
  m->triangles = malloc(3 * sizeof(int32_t) * tcap);
  char line[1024];
  while (fgets(line, sizeof line, f)) {
    if (line[0] == 'v' && line[1] == ' ') {
      if ((size_t)m->vertex_count == vcap) m->positions = realloc(m->positions, 3 * sizeof(double) * (vcap *= 2));
      double *p = m->positions + 3 * (size_t)m->vertex_count++;
      if (sscanf(line + 2, "%lf %lf %lf", &p[0], &p[1], &p[2]) != 3) return 0;
    } else if (line[0] == 'f' && line[1] == ' ') {
      long a, b, c;
      char *s = line + 2;
      a = strtol(s, &s, 10);
      while (*s && *s != ' ') ++s;
      b = strtol(s, &s, 10);
      while (*s && *s != ' ') ++s;
      c = strtol(s, &s, 10);
      if ((size_t)m->triangle_count == tcap) m->triangles = realloc(m->triangles, 3 * sizeof(int32_t) * (tcap *= 2));
      int32_t *t = m->triangles + 3 * (size_t)m->triangle_count++;
      t[0] = (int32_t)a - 1;
      t[1] = (int32_t)b - 1;
      t[2] = (int32_t)c - 1;
    }
  }
  fclose(f);
  return 1;
}

static void dihedral_range(const piola_tet_mesh *m, double *lo, double *hi) {
  static const int face_of[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  *lo = 180;
  *hi = 0;
  for (int32_t t = 0; t < m->tet_count; ++t) {
    double x[4][3], n[4][3];
    for (int k = 0; k < 4; ++k) memcpy(x[k], m->positions + 3 * (size_t)m->tets[4 * t + k], sizeof x[k]);
    for (int f = 0; f < 4; ++f) {
      const double *a = x[face_of[f][0]], *b = x[face_of[f][1]], *c = x[face_of[f][2]];
      double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      double w[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
      double l = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
      for (int i = 0; i < 3; ++i) n[f][i] = w[i] / l;
    }
    for (int f = 0; f < 4; ++f)
      for (int g = f + 1; g < 4; ++g) {
        double c = -(n[f][0] * n[g][0] + n[f][1] * n[g][1] + n[f][2] * n[g][2]);
        double a = acos(fmax(-1, fmin(1, c))) * 180 / M_PI;
        *lo = fmin(*lo, a);
        *hi = fmax(*hi, a);
      }
  }
}

static void run(const char *name, const piola_mesher_def *def, int runs) {
  double times[16], cpu[16];
  piola_tet_mesh mesh = {0};
  for (int r = 0; r < runs; ++r) {
    free(mesh.positions);
    free(mesh.tets);
    double t0 = now();
    clock_t c0 = clock();
    if (piola_mesher_generate(def, &mesh) != PIOLA_OK) {
      printf("%s: failed: %s\n", name, piola_last_error());
      return;
    }
    times[r] = now() - t0;
    cpu[r] = (double)(clock() - c0) / CLOCKS_PER_SEC;
  }
  qsort(times, (size_t)runs, sizeof(double), compare_double);
  qsort(cpu, (size_t)runs, sizeof(double), compare_double);
  double median = times[runs / 2], lo, hi;
  dihedral_range(&mesh, &lo, &hi);
  printf("| %-28s | %9d | %7.3f | %7.3f | %9.0f | %7.2f | %7.2f |\n", name, (int)mesh.tet_count,
         median, cpu[runs / 2], mesh.tet_count / median, lo, hi);
  free(mesh.positions);
  free(mesh.tets);
}

int main(int argc, char **argv) {
  int runs = argc > 1 ? atoi(argv[1]) : 3;
  if (runs < 1 || runs > 16) runs = 3;
  printf("threads: %d, runs: %d (median)\n", omp_get_max_threads(), runs);
  printf("| %-28s | %9s | %7s | %7s | %9s | %7s | %7s |\n", "case", "tets", "wall s", "cpu s",
         "tets/s", "min deg", "max deg");
  printf("|------------------------------|-----------|---------|---------|-----------|---------|---------|\n");
  piola_mesher_def def = piola_default_mesher_def();
  def.shapes[0].type = PIOLA_SHAPE_SPHERE;
  def.shapes[0].center = (piola_vec3){0, 0, 0};
  def.shapes[0].radius = 1.0;
  def.shape_count = 1;
  def.cell_size = 0.036;
  run("sphere r=1 h=0.036", &def, runs);
  def.cell_size = 0.09;
  def.refinement_levels = 1;
  run("sphere r=1 h=0.09 refine=1", &def, runs);
  def.refinement_levels = 0;
  piola_tri_mesh bunny;
  char path[4096];
  snprintf(path, sizeof path, "%s/surface/bunny_10k.obj", PIOLA_DATA_DIR);
  if (read_obj(path, &bunny)) {
    def.shapes[0].type = PIOLA_SHAPE_SURFACE;
    def.shapes[0].surface = &bunny;
    def.cell_size = 0.0115;
    run("bunny_10k.obj h=0.0115", &def, runs);
    free(bunny.positions);
    free(bunny.triangles);
  } else {
    printf("(bunny not found at %s)\n", path);
  }
  return 0;
}
