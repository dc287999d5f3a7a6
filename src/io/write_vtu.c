/* VTK UnstructuredGrid (.vtu) writer: XML header, then all arrays as appended raw binary
 * (little-endian, UInt64 size headers). Raw appended data is the most compact layout that
 * ParaView, VTK and meshio all read, and needs no base64 pass. Tets are VTK type 10,
 * triangles type 5. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "piola/files.h"
#include "piola/mesh_io.h"

static piola_status check_field(const char *path, const piola_vtu_field *f, const char *where) {
  if (!f->name || !f->name[0] || (f->components != 1 && f->components != 3) || !f->values)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "%s: %s field '%s' needs a name, 1 or 3 components and values", path,
                      where, f->name ? f->name : "(null)");
  for (const char *c = f->name; *c; ++c)
    if (*c == '"' || *c == '<' || *c == '>' || *c == '&')
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "%s: field name '%s' has a character not allowed in XML", path,
                        f->name);
  return PIOLA_OK;
}

/* One appended DataArray: its header's attributes and the block it points to. */
typedef struct {
  const char *type, *name;
  int components;
  const void *data;
  uint64_t bytes, offset;
} vtu_array;

static void write_array_header(FILE *o, const vtu_array *a) {
  fprintf(o, "        <DataArray type=\"%s\" Name=\"%s\"", a->type, a->name);
  fprintf(o, " NumberOfComponents=\"%d\" format=\"appended\" offset=\"%llu\"/>\n", a->components,
          (unsigned long long)a->offset);
}

static void write_block(FILE *o, const vtu_array *a) {
  fwrite(&a->bytes, 8, 1, o);
  if (a->bytes) fwrite(a->data, 1, (size_t)a->bytes, o);
}

/* The blocks go into the appended section in the reverse of the headers' order, the last
 * header's block at offset 0. VTK reads each block at its offset in any order; meshio 5
 * rewrites raw blocks to base64 in offset order and hands each block to the first header
 * (document order) whose offset attribute equals the block's raw offset, so with blocks in
 * header order a header already moved to its base64 offset can take a later block's data
 * (docs/file-formats.md). In reverse order every header still unmoved comes before every
 * moved one, and the match is always the block's own header. */
static void place_blocks_last_first(vtu_array *arrays, int count) {
  uint64_t offset = 0;
  for (int i = count - 1; i >= 0; --i) {
    arrays[i].offset = offset;
    offset += 8 + arrays[i].bytes;
  }
}

