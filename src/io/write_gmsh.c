/* Gmsh 4.1 ASCII writer.
 *
 * One volume entity per distinct region id, carrying that id as its physical group (ids <= 0
 * cannot be physical tags in Gmsh: such entities get none). Nodes in one block with tags
 * 1..N. Elements in blocks of consecutive tets with the same region, so reading the file
 * back gives the tets in their original order. Fibres (tet_fibers) follow as an
 * $ElementData view named "fiber" with 3 components, written to read back exactly. */
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "io/mesh_writers.h"
#include "io/text_writer.h"
#include "piola/files.h"

static int cmp_int32(const void *a, const void *b) {
  int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
  return (x > y) - (x < y);
}

piola_status piola__write_gmsh41(const char *path, const piola_tet_mesh *mesh) {
  size_t nt = (size_t)mesh->tet_count, nv = (size_t)mesh->vertex_count;
  int32_t *ids = malloc((nt + 1) * sizeof(int32_t));
  if (!ids) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
  for (size_t t = 0; t < nt; ++t) ids[t] = mesh->tet_regions ? mesh->tet_regions[t] : 0;
  qsort(ids, nt, sizeof(int32_t), cmp_int32);
  size_t regions = 0;
  for (size_t t = 0; t < nt; ++t)
    if (t == 0 || ids[t] != ids[t - 1]) ids[regions++] = ids[t];
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  for (size_t v = 0; v < nv; ++v)
    for (int k = 0; k < 3; ++k) {
      double x = mesh->positions[3 * v + k];
      if (v == 0 || x < lo[k]) lo[k] = x;
      if (v == 0 || x > hi[k]) hi[k] = x;
    }
  piola_atomic_file f;
  piola_status s = piola_atomic_file_open(&f, path);
  if (s != PIOLA_OK) {
    free(ids);
    return s;
  }
  FILE *o = f.stream;
  fprintf(o, "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n");
  fprintf(o, "$Entities\n0 0 0 %zu\n", regions);
  for (size_t r = 0; r < regions; ++r) {
    char box[6][32];
    for (int k = 0; k < 3; ++k) {
      piola__format_double(box[k], lo[k]);
      piola__format_double(box[3 + k], hi[k]);
    }
    fprintf(o, "%zu %s %s %s %s %s %s", r + 1, box[0], box[1], box[2], box[3], box[4], box[5]);
    if (ids[r] > 0) fprintf(o, " 1 %d 0\n", (int)ids[r]);
    else fprintf(o, " 0 0\n");
  }
  fprintf(o, "$EndEntities\n");
  fprintf(o, "$Nodes\n1 %zu 1 %zu\n3 1 0 %zu\n", nv, nv, nv);
  text_writer *w = malloc(sizeof *w);
  if (!w) {
    free(ids);
    piola_atomic_file_abort(&f);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
  }
  piola__tw_init(w, o);
  for (size_t v = 0; v < nv; ++v) {
    piola__tw_int(w, (int64_t)v + 1);
    piola__tw_char(w, '\n');
  }
  for (size_t v = 0; v < nv; ++v) {
    for (int k = 0; k < 3; ++k) {
      piola__tw_double(w, mesh->positions[3 * v + (size_t)k]);
      piola__tw_char(w, k < 2 ? ' ' : '\n');
    }
  }
  piola__tw_flush(w);
  fprintf(o, "$EndNodes\n");
  size_t blocks = 0;
  for (size_t t = 0; t < nt; ++t)
    if (t == 0 || (mesh->tet_regions && mesh->tet_regions[t] != mesh->tet_regions[t - 1])) ++blocks;
  fprintf(o, "$Elements\n%zu %zu 1 %zu\n", blocks, nt, nt);
  for (size_t t = 0; t < nt;) {
    int32_t region = mesh->tet_regions ? mesh->tet_regions[t] : 0;
    size_t e = t + 1;
    while (e < nt && (!mesh->tet_regions || mesh->tet_regions[e] == region)) ++e;
    size_t entity = 0;
    while (ids[entity] != region) ++entity;
    fprintf(o, "3 %zu 4 %zu\n", entity + 1, e - t);
    for (size_t k = t; k < e; ++k) {
      const int32_t *q = mesh->tets + 4 * k;
      piola__tw_int(w, (int64_t)k + 1);
      for (int j = 0; j < 4; ++j) {
        piola__tw_char(w, ' ');
        piola__tw_int(w, (int64_t)q[j] + 1);
      }
      piola__tw_char(w, '\n');
    }
    piola__tw_flush(w);
    t = e;
  }
  fprintf(o, "$EndElements\n");
  if (mesh->tet_fibers) {
    /* one view "fiber": time 0, step 0, 3 components, one entry per tet (tag t + 1) */
    fprintf(o, "$ElementData\n1\n\"fiber\"\n1\n0\n3\n0\n3\n%zu\n", nt);
    for (size_t t = 0; t < nt; ++t) {
      piola__tw_int(w, (int64_t)t + 1);
      for (int k = 0; k < 3; ++k) {
        piola__tw_char(w, ' ');
        piola__tw_double(w, mesh->tet_fibers[3 * t + (size_t)k]);
      }
      piola__tw_char(w, '\n');
    }
    piola__tw_flush(w);
    fprintf(o, "$EndElementData\n");
  }
  free(w);
  free(ids);
  return piola_atomic_file_commit(&f);
}
