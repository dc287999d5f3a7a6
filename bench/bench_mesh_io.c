/* Mesh file throughput: read and write MB/s for a generated structured tet mesh.
 *
 * usage: bench_mesh_io [cells_per_side (default 56 -> 1,053,696 tets)] [runs (default 5)]
 * The grid's vertices are jittered so coordinates carry full-length decimals like real
 * meshes. Formats: Gmsh 4.1 ASCII (.msh), TetGen (.node + .ele), Gmsh 4.1 binary (written
 * by this program, read by piola) and VTU (written by piola). Prints medians. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "piola/mesh.h"
#include "piola/mesh_io.h"
#include "support/bench_support.h"

/* CPU time of this process: less disturbed than wall time on a shared machine. */
static double file_size(const char *path) {
  struct stat st;
  return stat(path, &st) == 0 ? (double)st.st_size : 0.0;
}

/* n^3 cubes, each split into 6 tets around its main diagonal (conforming across cubes). */
static void make_grid(int n, piola_tet_mesh *m) {
  int p = n + 1;
  m->vertex_count = p * p * p;
  m->tet_count = 6 * n * n * n;
  m->positions = malloc(3 * (size_t)m->vertex_count * sizeof(double));
  m->tets = malloc(4 * (size_t)m->tet_count * sizeof(int32_t));
  m->tet_regions = malloc((size_t)m->tet_count * sizeof(int32_t));
  uint64_t state = 88172645463325252ull;
  double h = 1.0 / n;
  for (int k = 0; k < p; ++k)
    for (int j = 0; j < p; ++j)
      for (int i = 0; i < p; ++i) {
        double *x = m->positions + 3 * ((size_t)(k * p + j) * p + i);
        double c[3] = {i * h, j * h, k * h};
        for (int d = 0; d < 3; ++d) {
          state ^= state << 13;
          state ^= state >> 7;
          state ^= state << 17;
          double r = (double)(state >> 11) / 9007199254740992.0 - 0.5;
          x[d] = c[d] + 0.1 * h * r;
        }
      }
  static const int paths[6][3] = {{1, 2, 4}, {1, 4, 2}, {2, 1, 4}, {2, 4, 1}, {4, 1, 2}, {4, 2, 1}};
  size_t t = 0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        int32_t corner[8];
        for (int c = 0; c < 8; ++c)
          corner[c] = (int32_t)(((size_t)(k + ((c >> 2) & 1)) * p + (j + ((c >> 1) & 1))) * p + (i + (c & 1)));
        for (int s = 0; s < 6; ++s) {
          int a = 0, b = paths[s][0], c2 = b | paths[s][1], d = 7;
          int32_t *q = m->tets + 4 * t;
          q[0] = corner[a];
          q[1] = corner[b];
          q[2] = corner[c2];
          q[3] = corner[d];
          m->tet_regions[t] = 1 + (i >= n / 2);
          ++t;
        }
      }
  piola_tet_mesh_orient(m);
}

/* Gmsh 4.1 binary, written here so the reader can be timed on binary input. */
static int write_msh_binary(const char *path, const piola_tet_mesh *m) {
  FILE *f = fopen(path, "wb");
  if (!f) return -1;
  int one = 1;
  fprintf(f, "$MeshFormat\n4.1 1 8\n");
  fwrite(&one, 4, 1, f);
  fprintf(f, "\n$EndMeshFormat\n$Nodes\n");
  uint64_t nv = (uint64_t)m->vertex_count, nt = (uint64_t)m->tet_count;
  uint64_t head[4] = {1, nv, 1, nv};
  fwrite(head, 8, 4, f);
  int32_t block[3] = {3, 1, 0};
  fwrite(block, 4, 3, f);
  fwrite(&nv, 8, 1, f);
  for (uint64_t v = 1; v <= nv; ++v) fwrite(&v, 8, 1, f);
  fwrite(m->positions, 8, 3 * nv, f);
  fprintf(f, "\n$EndNodes\n$Elements\n");
  uint64_t ehead[4] = {1, nt, 1, nt};
  fwrite(ehead, 8, 4, f);
  int32_t eblock[3] = {3, 1, 4};
  fwrite(eblock, 4, 3, f);
  fwrite(&nt, 8, 1, f);
  for (uint64_t t = 0; t < nt; ++t) {
    uint64_t rec[5] = {t + 1, (uint64_t)m->tets[4 * t] + 1, (uint64_t)m->tets[4 * t + 1] + 1,
                       (uint64_t)m->tets[4 * t + 2] + 1, (uint64_t)m->tets[4 * t + 3] + 1};
    fwrite(rec, 8, 5, f);
  }
  fprintf(f, "\n$EndElements\n");
  return fclose(f) == 0 ? 0 : -1;
}

