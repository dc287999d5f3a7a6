/* OFF reader (surfaces): "OFF", "nv nf ne", nv lines "x y z", nf lines "n i1 .. in"
 * (0-based; any trailing colour values on a face line are ignored). Polygons are
 * fan-triangulated. '#' comments. The counts may follow OFF on the same line. */
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "io/mesh_io_internal.h"
#include "io/text_scanner.h"

static piola_status parse(text_scanner *s, piola_tri_mesh *out) {
  if (!piola__scan_accept(s, "OFF", 0)) return piola__scan_error(s, PIOLA_ERROR_PARSE, "not an OFF file: expected 'OFF'");
  int64_t nv, nf, ne;
  PIOLA_TRY(piola__scan_int64(s, &nv, "vertex count"));
  PIOLA_TRY(piola__scan_int64(s, &nf, "face count"));
  PIOLA_TRY(piola__scan_int64(s, &ne, "edge count"));
  if (nv < 0 || nv > INT32_MAX || (uint64_t)nv > (uint64_t)(s->end - s->p) / 6)
    return piola__scan_error(s, PIOLA_ERROR_PARSE, "vertex count %lld does not fit the file", (long long)nv);
  if (nf < 0 || nf > INT32_MAX / 4 || (uint64_t)nf > (uint64_t)(s->end - s->p) / 8)
    return piola__scan_error(s, PIOLA_ERROR_PARSE, "face count %lld does not fit the file", (long long)nf);
  out->positions = malloc((size_t)nv * 3 * sizeof(double) + 1);
  if (!out->positions) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", s->name);
  out->vertex_count = (int32_t)nv;
  for (int64_t i = 0; i < nv; ++i) {
    for (int k = 0; k < 3; ++k) PIOLA_TRY(piola__scan_double(s, &out->positions[3 * i + k], "coordinate"));
    piola__scan_next_line(s);
  }
  size_t capacity = 0, count = 0;
  for (int64_t f = 0; f < nf; ++f) {
    int64_t n;
    PIOLA_TRY(piola__scan_int64(s, &n, "corner count"));
    if (n < 3 || n > 1000000 || (uint64_t)n > (uint64_t)(s->end - s->p) / 2)
      return piola__scan_error(s, PIOLA_ERROR_PARSE, "face %lld has %lld corners", (long long)f, (long long)n);
    int32_t first = 0, previous = 0;
    for (int64_t k = 0; k < n; ++k) {
      int64_t v;
      PIOLA_TRY(piola__scan_int64(s, &v, "vertex index"));
      if (v < 0 || v >= nv)
        return piola__scan_error(s, PIOLA_ERROR_PARSE, "face %lld: vertex %lld out of range [0, %lld)", (long long)f,
                                 (long long)v, (long long)nv);
      if (k == 0) first = (int32_t)v;
      else if (k >= 2) {
        if (count >= INT32_MAX) return piola__scan_error(s, PIOLA_ERROR_UNSUPPORTED, "too many faces");
        if (piola__grow((void **)&out->triangles, &capacity, count + 1, 3 * sizeof(int32_t)))
          return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", s->name);
        out->triangles[3 * count] = first;
        out->triangles[3 * count + 1] = previous;
        out->triangles[3 * count + 2] = (int32_t)v;
        out->triangle_count = (int32_t)++count;
      }
      previous = (int32_t)v;
    }
    piola__scan_next_line(s);
  }
  return piola__tri_mesh_finish(out, s->name);
}

piola_status piola__read_off_mem(const char *name, const char *data, size_t size, piola_tri_mesh *out) {
  memset(out, 0, sizeof *out);
  text_scanner s;
  piola__scanner_init(&s, name, data, size, '#');
  piola_status status = parse(&s, out);
  if (status != PIOLA_OK) piola_tri_mesh_free(out);
  return status;
}
