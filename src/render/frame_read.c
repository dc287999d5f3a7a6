/* Reading a frame that piola wrote (VTK UnstructuredGrid, appended raw data) and turning it
 * into a renderable surface.
 *
 * The reader understands exactly what src/io/write_vtu.c writes (Float64 fields, Int64
 * connectivity and offsets, UInt8 types, UInt32 or UInt64 block headers) and checks every
 * offset and count against the file size, so a truncated frame of a running simulation
 * fails cleanly. The surface is the set of tet faces used by exactly one tet, each
 * remembering its tet, so per-cell data (inverted, energy density, solid) colour the faces;
 * triangle cells (shells) are drawn as they are. */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_internal.h"
#include "render/render_internal.h"

typedef struct vtu_array {
  char name[64];
  char type[16];
  int components;
  uint64_t offset;
  int section; /* 0 point data, 1 cell data, 2 points, 3 cells */
} vtu_array;

void piola_render_frame_destroy(piola_render_frame *f) {
  if (!f) return;
  for (int i = 0; i < f->field_count; ++i) free(f->fields[i].values);
  free(f->fields), free(f->points), free(f->surface), free(f->surface_cell), free(f->cell_inverted);
  free(f->rest), free(f->tets), free(f->tet_cell);
  free(f->face_inverted), free(f->face_values), free(f->face_parts);
  free(f);
}

/* Value of attribute `key` inside the tag text [tag, end) into out; false if absent. */
static bool attribute(const char *tag, const char *end, const char *key, char *out, size_t n) {
  size_t kl = strlen(key);
  for (const char *p = tag; p + kl + 2 < end; ++p) {
    if ((p == tag || isspace((unsigned char)p[-1])) && strncmp(p, key, kl) == 0 && p[kl] == '=' &&
        p[kl + 1] == '"') {
      const char *v = p + kl + 2, *q = v;
      while (q < end && *q != '"') ++q;
      size_t len = (size_t)(q - v);
      if (q >= end || len + 1 > n) return false;
      memcpy(out, v, len);
      out[len] = '\0';
      return true;
    }
  }
  return false;
}

static const char *find_in(const char *hay, const char *end, const char *needle) {
  size_t n = strlen(needle);
  for (const char *p = hay; p + n <= end; ++p)
    if (memcmp(p, needle, n) == 0) return p;
  return NULL;
}

typedef struct face_key {
  int32_t v[3]; /* sorted */
  int32_t corner[3];
  int32_t cell;
} face_key;

static int compare_face(const void *a, const void *b) {
  const face_key *x = a, *y = b;
  for (int k = 0; k < 3; ++k)
    if (x->v[k] != y->v[k]) return x->v[k] < y->v[k] ? -1 : 1;
  return (x->cell > y->cell) - (x->cell < y->cell);
}

static void sort3(int32_t v[3]) {
  int32_t t;
  if (v[0] > v[1]) t = v[0], v[0] = v[1], v[1] = t;
  if (v[1] > v[2]) t = v[1], v[1] = v[2], v[2] = t;
  if (v[0] > v[1]) t = v[0], v[0] = v[1], v[1] = t;
}

static piola_status build_surface(piola_render_frame *f, const int64_t *conn,
                                  const int64_t *offsets, const uint8_t *types, const char *path) {
  int64_t tets = 0, tris = 0;
  for (int64_t c = 0; c < f->cell_count; ++c) {
    if (types[c] == 10)
      ++tets;
    else if (types[c] == 5)
      ++tris;
  }
  if (4 * tets + tris > INT32_MAX / 4)
    return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED, "%s: too many cells to render", path);
  face_key *faces = malloc((size_t)(4 * tets > 0 ? 4 * tets : 1) * sizeof *faces);
  if (!faces) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
  static const int local[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  int64_t nf = 0;
  for (int64_t c = 0; c < f->cell_count; ++c) {
    if (types[c] != 10) continue;
    const int64_t *t = conn + (offsets[c] - 4);
    for (int k = 0; k < 4; ++k) {
      face_key *fk = &faces[nf++];
      for (int j = 0; j < 3; ++j) fk->v[j] = fk->corner[j] = (int32_t)t[local[k][j]];
      sort3(fk->v);
      fk->cell = (int32_t)c;
    }
  }
  qsort(faces, (size_t)nf, sizeof *faces, compare_face);
  int64_t cap = nf + tris;
  f->surface = malloc(3 * (size_t)(cap > 0 ? cap : 1) * sizeof *f->surface);
  f->surface_cell = malloc((size_t)(cap > 0 ? cap : 1) * sizeof *f->surface_cell);
  if (!f->surface || !f->surface_cell) {
    free(faces);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
  }
  int32_t n = 0;
  for (int64_t i = 0; i < nf;) {
    int64_t j = i + 1;
    while (j < nf && memcmp(faces[j].v, faces[i].v, sizeof faces[i].v) == 0) ++j;
    if (j - i == 1) {
      memcpy(f->surface + 3 * (size_t)n, faces[i].corner, sizeof faces[i].corner);
      f->surface_cell[n++] = faces[i].cell;
    }
    i = j;
  }
  free(faces);
  for (int64_t c = 0; c < f->cell_count; ++c) {
    if (types[c] != 5) continue;
    const int64_t *t = conn + (offsets[c] - 3);
    for (int j = 0; j < 3; ++j) f->surface[3 * (size_t)n + (size_t)j] = (int32_t)t[j];
    f->surface_cell[n++] = (int32_t)c;
  }
  f->surface_count = n;
  return PIOLA_OK;
}

