/* VTK XML UnstructuredGrid (.vtu) reader: the one reader of the format in piola.
 *
 * Reads what piola and the usual tools write without compression: one Piece, DataArrays
 * in ascii, inline base64 ("binary") or appended raw format, little-endian, UInt32 or
 * UInt64 headers. piola_vtu_read returns the cells as in the file (tets: VTK type 10 and
 * the corners of quadratic tets, 24; triangles: 5 and the corners of 22) with every
 * numeric point and cell field; the renderer builds its frames from it. The tet mesh reader
 * (piola_tet_mesh_read) sits on top: it keeps the tets, turns a cell field named "region"
 * into tet_regions and one named "fiber" or "fibers" (3 components) into tet_fibers, and
 * orients the mesh. Every count and offset is checked against the
 * file size before anything is read or allocated, so a truncated frame of a running
 * simulation fails cleanly. The XML is scanned for the few tags needed, not parsed in full:
 * this is an exchange format reader, not a general XML parser. Refused: compressed data,
 * big-endian data, appended base64, other dataset types. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "io/mesh_io_internal.h"
#include "io/text_scanner.h"
#include "mesh/mesh_internal.h"
#include "piola/files.h"

typedef struct vtu_reader {
  const char *name, *data, *end;
  int header64;
  const char *appended; /* first byte after '_' in <AppendedData>, or NULL */
} vtu_reader;

static long line_of(const vtu_reader *r, const char *p) {
  long line = 1;
  for (const char *q = r->data; q < p && q < r->end; ++q) line += *q == '\n';
  return line;
}

static piola_status error_at(const vtu_reader *r, const char *p, piola_status status, const char *message,
                             const char *detail) {
  return PIOLA_FAIL(status, "%s:%ld: %s%s", r->name, line_of(r, p), message, detail ? detail : "");
}

static const char *find(const char *from, const char *end, const char *needle) {
  size_t n = strlen(needle);
  for (const char *p = from; p && p + n <= end; ++p) {
    p = memchr(p, needle[0], (size_t)(end - p));
    if (!p || p + n > end) return NULL;
    if (memcmp(p, needle, n) == 0) return p;
  }
  return NULL;
}

/* Value of attribute `key` inside the tag starting at `tag` (up to '>'); copies into out. */
static int attribute(const char *tag, const char *end, const char *key, char *out, size_t size) {
  const char *close = memchr(tag, '>', (size_t)(end - tag));
  if (!close) return 0;
  size_t n = strlen(key);
  for (const char *p = tag + 1; p + n + 2 < close; ++p) {
    if ((p[-1] == ' ' || p[-1] == '\n' || p[-1] == '\t' || p[-1] == '\r') && memcmp(p, key, n) == 0 && p[n] == '=' &&
        (p[n + 1] == '"' || p[n + 1] == '\'')) {
      char quote = p[n + 1];
      const char *v = p + n + 2, *e = memchr(v, quote, (size_t)(close - v));
      if (!e || (size_t)(e - v) >= size) return 0;
      memcpy(out, v, (size_t)(e - v));
      out[e - v] = '\0';
      return 1;
    }
  }
  return 0;
}

static int type_size(const char *type) {
  if (!strcmp(type, "Float64") || !strcmp(type, "Int64") || !strcmp(type, "UInt64")) return 8;
  if (!strcmp(type, "Float32") || !strcmp(type, "Int32") || !strcmp(type, "UInt32")) return 4;
  if (!strcmp(type, "Int16") || !strcmp(type, "UInt16")) return 2;
  if (!strcmp(type, "Int8") || !strcmp(type, "UInt8")) return 1;
  return 0;
}