piola_status piola_vtu_write(const char *path, const piola_vtu_frame *frame) {
  if (!path || !frame) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "vtu write: NULL argument");
  const piola_tet_mesh *tm = frame->tets;
  const piola_tri_mesh *sm = frame->triangles;
  uint64_t ntv = tm ? (uint64_t)tm->vertex_count : 0, nsv = sm ? (uint64_t)sm->vertex_count : 0;
  uint64_t nt = tm ? (uint64_t)tm->tet_count : 0, ns = sm ? (uint64_t)sm->triangle_count : 0;
  uint64_t np = ntv + nsv, nc = nt + ns;
  if (tm) PIOLA_TRY(piola_tet_mesh_validate(tm));
  if (sm)
    for (uint64_t i = 0; i < 3 * ns; ++i)
      if (sm->triangles[i] < 0 || sm->triangles[i] >= sm->vertex_count)
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "%s: triangle %llu has a vertex out of range", path,
                          (unsigned long long)(i / 3));
  for (int i = 0; i < frame->point_field_count; ++i) PIOLA_TRY(check_field(path, &frame->point_fields[i], "point"));
  for (int i = 0; i < frame->cell_field_count; ++i) PIOLA_TRY(check_field(path, &frame->cell_fields[i], "cell"));

  double *points = malloc(3 * np * sizeof(double) + 1);
  int64_t *connectivity = malloc((4 * nt + 3 * ns) * sizeof(int64_t) + 1);
  int64_t *offsets = malloc(nc * sizeof(int64_t) + 1);
  uint8_t *types = malloc(nc + 1);
  if (!points || !connectivity || !offsets || !types) {
    free(points);
    free(connectivity);
    free(offsets);
    free(types);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
  }
  if (frame->positions) memcpy(points, frame->positions, 3 * np * sizeof(double));
  else {
    if (ntv) memcpy(points, tm->positions, 3 * ntv * sizeof(double));
    if (nsv) memcpy(points + 3 * ntv, sm->positions, 3 * nsv * sizeof(double));
  }
  uint64_t c = 0;
  for (uint64_t t = 0; t < nt; ++t) {
    for (int k = 0; k < 4; ++k) connectivity[c++] = tm->tets[4 * t + (uint64_t)k];
    offsets[t] = (int64_t)c;
    types[t] = 10;
  }
  for (uint64_t t = 0; t < ns; ++t) {
    for (int k = 0; k < 3; ++k) connectivity[c++] = (int64_t)ntv + sm->triangles[3 * t + (uint64_t)k];
    offsets[nt + t] = (int64_t)c;
    types[nt + t] = 5;
  }

  /* headers in the order the schema asks: point data, cell data, points, cells */
  int count = 0, field_count = frame->point_field_count + frame->cell_field_count;
  vtu_array *arrays = malloc((size_t)(field_count + 4) * sizeof *arrays);
  if (!arrays) {
    free(points);
    free(connectivity);
    free(offsets);
    free(types);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
  }
  for (int i = 0; i < frame->point_field_count; ++i) {
    const piola_vtu_field *fd = &frame->point_fields[i];
    arrays[count++] = (vtu_array){"Float64", fd->name, fd->components, fd->values,
                                  np * (uint64_t)fd->components * 8, 0};
  }
  for (int i = 0; i < frame->cell_field_count; ++i) {
    const piola_vtu_field *fd = &frame->cell_fields[i];
    arrays[count++] = (vtu_array){"Float64", fd->name, fd->components, fd->values,
                                  nc * (uint64_t)fd->components * 8, 0};
  }
  const int points_at = count;
  arrays[count++] = (vtu_array){"Float64", "Points", 3, points, 3 * np * 8, 0};
  arrays[count++] = (vtu_array){"Int64", "connectivity", 1, connectivity, c * 8, 0};
  arrays[count++] = (vtu_array){"Int64", "offsets", 1, offsets, nc * 8, 0};
  arrays[count++] = (vtu_array){"UInt8", "types", 1, types, nc, 0};
  place_blocks_last_first(arrays, count);

  piola_atomic_file f;
  piola_status s = piola_atomic_file_open(&f, path);
  if (s == PIOLA_OK) {
    FILE *o = f.stream;
    fprintf(o, "<?xml version=\"1.0\"?>\n"
               "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
               "header_type=\"UInt64\">\n  <UnstructuredGrid>\n");
    fprintf(o, "    <Piece NumberOfPoints=\"%llu\" NumberOfCells=\"%llu\">\n", (unsigned long long)np,
            (unsigned long long)nc);
    fprintf(o, "      <PointData>\n");
    for (int i = 0; i < frame->point_field_count; ++i) write_array_header(o, &arrays[i]);
    fprintf(o, "      </PointData>\n      <CellData>\n");
    for (int i = frame->point_field_count; i < points_at; ++i) write_array_header(o, &arrays[i]);
    fprintf(o, "      </CellData>\n      <Points>\n");
    write_array_header(o, &arrays[points_at]);
    fprintf(o, "      </Points>\n      <Cells>\n");
    for (int i = points_at + 1; i < count; ++i) write_array_header(o, &arrays[i]);
    fprintf(o, "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _");
    for (int i = count - 1; i >= 0; --i) write_block(o, &arrays[i]);
    fprintf(o, "\n  </AppendedData>\n</VTKFile>\n");
    s = piola_atomic_file_commit(&f);
  }
  free(arrays);
  free(points);
  free(connectivity);
  free(offsets);
  free(types);
  return s;
}