static double signed_volume(const double *x, const int64_t *t) {
  vec3 a = vec3_load(x + 3 * t[0]);
  vec3 e1 = vec3_sub(vec3_load(x + 3 * t[1]), a), e2 = vec3_sub(vec3_load(x + 3 * t[2]), a);
  vec3 e3 = vec3_sub(vec3_load(x + 3 * t[3]), a);
  return vec3_dot(e1, vec3_cross(e2, e3)) / 6;
}

static piola_status parse(piola_render_frame *f, const char *buf, size_t size, const char *path) {
  const char *end = buf + size;
  const char *data = find_in(buf, end, "<AppendedData");
  if (!data)
    return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: no <AppendedData> (not a frame piola wrote)", path);
  const char *underscore = memchr(data, '_', (size_t)(end - data));
  if (!underscore)
    return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: appended data has no '_' marker", path);
  const char *base = underscore + 1;
  const char *head = find_in(buf, data, "<VTKFile");
  char value[128];
  int header_bytes = 8;
  if (head && attribute(head, data, "header_type", value, sizeof value) &&
      strcmp(value, "UInt32") == 0)
    header_bytes = 4;
  const char *piece = find_in(buf, data, "<Piece");
  if (!piece) return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: no <Piece>", path);
  const char *piece_end = memchr(piece, '>', (size_t)(data - piece));
  char np[32], nc[32];
  if (!piece_end || !attribute(piece, piece_end, "NumberOfPoints", np, sizeof np) ||
      !attribute(piece, piece_end, "NumberOfCells", nc, sizeof nc))
    return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: <Piece> lacks NumberOfPoints or NumberOfCells", path);
  f->point_count = strtoll(np, NULL, 10);
  f->cell_count = strtoll(nc, NULL, 10);
  if (f->point_count < 0 || f->cell_count < 0 || f->point_count > ((int64_t)1 << 30) ||
      f->cell_count > ((int64_t)1 << 30))
    return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: point or cell count out of range", path);

  vtu_array arrays[64];
  int na = 0, section = -1;
  for (const char *p = piece_end; p < data;) {
    const char *lt = memchr(p, '<', (size_t)(data - p));
    if (!lt) break;
    const char *gt = memchr(lt, '>', (size_t)(data - lt));
    if (!gt) break;
    if (strncmp(lt, "<PointData", 10) == 0)
      section = 0;
    else if (strncmp(lt, "<CellData", 9) == 0)
      section = 1;
    else if (strncmp(lt, "<Points", 7) == 0)
      section = 2;
    else if (strncmp(lt, "<Cells", 6) == 0)
      section = 3;
    else if (strncmp(lt, "<DataArray", 10) == 0 && na < 64) {
      vtu_array *a = &arrays[na];
      char comps[16] = "1", off[32], format[32];
      if (!attribute(lt, gt, "Name", a->name, sizeof a->name)) a->name[0] = '\0';
      if (!attribute(lt, gt, "type", a->type, sizeof a->type) ||
          !attribute(lt, gt, "offset", off, sizeof off) ||
          !attribute(lt, gt, "format", format, sizeof format) || strcmp(format, "appended") != 0)
        return PIOLA_FAIL(PIOLA_ERROR_PARSE,
                          "%s: DataArray '%s' is not appended data with a type and offset", path,
                          a->name);
      attribute(lt, gt, "NumberOfComponents", comps, sizeof comps);
      a->components = atoi(comps);
      a->offset = strtoull(off, NULL, 10);
      a->section = section;
      ++na;
    }
    p = gt + 1;
  }
  /* Locates array a's block, checking its size against the file and the expected count. */
#define BLOCK(a, elem, count, ptr)                                                               \
  do {                                                                                           \
    uint64_t bytes_ = 0;                                                                         \
    if ((a)->offset > (uint64_t)(end - base) ||                                                  \
        (uint64_t)(end - base) - (a)->offset < (uint64_t)header_bytes)                           \
      return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: array '%s' lies past the end of the file", path, \
                        (a)->name);                                                              \
    memcpy(&bytes_, base + (a)->offset, (size_t)header_bytes);                                   \
    if (bytes_ != (uint64_t)(elem) * (uint64_t)(count) ||                                        \
        bytes_ > (uint64_t)(end - base) - (a)->offset - (uint64_t)header_bytes)                  \
      return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: array '%s' has %llu bytes, expected %llu", path, \
                        (a)->name, (unsigned long long)bytes_,                                   \
                        (unsigned long long)((uint64_t)(elem) * (uint64_t)(count)));             \
    (ptr) = base + (a)->offset + header_bytes;                                                   \
  } while (0)

  const char *pts = NULL, *offs = NULL, *types = NULL;
  const vtu_array *conn_a = NULL;
  for (int i = 0; i < na; ++i) {
    vtu_array *a = &arrays[i];
    if (a->section == 2) {
      if (strcmp(a->type, "Float64") != 0 || a->components != 3)
        return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED, "%s: points must be Float64 x 3", path);
      BLOCK(a, 24, f->point_count, pts);
    } else if (a->section == 3 && strcmp(a->name, "offsets") == 0) {
      if (strcmp(a->type, "Int64") != 0)
        return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED, "%s: offsets must be Int64", path);
      BLOCK(a, 8, f->cell_count, offs);
    } else if (a->section == 3 && strcmp(a->name, "types") == 0) {
      if (strcmp(a->type, "UInt8") != 0)
        return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED, "%s: types must be UInt8", path);
      BLOCK(a, 1, f->cell_count, types);
    } else if (a->section == 3 && strcmp(a->name, "connectivity") == 0) {
      if (strcmp(a->type, "Int64") != 0)
        return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED, "%s: connectivity must be Int64", path);
      conn_a = a;
    }
  }
  if (!pts || !offs || !types || !conn_a)
    return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: missing points, connectivity, offsets or types",
                      path);
  int64_t *offsets = malloc((size_t)(f->cell_count > 0 ? f->cell_count : 1) * sizeof *offsets);
  uint8_t *type_v = malloc((size_t)(f->cell_count > 0 ? f->cell_count : 1));
  f->points = malloc(3 * (size_t)(f->point_count > 0 ? f->point_count : 1) * sizeof *f->points);
  if (!offsets || !type_v || !f->points) {
    free(offsets), free(type_v);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
  }
  memcpy(offsets, offs, (size_t)f->cell_count * 8);
  memcpy(type_v, types, (size_t)f->cell_count);
  memcpy(f->points, pts, 3 * (size_t)f->point_count * 8);
  int64_t conn_len = f->cell_count > 0 ? offsets[f->cell_count - 1] : 0;
  piola_status st = PIOLA_OK;
  int64_t *conn_v = NULL;
  if (conn_len < 0 || conn_len > ((int64_t)1 << 32))
    st = PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: bad offsets", path);
  for (int64_t c = 0; st == PIOLA_OK && c < f->cell_count; ++c) {
    int64_t prev = c > 0 ? offsets[c - 1] : 0;
    int64_t want = type_v[c] == 10 ? 4 : type_v[c] == 5 ? 3 : -1;
    if (offsets[c] < prev || (want > 0 && offsets[c] - prev != want))
      st = PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: cell %lld has a bad offset for its type %d", path,
                      (long long)c, (int)type_v[c]);
  }
  if (st == PIOLA_OK) {
    const char *cp = NULL;
    uint64_t bytes = 0;
    if (conn_a->offset > (uint64_t)(end - base) ||
        (uint64_t)(end - base) - conn_a->offset < (uint64_t)header_bytes)
      st = PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: connectivity lies past the end of the file", path);
    else {
      memcpy(&bytes, base + conn_a->offset, (size_t)header_bytes);
      if (bytes != 8 * (uint64_t)conn_len ||
          bytes > (uint64_t)(end - base) - conn_a->offset - header_bytes)
        st = PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: connectivity has %llu bytes, expected %llu", path,
                        (unsigned long long)bytes, (unsigned long long)(8 * conn_len));
      else
        cp = base + conn_a->offset + header_bytes;
    }
    if (st == PIOLA_OK) {
      conn_v = malloc((size_t)(conn_len > 0 ? conn_len : 1) * 8);
      if (!conn_v)
        st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
      else
        memcpy(conn_v, cp, (size_t)conn_len * 8);
    }
    for (int64_t k = 0; st == PIOLA_OK && k < conn_len; ++k)
      if (conn_v[k] < 0 || conn_v[k] >= f->point_count)
        st = PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: connectivity entry %lld out of range", path,
                        (long long)k);
  }
  /* per-cell scalar fields */
  for (int i = 0; st == PIOLA_OK && i < na; ++i) {
    vtu_array *a = &arrays[i];
    if (a->section != 1 || a->components != 1 || strcmp(a->type, "Float64") != 0 || !a->name[0])
      continue;
    const char *vp = NULL;
    uint64_t bytes = 0;
    if (a->offset > (uint64_t)(end - base) ||
        (uint64_t)(end - base) - a->offset < (uint64_t)header_bytes) {
      st = PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: array '%s' lies past the end of the file", path,
                      a->name);
      break;
    }
    memcpy(&bytes, base + a->offset, (size_t)header_bytes);
    if (bytes != 8 * (uint64_t)f->cell_count ||
        bytes > (uint64_t)(end - base) - a->offset - header_bytes) {
      st = PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: cell field '%s' has the wrong size", path, a->name);
      break;
    }
    vp = base + a->offset + header_bytes;
    render_cell_field *grown = realloc(f->fields, (size_t)(f->field_count + 1) * sizeof *grown);
    double *values = malloc((size_t)(f->cell_count > 0 ? f->cell_count : 1) * sizeof *values);
    if (grown) f->fields = grown;
    if (!grown || !values) {
      free(values);
      st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
      break;
    }
    memcpy(values, vp, (size_t)f->cell_count * 8);
    memcpy(f->fields[f->field_count].name, a->name, sizeof a->name);
    f->fields[f->field_count++].values = values;
  }
  if (st == PIOLA_OK) st = build_surface(f, conn_v, offsets, type_v, path);
  if (st == PIOLA_OK) {
    f->cell_inverted = calloc((size_t)(f->cell_count > 0 ? f->cell_count : 1), 1);
    if (!f->cell_inverted) st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
  }
  if (st == PIOLA_OK) {
    const double *inv = NULL;
    for (int i = 0; i < f->field_count; ++i)
      if (strcmp(f->fields[i].name, "inverted") == 0) inv = f->fields[i].values;
    for (int64_t c = 0; c < f->cell_count; ++c) {
      bool flag = inv ? inv[c] > 0.5
                      : (type_v[c] == 10 && signed_volume(f->points, conn_v + offsets[c] - 4) < 0);
      f->cell_inverted[c] = flag;
      f->inverted_count += flag;
    }
  }
  /* the tets (for stresses) and the rest positions, when the frame has displacements */
  if (st == PIOLA_OK) {
    int64_t nt = 0;
    for (int64_t c = 0; c < f->cell_count; ++c) nt += type_v[c] == 10;
    f->tets = malloc(4 * (size_t)(nt > 0 ? nt : 1) * sizeof *f->tets);
    f->tet_cell = malloc((size_t)(nt > 0 ? nt : 1) * sizeof *f->tet_cell);
    if (!f->tets || !f->tet_cell)
      st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
    for (int64_t c = 0; st == PIOLA_OK && c < f->cell_count; ++c)
      if (type_v[c] == 10) {
        for (int k = 0; k < 4; ++k)
          f->tets[4 * (size_t)f->tet_count + (size_t)k] = (int32_t)conn_v[offsets[c] - 4 + k];
        f->tet_cell[f->tet_count++] = (int32_t)c;
      }
  }
  for (int i = 0; st == PIOLA_OK && i < na; ++i) {
    vtu_array *a = &arrays[i];
    if (a->section != 0 || a->components != 3 || strcmp(a->type, "Float64") != 0 ||
        strcmp(a->name, "displacement") != 0)
      continue;
    const char *vp = NULL;
    uint64_t bytes = 0;
    if (a->offset > (uint64_t)(end - base) ||
        (uint64_t)(end - base) - a->offset < (uint64_t)header_bytes) {
      st = PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: array '%s' lies past the end of the file", path,
                      a->name);
      break;
    }
    memcpy(&bytes, base + a->offset, (size_t)header_bytes);
    if (bytes != 24 * (uint64_t)f->point_count ||
        bytes > (uint64_t)(end - base) - a->offset - header_bytes) {
      st = PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: point field '%s' has the wrong size", path, a->name);
      break;
    }
    vp = base + a->offset + header_bytes;
    f->rest = malloc(3 * (size_t)(f->point_count > 0 ? f->point_count : 1) * sizeof *f->rest);
    if (!f->rest) {
      st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
      break;
    }
    memcpy(f->rest, vp, 3 * (size_t)f->point_count * sizeof *f->rest);
    for (int64_t k = 0; k < 3 * f->point_count; ++k) f->rest[k] = f->points[k] - f->rest[k];
  }
  free(offsets), free(type_v), free(conn_v);