typedef struct row {
  const char *name;
  const char *path;   /* file written/read */
  const char *extra;  /* second file whose size counts (TetGen .ele) or NULL */
  int write_with_piola;
  int read_with_piola;
} row;

int main(int argc, char **argv) {
  int n = argc > 1 ? atoi(argv[1]) : 56;
  int runs = argc > 2 ? atoi(argv[2]) : 5;
  if (n < 1 || runs < 1) {
    fprintf(stderr, "usage: bench_mesh_io [cells_per_side] [runs]\n");
    return 2;
  }
  char dir[] = "/tmp/piola_bench_io_XXXXXX";
  if (!mkdtemp(dir)) return 1;
  piola_tet_mesh mesh = {0};
  make_grid(n, &mesh);
  printf("mesh: %d vertices, %d tets (structured %d^3 grid, 6 tets per cube), %d runs, bench_median\n",
         (int)mesh.vertex_count, (int)mesh.tet_count, n, runs);
  char msh[256], node[256], ele[256], bin[256], vtu[256];
  snprintf(msh, sizeof msh, "%s/grid.msh", dir);
  snprintf(node, sizeof node, "%s/grid.node", dir);
  snprintf(ele, sizeof ele, "%s/grid.ele", dir);
  snprintf(bin, sizeof bin, "%s/grid_bin.msh", dir);
  snprintf(vtu, sizeof vtu, "%s/grid.vtu", dir);
  row rows[] = {
      {"Gmsh 4.1 ASCII (.msh)", msh, NULL, 1, 1},
      {"TetGen (.node + .ele)", node, ele, 1, 1},
      {"Gmsh 4.1 binary (.msh)", bin, NULL, 0, 1},
      {"VTU appended raw (.vtu)", vtu, NULL, 1, 0},
  };
  printf("%-26s %8s %9s %10s %11s %9s %10s %11s\n", "format", "size MB", "write s", "write MB/s",
         "w. cpu MB/s", "read s", "read MB/s", "r. cpu MB/s");
  int status = 0;
  double *times = malloc((size_t)runs * sizeof(double));
  double *cpu = malloc((size_t)runs * sizeof(double));
  for (size_t r = 0; r < sizeof rows / sizeof rows[0]; ++r) {
    double wt = 0, wc = 0, rt = 0, rc = 0;
    if (rows[r].write_with_piola) {
      for (int i = 0; i < runs; ++i) {
        double t0 = bench_wall_seconds(), c0 = bench_cpu_seconds();
        if (piola_tet_mesh_write(rows[r].path, &mesh) != PIOLA_OK) {
          fprintf(stderr, "%s\n", piola_last_error());
          status = 1;
        }
        times[i] = bench_wall_seconds() - t0;
        cpu[i] = bench_cpu_seconds() - c0;
      }
      wt = bench_median(times, runs);
      wc = bench_median(cpu, runs);
    } else if (write_msh_binary(rows[r].path, &mesh) != 0) {
      status = 1;
    }
    double size = file_size(rows[r].path) + (rows[r].extra ? file_size(rows[r].extra) : 0);
    if (rows[r].read_with_piola) {
      for (int i = 0; i < runs; ++i) {
        piola_tet_mesh back;
        double t0 = bench_wall_seconds(), c0 = bench_cpu_seconds();
        if (piola_tet_mesh_read(rows[r].path, &back) != PIOLA_OK) {
          fprintf(stderr, "%s\n", piola_last_error());
          status = 1;
        }
        times[i] = bench_wall_seconds() - t0;
        cpu[i] = bench_cpu_seconds() - c0;
        if (back.tet_count != mesh.tet_count) status = 1;
        piola_tet_mesh_free(&back);
      }
      rt = bench_median(times, runs);
      rc = bench_median(cpu, runs);
    }
    double mb = size / 1e6;
    printf("%-26s %8.1f ", rows[r].name, mb);
    if (wt > 0) printf("%9.3f %10.1f %11.1f ", wt, mb / wt, mb / wc);
    else printf("%9s %10s %11s ", "-", "-", "-");
    if (rt > 0) printf("%9.3f %10.1f %11.1f\n", rt, mb / rt, mb / rc);
    else printf("%9s %10s %11s\n", "-", "-", "-");
    unlink(rows[r].path);
    if (rows[r].extra) unlink(rows[r].extra);
  }
  free(times);
  free(cpu);
  piola_tet_mesh_free(&mesh);
  rmdir(dir);
  return status;
}