static double element(const char *type, const unsigned char *p) {
  switch (type[0] == 'F' ? 'F' : (type[0] == 'U' ? 'U' : 'I')) {
    case 'F':
      if (type[5] == '6') {
        double d;
        memcpy(&d, p, 8);
        return d;
      } else {
        float f;
        memcpy(&f, p, 4);
        return f;
      }
    case 'U': {
      uint64_t u = 0;
      memcpy(&u, p, (size_t)type_size(type));
      return (double)u;
    }
    default: {
      int s = type_size(type);
      if (s == 8) {
        int64_t v;
        memcpy(&v, p, 8);
        return (double)v;
      }
      if (s == 4) {
        int32_t v;
        memcpy(&v, p, 4);
        return v;
      }
      if (s == 2) {
        int16_t v;
        memcpy(&v, p, 2);
        return v;
      }
      return (double)(int8_t)p[0];
    }
  }
}

static int base64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

/* Decodes base64 groups (padding may occur between concatenated blocks). */
static unsigned char *decode_base64(const char *p, const char *end, size_t *size) {
  unsigned char *out = malloc((size_t)(end - p) / 4 * 3 + 4);
  if (!out) return NULL;
  size_t n = 0;
  char group[4];
  int g = 0;
  for (; p < end; ++p) {
    if (*p == ' ' || *p == '\n' || *p == '\r' || *p == '\t') continue;
    group[g++] = *p;
    if (g < 4) continue;
    g = 0;
    int v[4], pad = 0;
    for (int k = 0; k < 4; ++k) {
      if (group[k] == '=') {
        v[k] = 0;
        ++pad;
      } else if ((v[k] = base64_value(group[k])) < 0 || pad) {
        free(out);
        return NULL;
      }
    }
    if (pad > 2) {
      free(out);
      return NULL;
    }
    uint32_t bits = ((uint32_t)v[0] << 18) | ((uint32_t)v[1] << 12) | ((uint32_t)v[2] << 6) | (uint32_t)v[3];
    out[n++] = (unsigned char)(bits >> 16);
    if (pad < 2) out[n++] = (unsigned char)(bits >> 8);
    if (pad < 1) out[n++] = (unsigned char)bits;
  }
  if (g != 0) {
    free(out);
    return NULL;
  }
  *size = n;
  return out;
}

/* Reads `count` values of the DataArray whose tag starts at `tag` into doubles. */
static piola_status read_array(vtu_reader *r, const char *tag, size_t count, double **out) {
  char type[32], format[32] = "ascii", offset_text[32] = "0", what[64] = "";
  attribute(tag, r->end, "Name", what, sizeof what);
  if (!attribute(tag, r->end, "type", type, sizeof type) || type_size(type) == 0)
    return error_at(r, tag, PIOLA_ERROR_PARSE, "DataArray without a known type: ", what);
  attribute(tag, r->end, "format", format, sizeof format);
  const char *body = memchr(tag, '>', (size_t)(r->end - tag));
  if (!body) return error_at(r, tag, PIOLA_ERROR_PARSE, "unterminated DataArray tag", NULL);
  ++body;
  /* every value takes at least one byte of the file in any format: a count beyond the file
   * size is a damaged header, refused before allocating for it */
  if (count > (size_t)(r->end - r->data))
    return error_at(r, tag, PIOLA_ERROR_PARSE, "DataArray longer than the file: ", what);
  *out = malloc(count * sizeof(double) + 1);
  if (!*out) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", r->name);
  int size = type_size(type);
  if (!strcmp(format, "ascii")) {
    const char *close = find(body, r->end, "</DataArray>");
    if (!close) return error_at(r, tag, PIOLA_ERROR_PARSE, "missing </DataArray>", NULL);
    text_scanner s;
    piola__scanner_init(&s, r->name, body, (size_t)(close - body), 0);
    s.line = line_of(r, body);
    for (size_t i = 0; i < count; ++i) PIOLA_TRY(piola__scan_double(&s, &(*out)[i], "DataArray value"));
    return PIOLA_OK;
  }
  const unsigned char *bytes = NULL;
  size_t available = 0;
  unsigned char *decoded = NULL;
  if (!strcmp(format, "appended")) {
    if (!r->appended) return error_at(r, tag, PIOLA_ERROR_PARSE, "appended DataArray but no raw <AppendedData>", NULL);
    attribute(tag, r->end, "offset", offset_text, sizeof offset_text);
    char *stop;
    unsigned long long offset = strtoull(offset_text, &stop, 10);
    if (*stop || offset > (unsigned long long)(r->end - r->appended))
      return error_at(r, tag, PIOLA_ERROR_PARSE, "DataArray offset out of the file: ", offset_text);
    bytes = (const unsigned char *)r->appended + offset;
    available = (size_t)(r->end - r->appended) - (size_t)offset;
  } else if (!strcmp(format, "binary")) {
    const char *close = find(body, r->end, "</DataArray>");
    if (!close) return error_at(r, tag, PIOLA_ERROR_PARSE, "missing </DataArray>", NULL);
    /* the data ends at the first child element: VTK 9 follows it with <InformationKey>s */
    const char *child = memchr(body, '<', (size_t)(close - body));
    decoded = decode_base64(body, child ? child : close, &available);
    if (!decoded) return error_at(r, tag, PIOLA_ERROR_PARSE, "bad base64 data in DataArray ", what);
    bytes = decoded;
  } else {
    return error_at(r, tag, PIOLA_ERROR_UNSUPPORTED, "DataArray format not supported: ", format);
  }
  size_t header = r->header64 ? 8 : 4;
  uint64_t length = 0;
  piola_status status = PIOLA_OK;
  if (available < header) status = error_at(r, tag, PIOLA_ERROR_PARSE, "truncated DataArray ", what);
  else {
    memcpy(&length, bytes, header);
    if (length != (uint64_t)count * (uint64_t)size || length > available - header)
      status = error_at(r, tag, PIOLA_ERROR_PARSE, "DataArray size does not match the counts: ", what);
    else
      for (size_t i = 0; i < count; ++i) (*out)[i] = element(type, bytes + header + i * (size_t)size);
  }
  free(decoded);
  return status;
}