#undef BLOCK
  return st;
}

piola_status piola_render_frame_read(const char *path, piola_render_frame **out) {
  if (!path || !out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "render frame: NULL argument");
  *out = NULL;
  FILE *fp = fopen(path, "rb");
  if (!fp) return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: cannot open", path);
  char *buf = NULL;
  long size = -1;
  if (fseek(fp, 0, SEEK_END) == 0) size = ftell(fp);
  if (size >= 0 && fseek(fp, 0, SEEK_SET) == 0) buf = malloc((size_t)size + 1);
  if (!buf || fread(buf, 1, (size_t)size, fp) != (size_t)size) {
    fclose(fp);
    free(buf);
    return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: cannot read", path);
  }
  fclose(fp);
  buf[size] = '\0';
  piola_render_frame *f = calloc(1, sizeof *f);
  if (!f) {
    free(buf);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
  }
  piola_status st = parse(f, buf, (size_t)size, path);
  free(buf);
  if (st != PIOLA_OK) {
    piola_render_frame_destroy(f);
    return st;
  }
  *out = f;
  return PIOLA_OK;
}

static const double *field(const piola_render_frame *f, const char *name) {
  for (int i = 0; i < f->field_count; ++i)
    if (strcmp(f->fields[i].name, name) == 0) return f->fields[i].values;
  return NULL;
}

