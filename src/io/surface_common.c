/* Shared steps of the surface readers: welding and final checks. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "io/mesh_io_internal.h"

typedef struct weld_key {
  double x[3];
  int32_t index;
} weld_key;

static int compare_keys(const void *a, const void *b) {
  const weld_key *p = a, *q = b;
  for (int k = 0; k < 3; ++k) {
    if (p->x[k] < q->x[k]) return -1;
    if (p->x[k] > q->x[k]) return 1;
  }
  return (p->index > q->index) - (p->index < q->index);
}

piola_status piola__weld_vertices(piola_tri_mesh *mesh, const char *source) {
  size_t n = (size_t)mesh->vertex_count;
  if (n == 0) return PIOLA_OK;
  weld_key *keys = malloc(n * sizeof(weld_key));
  int32_t *remap = malloc(n * sizeof(int32_t));
  int32_t *renumber = malloc(n * sizeof(int32_t));
  double *positions = malloc(3 * n * sizeof(double));
  if (!keys || !remap || !renumber || !positions) {
    free(keys);
    free(remap);
    free(renumber);
    free(positions);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", source);
  }
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      double v = mesh->positions[3 * i + k];
      keys[i].x[k] = v == 0.0 ? 0.0 : v; /* -0 welds with +0 */
    }
    keys[i].index = (int32_t)i;
  }
  qsort(keys, n, sizeof(weld_key), compare_keys);
  /* Each run of equal coordinates maps to its smallest index (first in the run). */
  for (size_t i = 0; i < n;) {
    size_t j = i + 1;
    while (j < n && memcmp(keys[i].x, keys[j].x, sizeof keys[i].x) == 0) ++j;
    for (size_t k = i; k < j; ++k) remap[keys[k].index] = keys[i].index;
    i = j;
  }
  /* Unique vertices keep the order of their first appearance in the file. */
  int32_t count = 0;
  for (size_t i = 0; i < n; ++i)
    if (remap[i] == (int32_t)i) {
      memcpy(positions + 3 * (size_t)count, mesh->positions + 3 * i, 3 * sizeof(double));
      renumber[i] = count++;
    }
  for (size_t i = 0; i < 3 * (size_t)mesh->triangle_count; ++i) mesh->triangles[i] = renumber[remap[mesh->triangles[i]]];
  free(keys);
  free(remap);
  free(renumber);
  free(mesh->positions);
  mesh->positions = positions;
  mesh->vertex_count = count;
  return PIOLA_OK;
}

piola_status piola__tri_mesh_finish(piola_tri_mesh *mesh, const char *source) {
  if (mesh->triangle_count <= 0) return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: the surface has no triangles", source);
  for (int32_t i = 0; i < 3 * mesh->vertex_count; ++i)
    if (!isfinite(mesh->positions[i]))
      return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: vertex %d has a non-finite coordinate", source, (int)(i / 3));
  for (int32_t i = 0; i < 3 * mesh->triangle_count; ++i)
    if (mesh->triangles[i] < 0 || mesh->triangles[i] >= mesh->vertex_count)
      return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: triangle %d has a vertex index out of range", source, (int)(i / 3));
  return PIOLA_OK;
}