/* The DataArray named `name` (or the first one when name is NULL) in [from, to). */
static const char *find_array(const char *from, const char *to, const char *name) {
  for (const char *p = find(from, to, "<DataArray"); p; p = find(p + 1, to, "<DataArray")) {
    if (!name) return p;
    char value[64];
    if (attribute(p, to, "Name", value, sizeof value) && !strcmp(value, name)) return p;
  }
  return NULL;
}

/* Reads every numeric DataArray of the <PointData> or <CellData> section (`section` is the
 * tag name without '<') in [piece, xml_end), `count` tuples each. */
static piola_status read_fields(vtu_reader *r, const char *piece, const char *xml_end, const char *section,
                                size_t count, piola_vtu_array **fields, int32_t *field_count) {
  char open_tag[32], close_tag[32];
  snprintf(open_tag, sizeof open_tag, "<%s", section);
  snprintf(close_tag, sizeof close_tag, "</%s>", section);
  const char *tag = find(piece, xml_end, open_tag);
  if (!tag) return PIOLA_OK;
  const char *tag_end = memchr(tag, '>', (size_t)(xml_end - tag));
  if (!tag_end) return error_at(r, tag, PIOLA_ERROR_PARSE, "unterminated tag ", open_tag);
  if (tag_end[-1] == '/') return PIOLA_OK; /* <PointData/> */
  const char *end = find(tag_end, xml_end, close_tag);
  if (!end) return error_at(r, tag, PIOLA_ERROR_PARSE, "missing ", close_tag);
  for (const char *p = find(tag_end, end, "<DataArray"); p; p = find(p + 1, end, "<DataArray")) {
    char type[32] = "", components_text[32] = "1";
    if (!attribute(p, end, "type", type, sizeof type) || type_size(type) == 0) continue; /* String */
    attribute(p, end, "NumberOfComponents", components_text, sizeof components_text);
    char *stop;
    long components = strtol(components_text, &stop, 10);
    if (*stop || components < 1 || components > 64)
      return error_at(r, p, PIOLA_ERROR_PARSE, "NumberOfComponents must be 1..64, not ", components_text);
    piola_vtu_array *grown = realloc(*fields, (size_t)(*field_count + 1) * sizeof *grown);
    if (!grown) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", r->name);
    *fields = grown;
    piola_vtu_array *a = &grown[*field_count];
    memset(a, 0, sizeof *a);
    if (!attribute(p, end, "Name", a->name, sizeof a->name)) a->name[0] = '\0';
    a->components = (int)components;
    ++*field_count; /* counted before reading, so a failure frees what was allocated */
    PIOLA_TRY(read_array(r, p, (size_t)components * count, &a->values));
  }
  return PIOLA_OK;
}