bool piola_render_frame_has_field(const piola_render_frame *f, const char *name) {
  return f && name && field(f, name) != NULL;
}

int32_t piola_render_frame_inverted_count(const piola_render_frame *f) {
  return f ? f->inverted_count : 0;
}

void piola_render_frame_bounds(const piola_render_frame *f, piola_vec3 *lo, piola_vec3 *hi) {
  vec3 a = {INFINITY, INFINITY, INFINITY}, b = {-INFINITY, -INFINITY, -INFINITY};
  for (int64_t i = 0; f && i < f->point_count; ++i) {
    const double *p = f->points + 3 * i;
    a.x = fmin(a.x, p[0]), a.y = fmin(a.y, p[1]), a.z = fmin(a.z, p[2]);
    b.x = fmax(b.x, p[0]), b.y = fmax(b.y, p[1]), b.z = fmax(b.z, p[2]);
  }
  if (lo) *lo = a;
  if (hi) *hi = b;
}

piola_status piola_render_frame_mesh(const piola_render_frame *cf, const char *value_field,
                                     double time, piola_render_mesh *out) {
  if (!cf || !out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "render frame: NULL argument");
  piola_render_frame *f = (piola_render_frame *)cf; /* the per-face arrays are a cache */
  const double *values = NULL;
  if (value_field) {
    values = field(f, value_field);
    if (!values)
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "frame has no cell field '%s'", value_field);
  }
  const double *solid = field(f, "solid");
  size_t n = (size_t)(f->surface_count > 0 ? f->surface_count : 1);
  if (!f->face_inverted) {
    f->face_inverted = malloc(n);
    f->face_values = malloc(n * sizeof *f->face_values);
    f->face_parts = malloc(n * sizeof *f->face_parts);
    if (!f->face_inverted || !f->face_values || !f->face_parts)
      return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "render frame: out of memory");
  }
  for (int32_t t = 0; t < f->surface_count; ++t) {
    int32_t c = f->surface_cell[t];
    f->face_inverted[t] = f->cell_inverted[c];
    f->face_values[t] = values ? values[c] : 0;
    double s = solid ? solid[c] : 0;
    f->face_parts[t] = isfinite(s) && fabs(s) < 1e9 ? (int32_t)s : 0;
  }
  out->vertex_count = (int32_t)f->point_count;
  out->positions = f->points;
  out->triangle_count = f->surface_count;
  out->triangles = f->surface;
  out->inverted = f->face_inverted;
  out->values = values ? f->face_values : NULL;
  out->parts = f->face_parts;
  out->time = time;
  return PIOLA_OK;
}
