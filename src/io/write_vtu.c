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

static void write_array_header(FILE *o, const char *type, const char *name, int components, uint64_t *offset,
                               uint64_t bytes) {
  fprintf(o, "        <DataArray type=\"%s\"", type);
  if (name) fprintf(o, " Name=\"%s\"", name);
  fprintf(o, " NumberOfComponents=\"%d\" format=\"appended\" offset=\"%llu\"/>\n", components,
          (unsigned long long)*offset);
  *offset += 8 + bytes;
}

static void write_block(FILE *o, const void *data, uint64_t bytes) {
  fwrite(&bytes, 8, 1, o);
  if (bytes) fwrite(data, 1, (size_t)bytes, o);
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

  piola_atomic_file f;
  piola_status s = piola_atomic_file_open(&f, path);
  if (s == PIOLA_OK) {
    FILE *o = f.stream;
    uint64_t offset = 0;
    fprintf(o, "<?xml version=\"1.0\"?>\n"
               "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
               "header_type=\"UInt64\">\n  <UnstructuredGrid>\n");
    fprintf(o, "    <Piece NumberOfPoints=\"%llu\" NumberOfCells=\"%llu\">\n", (unsigned long long)np,
            (unsigned long long)nc);
    fprintf(o, "      <PointData>\n");
    for (int i = 0; i < frame->point_field_count; ++i) {
      const piola_vtu_field *fd = &frame->point_fields[i];
      write_array_header(o, "Float64", fd->name, fd->components, &offset, np * (uint64_t)fd->components * 8);
    }
    fprintf(o, "      </PointData>\n      <CellData>\n");
    for (int i = 0; i < frame->cell_field_count; ++i) {
      const piola_vtu_field *fd = &frame->cell_fields[i];
      write_array_header(o, "Float64", fd->name, fd->components, &offset, nc * (uint64_t)fd->components * 8);
    }
    fprintf(o, "      </CellData>\n      <Points>\n");
    write_array_header(o, "Float64", "Points", 3, &offset, 3 * np * 8);
    fprintf(o, "      </Points>\n      <Cells>\n");
    write_array_header(o, "Int64", "connectivity", 1, &offset, c * 8);
    write_array_header(o, "Int64", "offsets", 1, &offset, nc * 8);
    write_array_header(o, "UInt8", "types", 1, &offset, nc);
    fprintf(o, "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _");
    for (int i = 0; i < frame->point_field_count; ++i) {
      const piola_vtu_field *fd = &frame->point_fields[i];
      write_block(o, fd->values, np * (uint64_t)fd->components * 8);
    }
    for (int i = 0; i < frame->cell_field_count; ++i) {
      const piola_vtu_field *fd = &frame->cell_fields[i];
      write_block(o, fd->values, nc * (uint64_t)fd->components * 8);
    }
    write_block(o, points, 3 * np * 8);
    write_block(o, connectivity, c * 8);
    write_block(o, offsets, nc * 8);
    write_block(o, types, nc);
    fprintf(o, "\n  </AppendedData>\n</VTKFile>\n");
    s = piola_atomic_file_commit(&f);
  }
  free(points);
  free(connectivity);
  free(offsets);
  free(types);
  return s;
}