static piola_status parse(vtu_reader *r, piola_vtu_data *out) {
  const char *file = find(r->data, r->end, "<VTKFile");
  if (!file) return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s:1: not a VTK XML file (no <VTKFile>)", r->name);
  char value[64];
  if (!attribute(file, r->end, "type", value, sizeof value) || strcmp(value, "UnstructuredGrid") != 0)
    return error_at(r, file, PIOLA_ERROR_UNSUPPORTED, "only UnstructuredGrid files are read", NULL);
  if (attribute(file, r->end, "byte_order", value, sizeof value) && strcmp(value, "LittleEndian") != 0)
    return error_at(r, file, PIOLA_ERROR_UNSUPPORTED, "byte order not supported: ", value);
  if (attribute(file, r->end, "compressor", value, sizeof value))
    return error_at(r, file, PIOLA_ERROR_UNSUPPORTED, "compressed data not supported: ", value);
  r->header64 = attribute(file, r->end, "header_type", value, sizeof value) && !strcmp(value, "UInt64");
  const char *appended = find(file, r->end, "<AppendedData");
  const char *xml_end = appended ? appended : r->end;
  if (appended) {
    if (attribute(appended, r->end, "encoding", value, sizeof value) && strcmp(value, "raw") != 0)
      return error_at(r, appended, PIOLA_ERROR_UNSUPPORTED, "appended data encoding not supported: ", value);
    const char *close = memchr(appended, '>', (size_t)(r->end - appended));
    const char *underscore = close ? memchr(close, '_', (size_t)(r->end - close)) : NULL;
    if (!underscore) return error_at(r, appended, PIOLA_ERROR_PARSE, "<AppendedData> without '_'", NULL);
    r->appended = underscore + 1;
  }
  const char *piece = find(file, xml_end, "<Piece");
  if (!piece) return error_at(r, file, PIOLA_ERROR_PARSE, "no <Piece>", NULL);
  if (find(piece + 1, xml_end, "<Piece")) return error_at(r, piece, PIOLA_ERROR_UNSUPPORTED, "more than one <Piece>", NULL);
  char np_text[32], nc_text[32];
  if (!attribute(piece, xml_end, "NumberOfPoints", np_text, sizeof np_text) ||
      !attribute(piece, xml_end, "NumberOfCells", nc_text, sizeof nc_text))
    return error_at(r, piece, PIOLA_ERROR_PARSE, "<Piece> without NumberOfPoints/NumberOfCells", NULL);
  char *stop1, *stop2;
  unsigned long long np = strtoull(np_text, &stop1, 10), nc = strtoull(nc_text, &stop2, 10);
  size_t file_size = (size_t)(r->end - r->data);
  if (*stop1 || *stop2 || np > INT32_MAX / 4 || nc > INT32_MAX / 4 || np > file_size || nc > file_size)
    return error_at(r, piece, PIOLA_ERROR_PARSE, "point or cell count does not fit the file", NULL);
  const char *points = find(piece, xml_end, "<Points"), *cells = find(piece, xml_end, "<Cells");
  const char *points_end = points ? find(points, xml_end, "</Points>") : NULL;
  const char *cells_end = cells ? find(cells, xml_end, "</Cells>") : NULL;
  if (!points_end || !cells_end) return error_at(r, piece, PIOLA_ERROR_PARSE, "missing <Points> or <Cells>", NULL);
  const char *point_array = find_array(points, points_end, NULL);
  const char *conn_array = find_array(cells, cells_end, "connectivity");
  const char *offs_array = find_array(cells, cells_end, "offsets");
  const char *type_array = find_array(cells, cells_end, "types");
  if (!point_array || !conn_array || !offs_array || !type_array)
    return error_at(r, cells, PIOLA_ERROR_PARSE, "missing points, connectivity, offsets or types", NULL);
  out->point_count = (int32_t)np;
  out->cell_count = (int32_t)nc;
  double *offsets = NULL, *types = NULL, *conn = NULL;
  piola_status status = read_array(r, point_array, 3 * (size_t)np, &out->positions);
  if (status == PIOLA_OK) status = read_array(r, offs_array, (size_t)nc, &offsets);
  if (status == PIOLA_OK) status = read_array(r, type_array, (size_t)nc, &types);
  size_t nconn = 0;
  if (status == PIOLA_OK && nc) {
    if (!(offsets[nc - 1] >= 0 && offsets[nc - 1] <= (double)file_size))
      status = error_at(r, offs_array, PIOLA_ERROR_PARSE, "bad last offset", NULL);
    else
      nconn = (size_t)offsets[nc - 1];
  }
  if (status == PIOLA_OK) status = read_array(r, conn_array, nconn, &conn);
  if (status == PIOLA_OK)
    status = read_fields(r, piece, xml_end, "PointData", (size_t)np, &out->point_fields, &out->point_field_count);
  if (status == PIOLA_OK)
    status = read_fields(r, piece, xml_end, "CellData", (size_t)nc, &out->cell_fields, &out->cell_field_count);
  if (status == PIOLA_OK) {
    out->tets = malloc(4 * (size_t)nc * sizeof(int32_t) + 1);
    out->tet_cells = malloc((size_t)nc * sizeof(int32_t) + 1);
    out->triangles = malloc(3 * (size_t)nc * sizeof(int32_t) + 1);
    out->triangle_cells = malloc((size_t)nc * sizeof(int32_t) + 1);
    if (!out->tets || !out->tet_cells || !out->triangles || !out->triangle_cells)
      status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", r->name);
  }
  double previous = 0;
  for (size_t c = 0; status == PIOLA_OK && c < nc; ++c) {
    double begin = previous, finish = offsets[c];
    previous = finish;
    if (!(finish >= begin && finish <= (double)nconn)) {
      status = error_at(r, offs_array, PIOLA_ERROR_PARSE, "offsets are not increasing", NULL);
      break;
    }
    int type = (int)types[c], corners = 0, nodes = 0;
    if (type == 10 || type == 24) corners = 4, nodes = type == 10 ? 4 : 10;
    if (type == 5 || type == 22) corners = 3, nodes = type == 5 ? 3 : 6;
    if (!corners) continue;
    if (finish - begin != nodes) {
      status = error_at(r, offs_array, PIOLA_ERROR_PARSE,
                        corners == 4 ? "a tet cell does not have the right node count"
                                     : "a triangle cell does not have the right node count",
                        NULL);
      break;
    }
    int32_t *dest = corners == 4 ? out->tets + 4 * (size_t)out->tet_count
                                 : out->triangles + 3 * (size_t)out->triangle_count;
    for (int k = 0; k < corners; ++k) {
      double v = conn[(size_t)begin + (size_t)k];
      if (!(v >= 0 && v < (double)np)) {
        status = error_at(r, conn_array, PIOLA_ERROR_PARSE, "connectivity index out of range", NULL);
        break;
      }
      dest[k] = (int32_t)v;
    }
    if (corners == 4)
      out->tet_cells[out->tet_count++] = (int32_t)c;
    else
      out->triangle_cells[out->triangle_count++] = (int32_t)c;
  }
  free(offsets);
  free(types);
  free(conn);
  return status;
}

