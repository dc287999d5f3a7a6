/* Wavefront OBJ reader (surfaces).
 *
 * Only "v x y z [w]" and "f" lines matter. Face corners may be v, v/vt, v//vn or v/vt/vn;
 * the vertex index is the integer before the first '/'. Indices are 1-based, or negative
 * (relative to the vertices read so far). Polygons are fan-triangulated from their first
 * corner. Other statements (vt, vn, o, g, s, usemtl, mtllib, l, p, ...) are ignored. */
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "io/mesh_io_internal.h"
#include "io/text_scanner.h"

typedef struct obj_reader {
  text_scanner s;
  double *positions;
  size_t vertex_count, vertex_capacity;
  int32_t *triangles;
  size_t triangle_count, triangle_capacity;
} obj_reader;

static piola_status face_corner(obj_reader *r, int32_t *index) {
  text_scanner *s = &r->s;
  const char *p = s->p, *end = s->end;
  int negative = 0;
  if (p < end && (*p == '-' || *p == '+')) {
    negative = *p == '-';
    ++p;
  }
  int64_t v = 0;
  const char *digits = p;
  while (p < end && *p >= '0' && *p <= '9' && v < ((int64_t)1 << 40)) v = v * 10 + (*p++ - '0');
  if (p == digits) return piola__scan_error(s, PIOLA_ERROR_PARSE, "bad face corner (expected a vertex index)");
  if (negative) v = (int64_t)r->vertex_count - v;
  else v -= 1;
  if (v < 0 || v >= (int64_t)r->vertex_count)
    return piola__scan_error(s, PIOLA_ERROR_PARSE, "face vertex index %s%lld out of range (%zu vertices so far)",
                             negative ? "-" : "", (long long)(negative ? (int64_t)r->vertex_count - v : v + 1),
                             r->vertex_count);
  /* Skip /vt/vn parts. */
  while (p < end && (*p == '/' || (*p >= '0' && *p <= '9') || *p == '-')) ++p;
  if (p < end && !(*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n' || *p == '#'))
    return piola__scan_error(s, PIOLA_ERROR_PARSE, "bad face corner");
  s->p = p;
  *index = (int32_t)v;
  return PIOLA_OK;
}

static piola_status parse(obj_reader *r) {
  text_scanner *s = &r->s;
  while (piola__scan_skip(s)) {
    const char *tok;
    size_t len;
    PIOLA_TRY(piola__scan_token(s, &tok, &len, "a statement"));
    if (len == 1 && tok[0] == 'v') {
      if (r->vertex_count >= INT32_MAX) return piola__scan_error(s, PIOLA_ERROR_UNSUPPORTED, "too many vertices");
      if (piola__grow((void **)&r->positions, &r->vertex_capacity, r->vertex_count + 1, 3 * sizeof(double)))
        return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", s->name);
      for (int k = 0; k < 3; ++k) PIOLA_TRY(piola__scan_double(s, &r->positions[3 * r->vertex_count + k], "coordinate"));
      ++r->vertex_count;
      piola__scan_next_line(s); /* optional w */
    } else if (len == 1 && tok[0] == 'f') {
      int32_t first = -1, previous = -1;
      int corners = 0;
      while (piola__scan_more_on_line(s)) {
        int32_t v = 0;
        PIOLA_TRY(face_corner(r, &v));
        if (corners == 0) first = v;
        else if (corners >= 2) {
          if (r->triangle_count >= INT32_MAX) return piola__scan_error(s, PIOLA_ERROR_UNSUPPORTED, "too many faces");
          if (piola__grow((void **)&r->triangles, &r->triangle_capacity, r->triangle_count + 1, 3 * sizeof(int32_t)))
            return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", s->name);
          int32_t *t = r->triangles + 3 * r->triangle_count++;
          t[0] = first;
          t[1] = previous;
          t[2] = v;
        }
        previous = v;
        ++corners;
      }
      if (corners < 3) return piola__scan_error(s, PIOLA_ERROR_PARSE, "face with %d corners, expected at least 3", corners);
    } else {
      piola__scan_next_line(s);
    }
  }
  return PIOLA_OK;
}

piola_status piola__read_obj_mem(const char *name, const char *data, size_t size, piola_tri_mesh *out) {
  memset(out, 0, sizeof *out);
  obj_reader r;
  memset(&r, 0, sizeof r);
  piola__scanner_init(&r.s, name, data, size, '#');
  piola_status status = parse(&r);
  out->positions = r.positions;
  out->vertex_count = (int32_t)r.vertex_count;
  out->triangles = r.triangles;
  out->triangle_count = (int32_t)r.triangle_count;
  if (status == PIOLA_OK) status = piola__tri_mesh_finish(out, name);
  if (status != PIOLA_OK) piola_tri_mesh_free(out);
  return status;
}
