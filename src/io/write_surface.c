/* Surface writers: OBJ, OFF and binary STL. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "io/mesh_writers.h"
#include "piola/files.h"

piola_status piola__tri_mesh_compact(piola_tri_mesh *mesh) {
  size_t n = (size_t)mesh->vertex_count;
  int32_t *renumber = malloc(n * sizeof(int32_t) + 1);
  if (!renumber) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "out of memory");
  for (size_t i = 0; i < n; ++i) renumber[i] = -1;
  for (size_t i = 0; i < 3 * (size_t)mesh->triangle_count; ++i) renumber[mesh->triangles[i]] = 0;
  int32_t count = 0;
  for (size_t i = 0; i < n; ++i)
    if (renumber[i] == 0) {
      memmove(mesh->positions + 3 * (size_t)count, mesh->positions + 3 * i, 3 * sizeof(double));
      renumber[i] = count++;
    }
  for (size_t i = 0; i < 3 * (size_t)mesh->triangle_count; ++i) mesh->triangles[i] = renumber[mesh->triangles[i]];
  mesh->vertex_count = count;
  free(renumber);
  return PIOLA_OK;
}

/* The vertices as lines "<prefix><x> <y> <z>", then the triangles as "<prefix> <i> <j> <k>"
 * with the indices counted from base: OBJ and OFF differ only in these. */
static void write_lines(FILE *stream, const piola_tri_mesh *mesh, const char *vertex_prefix,
                        const char *face_prefix, int base) {
  char a[32], b[32], c[32];
  for (int32_t v = 0; v < mesh->vertex_count; ++v) {
    piola__format_double(a, mesh->positions[3 * v]);
    piola__format_double(b, mesh->positions[3 * v + 1]);
    piola__format_double(c, mesh->positions[3 * v + 2]);
    fprintf(stream, "%s%s %s %s\n", vertex_prefix, a, b, c);
  }
  for (int32_t t = 0; t < mesh->triangle_count; ++t) {
    const int32_t *q = mesh->triangles + 3 * (size_t)t;
    fprintf(stream, "%s %d %d %d\n", face_prefix, q[0] + base, q[1] + base, q[2] + base);
  }
}

piola_status piola__write_obj(const char *path, const piola_tri_mesh *mesh) {
  piola_atomic_file f;
  PIOLA_TRY(piola_atomic_file_open(&f, path));
  fprintf(f.stream, "# written by piola: %d vertices, %d triangles\n", (int)mesh->vertex_count,
          (int)mesh->triangle_count);
  write_lines(f.stream, mesh, "v ", "f", 1); /* OBJ counts from 1 */
  return piola_atomic_file_commit(&f);
}

piola_status piola__write_off(const char *path, const piola_tri_mesh *mesh) {
  piola_atomic_file f;
  PIOLA_TRY(piola_atomic_file_open(&f, path));
  fprintf(f.stream, "OFF\n%d %d 0\n", (int)mesh->vertex_count, (int)mesh->triangle_count);
  write_lines(f.stream, mesh, "", "3", 0);
  return piola_atomic_file_commit(&f);
}

/* Binary STL stores float32: coordinates are rounded to single precision. */
piola_status piola__write_stl(const char *path, const piola_tri_mesh *mesh) {
  piola_atomic_file f;
  PIOLA_TRY(piola_atomic_file_open(&f, path));
  unsigned char header[84];
  memset(header, 0, sizeof header);
  memcpy(header, "binary STL written by piola", 27);
  uint32_t n = (uint32_t)mesh->triangle_count;
  memcpy(header + 80, &n, 4);
  fwrite(header, 1, sizeof header, f.stream);
  for (int32_t t = 0; t < mesh->triangle_count; ++t) {
    const int32_t *q = mesh->triangles + 3 * (size_t)t;
    const double *p0 = mesh->positions + 3 * (size_t)q[0], *p1 = mesh->positions + 3 * (size_t)q[1],
                 *p2 = mesh->positions + 3 * (size_t)q[2];
    double e1[3], e2[3], nrm[3];
    for (int k = 0; k < 3; ++k) {
      e1[k] = p1[k] - p0[k];
      e2[k] = p2[k] - p0[k];
    }
    nrm[0] = e1[1] * e2[2] - e1[2] * e2[1];
    nrm[1] = e1[2] * e2[0] - e1[0] * e2[2];
    nrm[2] = e1[0] * e2[1] - e1[1] * e2[0];
    double len = nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2];
    len = len > 0 ? 1.0 / __builtin_sqrt(len) : 0.0;
    unsigned char rec[50];
    float v[12];
    for (int k = 0; k < 3; ++k) {
      v[k] = (float)(nrm[k] * len);
      v[3 + k] = (float)p0[k];
      v[6 + k] = (float)p1[k];
      v[9 + k] = (float)p2[k];
    }
    memcpy(rec, v, 48);
    rec[48] = rec[49] = 0;
    fwrite(rec, 1, 50, f.stream);
  }
  return piola_atomic_file_commit(&f);
}