void piola_vtu_data_free(piola_vtu_data *data) {
  if (!data) return;
  for (int32_t i = 0; i < data->point_field_count; ++i) free(data->point_fields[i].values);
  for (int32_t i = 0; i < data->cell_field_count; ++i) free(data->cell_fields[i].values);
  free(data->point_fields);
  free(data->cell_fields);
  free(data->positions);
  free(data->tets);
  free(data->tet_cells);
  free(data->triangles);
  free(data->triangle_cells);
  memset(data, 0, sizeof *data);
}

const piola_vtu_array *piola_vtu_find_field(const piola_vtu_array *fields, int32_t count, const char *name) {
  for (int32_t i = 0; fields && name && i < count; ++i)
    if (strcmp(fields[i].name, name) == 0) return &fields[i];
  return NULL;
}

piola_status piola__vtu_read_mem(const char *name, const char *data, size_t size, piola_vtu_data *out) {
  memset(out, 0, sizeof *out);
  vtu_reader r = {name, data, data + size, 0, NULL};
  piola_status status = parse(&r, out);
  if (status != PIOLA_OK) piola_vtu_data_free(out);
  return status;
}

piola_status piola_vtu_read(const char *path, piola_vtu_data *out) {
  if (!path || !out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "piola_vtu_read: NULL argument");
  memset(out, 0, sizeof *out);
  char *data = NULL;
  size_t size = 0;
  PIOLA_TRY(piola_read_file(path, 0, &data, &size));
  piola_status status = piola__vtu_read_mem(path, data, size, out);
  free(data);
  return status;
}

