/* STL reader (surfaces), ASCII and binary.
 *
 * Binary: 80-byte header, uint32 triangle count, 50-byte records (normal, 3 corners as
 * float32, uint16 attribute); recognised when the size is exactly 84 + 50 * count, which
 * also catches binary files whose header starts with "solid". ASCII: solid / facet normal /
 * outer loop / vertex x y z (x3) / endloop / endfacet / endsolid. STL repeats corners per
 * triangle; corners with identical coordinates are welded into one vertex. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "io/mesh_io_internal.h"
#include "io/text_scanner.h"

static piola_status read_binary(const char *name, const unsigned char *data, size_t size, piola_tri_mesh *out) {
  uint32_t n;
  memcpy(&n, data + 80, 4);
  out->positions = malloc((size_t)n * 9 * sizeof(double) + 1);
  out->triangles = malloc((size_t)n * 3 * sizeof(int32_t) + 1);
  if (!out->positions || !out->triangles) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", name);
  (void)size;
  for (uint32_t t = 0; t < n; ++t) {
    const unsigned char *rec = data + 84 + 50 * (size_t)t;
    for (int k = 0; k < 9; ++k) {
      float f;
      memcpy(&f, rec + 12 + 4 * k, 4);
      if (!isfinite(f))
        return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: byte %zu: triangle %u has a non-finite coordinate", name,
                          (size_t)(84 + 50 * (size_t)t + 12 + 4 * (size_t)k), t);
      out->positions[9 * (size_t)t + k] = f;
    }
    for (int k = 0; k < 3; ++k) out->triangles[3 * (size_t)t + k] = (int32_t)(3 * t + (uint32_t)k);
  }
  out->vertex_count = (int32_t)(3 * n);
  out->triangle_count = (int32_t)n;
  return PIOLA_OK;
}

static piola_status expect_word(text_scanner *s, const char *word) {
  if (!piola__scan_accept(s, word, 1)) return piola__scan_error(s, PIOLA_ERROR_PARSE, "expected '%s'", word);
  return PIOLA_OK;
}

static piola_status read_ascii(text_scanner *s, piola_tri_mesh *out) {
  PIOLA_TRY(expect_word(s, "solid"));
  piola__scan_next_line(s); /* the solid's name */
  size_t capacity = 0, count = 0, vcap = 0;
  while (!piola__scan_accept(s, "endsolid", 1)) {
    if (!piola__scan_skip(s)) return piola__scan_error(s, PIOLA_ERROR_PARSE, "unexpected end of file, expected 'endsolid'");
    PIOLA_TRY(expect_word(s, "facet"));
    PIOLA_TRY(expect_word(s, "normal"));
    for (int k = 0; k < 3; ++k) {
      double ignored;
      PIOLA_TRY(piola__scan_double(s, &ignored, "normal"));
    }
    PIOLA_TRY(expect_word(s, "outer"));
    PIOLA_TRY(expect_word(s, "loop"));
    if (count >= INT32_MAX / 3) return piola__scan_error(s, PIOLA_ERROR_UNSUPPORTED, "too many facets");
    if (piola__grow((void **)&out->positions, &vcap, 3 * count + 3, 3 * sizeof(double)) ||
        piola__grow((void **)&out->triangles, &capacity, count + 1, 3 * sizeof(int32_t)))
      return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", s->name);
    for (int c = 0; c < 3; ++c) {
      PIOLA_TRY(expect_word(s, "vertex"));
      for (int k = 0; k < 3; ++k) PIOLA_TRY(piola__scan_double(s, &out->positions[9 * count + 3 * (size_t)c + k], "coordinate"));
      out->triangles[3 * count + (size_t)c] = (int32_t)(3 * count + (size_t)c);
    }
    PIOLA_TRY(expect_word(s, "endloop"));
    PIOLA_TRY(expect_word(s, "endfacet"));
    ++count;
    out->triangle_count = (int32_t)count;
    out->vertex_count = (int32_t)(3 * count);
  }
  return PIOLA_OK;
}

piola_status piola__read_stl_mem(const char *name, const char *data, size_t size, piola_tri_mesh *out) {
  memset(out, 0, sizeof *out);
  piola_status status;
  uint32_t n = 0;
  if (size >= 84) memcpy(&n, data + 80, 4);
  if (size >= 84 && (size - 84) % 50 == 0 && (size - 84) / 50 == n) {
    status = read_binary(name, (const unsigned char *)data, size, out);
  } else {
    text_scanner s;
    piola__scanner_init(&s, name, data, size, 0);
    if (!piola__scan_accept(&s, "solid", 1)) {
      status = PIOLA_FAIL(PIOLA_ERROR_PARSE,
                          "%s: neither ASCII STL (no 'solid') nor binary STL (size %zu is not 84 + 50 x %u triangles)",
                          name, size, n);
    } else {
      piola__scanner_init(&s, name, data, size, 0);
      status = read_ascii(&s, out);
    }
  }
  if (status == PIOLA_OK) status = piola__weld_vertices(out, name);
  if (status == PIOLA_OK) status = piola__tri_mesh_finish(out, name);
  if (status != PIOLA_OK) piola_tri_mesh_free(out);
  return status;
}