/* The tet mesh of a VTU file: its tets, a cell field "region" as tet_regions, a 3-component
 * cell field "fiber" or "fibers" as tet_fibers, oriented. */
piola_status piola__read_vtu_mem(const char *name, const char *data, size_t size, piola_tet_mesh *out) {
  memset(out, 0, sizeof *out);
  piola_vtu_data vtu;
  PIOLA_TRY(piola__vtu_read_mem(name, data, size, &vtu));
  const piola_vtu_array *region = piola_vtu_find_field(vtu.cell_fields, vtu.cell_field_count, "region");
  piola_status status = PIOLA_OK;
  if (region) {
    out->tet_regions = malloc((size_t)vtu.tet_count * sizeof(int32_t) + 1);
    if (!out->tet_regions) status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", name);
    for (int32_t t = 0; status == PIOLA_OK && t < vtu.tet_count; ++t) {
      double reg = region->values[(size_t)region->components * (size_t)vtu.tet_cells[t]];
      out->tet_regions[t] = fabs(reg) < 2e9 ? (int32_t)lround(reg) : 0;
    }
  }
  /* fibres: a 3-component cell array "fiber" (or "fibers"), one direction per tet */
  const piola_vtu_array *fiber = piola_vtu_find_field(vtu.cell_fields, vtu.cell_field_count, "fiber");
  if (!fiber) fiber = piola_vtu_find_field(vtu.cell_fields, vtu.cell_field_count, "fibers");
  if (status == PIOLA_OK && fiber) {
    if (fiber->components != 3)
      status = PIOLA_FAIL(PIOLA_ERROR_PARSE,
                          "%s: CellData array '%s' has %d components, expected 3 (a fibre direction per cell)",
                          name, fiber->name, fiber->components);
    else if (!(out->tet_fibers = malloc(3 * (size_t)vtu.tet_count * sizeof(double) + 1)))
      status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", name);
    for (int32_t t = 0; status == PIOLA_OK && t < vtu.tet_count; ++t)
      for (int k = 0; k < 3; ++k) {
        double v = fiber->values[3 * (size_t)vtu.tet_cells[t] + (size_t)k];
        if (!isfinite(v)) {
          status = PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: CellData array '%s': cell %d has a non-finite value",
                              name, fiber->name, (int)vtu.tet_cells[t]);
          break;
        }
        out->tet_fibers[3 * (size_t)t + (size_t)k] = v;
      }
  }
  out->vertex_count = vtu.point_count;
  out->positions = vtu.positions;
  out->tet_count = vtu.tet_count;
  out->tets = vtu.tets;
  vtu.positions = NULL;
  vtu.tets = NULL;
  piola_vtu_data_free(&vtu);
  if (status == PIOLA_OK) status = piola__tet_mesh_finish(out, name, NULL);
  if (status != PIOLA_OK) piola_tet_mesh_free(out);
  return status;
}
