/* TetGen .node/.ele reader.
 *
 * .node: "N dim nattr nbdmarker" then N lines "id x y z [attributes] [marker]".
 * .ele:  "T nodes_per_tet nattr" then T lines "id n1 n2 n3 n4 [n5..n10] [attributes]".
 * The index base is the first node id (TetGen writes 0- or 1-based files); node ids must
 * then run consecutively. 10-node tets keep their four corners. The first element
 * attribute, rounded, becomes the tet region. '#' starts a comment anywhere. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "io/mesh_io_internal.h"
#include "io/text_scanner.h"
#include "mesh/mesh_internal.h"

static piola_status read_nodes(text_scanner *s, piola_tet_mesh *out, int64_t *base) {
  int64_t n, dim, nattr, nmarker;
  PIOLA_TRY(piola__scan_int64(s, &n, "node count"));
  PIOLA_TRY(piola__scan_int64(s, &dim, "dimension"));
  PIOLA_TRY(piola__scan_int64(s, &nattr, "attribute count"));
  PIOLA_TRY(piola__scan_int64(s, &nmarker, "boundary marker count"));
  if (dim != 3) return piola__scan_error(s, PIOLA_ERROR_UNSUPPORTED, "dimension %lld, expected 3", (long long)dim);
  if (nattr < 0 || nattr > 1000 || nmarker < 0 || nmarker > 1)
    return piola__scan_error(s, PIOLA_ERROR_PARSE, "bad attribute (%lld) or marker (%lld) count", (long long)nattr,
                             (long long)nmarker);
  /* Every node needs at least 4 numbers of 2 bytes each. */
  if (n <= 0 || n > INT32_MAX || (uint64_t)n > (uint64_t)(s->end - s->p) / 8)
    return piola__scan_error(s, PIOLA_ERROR_PARSE, "node count %lld does not fit the file", (long long)n);
  out->positions = malloc((size_t)n * 3 * sizeof(double));
  if (!out->positions) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", s->name);
  out->vertex_count = (int32_t)n;
  for (int64_t i = 0; i < n; ++i) {
    int64_t id;
    PIOLA_TRY(piola__scan_int64(s, &id, "node id"));
    if (i == 0) *base = id;
    if (id != *base + i)
      return piola__scan_error(s, PIOLA_ERROR_PARSE, "node id %lld out of sequence, expected %lld", (long long)id,
                               (long long)(*base + i));
    for (int k = 0; k < 3; ++k) PIOLA_TRY(piola__scan_double(s, &out->positions[3 * i + k], "coordinate"));
    for (int64_t k = 0; k < nattr + nmarker; ++k) {
      double ignored;
      PIOLA_TRY(piola__scan_double(s, &ignored, "node attribute or marker"));
    }
    if (piola__scan_more_on_line(s)) return piola__scan_error(s, PIOLA_ERROR_PARSE, "extra values after node %lld", (long long)id);
  }
  return PIOLA_OK;
}

static piola_status read_tets(text_scanner *s, piola_tet_mesh *out, int64_t base, int32_t **lines) {
  int64_t n, npe, nattr;
  PIOLA_TRY(piola__scan_int64(s, &n, "tet count"));
  PIOLA_TRY(piola__scan_int64(s, &npe, "nodes per tet"));
  PIOLA_TRY(piola__scan_int64(s, &nattr, "attribute count"));
  if (npe != 4 && npe != 10)
    return piola__scan_error(s, PIOLA_ERROR_UNSUPPORTED, "%lld nodes per tet, expected 4 or 10", (long long)npe);
  if (nattr < 0 || nattr > 1000) return piola__scan_error(s, PIOLA_ERROR_PARSE, "bad attribute count %lld", (long long)nattr);
  if (n == 0)
    return piola__scan_error(s, PIOLA_ERROR_PARSE, "tet count 0: the mesh has no tetrahedra");
  if (n < 0 || n > INT32_MAX || (uint64_t)n > (uint64_t)(s->end - s->p) / 10)
    return piola__scan_error(s, PIOLA_ERROR_PARSE, "tet count %lld does not fit the file", (long long)n);
  out->tets = malloc((size_t)n * 4 * sizeof(int32_t));
  *lines = malloc((size_t)n * sizeof(int32_t));
  if (!*lines) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", s->name);
  if (nattr > 0) out->tet_regions = malloc((size_t)n * sizeof(int32_t));
  if (!out->tets || (nattr > 0 && !out->tet_regions))
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", s->name);
  out->tet_count = (int32_t)n;
  int64_t first = 0;
  for (int64_t t = 0; t < n; ++t) {
    int64_t id;
    PIOLA_TRY(piola__scan_int64(s, &id, "tet id"));
    (*lines)[t] = (int32_t)s->line;
    if (t == 0) first = id;
    if (id != first + t)
      return piola__scan_error(s, PIOLA_ERROR_PARSE, "tet id %lld out of sequence, expected %lld", (long long)id,
                               (long long)(first + t));
    for (int64_t k = 0; k < npe; ++k) {
      int64_t v;
      PIOLA_TRY(piola__scan_int64(s, &v, "node index"));
      v -= base;
      if (v < 0 || v >= out->vertex_count)
        return piola__scan_error(s, PIOLA_ERROR_PARSE, "tet %lld: node %lld out of range [%lld, %lld]", (long long)id,
                                 (long long)(v + base), (long long)base, (long long)(base + out->vertex_count - 1));
      if (k < 4) out->tets[4 * t + k] = (int32_t)v;
    }
    for (int64_t k = 0; k < nattr; ++k) {
      double a;
      PIOLA_TRY(piola__scan_double(s, &a, "tet attribute"));
      if (k == 0) {
        if (!(fabs(a) < 2e9)) return piola__scan_error(s, PIOLA_ERROR_PARSE, "tet attribute %g out of range", a);
        out->tet_regions[t] = (int32_t)lround(a);
      }
    }
    if (piola__scan_more_on_line(s)) return piola__scan_error(s, PIOLA_ERROR_PARSE, "extra values after tet %lld", (long long)id);
  }
  return PIOLA_OK;
}

piola_status piola__read_tetgen_mem(const char *node_name, const char *node_data, size_t node_size,
                                    const char *ele_name, const char *ele_data, size_t ele_size,
                                    piola_tet_mesh *out) {
  memset(out, 0, sizeof *out);
  text_scanner s;
  int64_t base = 0;
  int32_t *lines = NULL;
  piola__scanner_init(&s, node_name, node_data, node_size, '#');
  piola_status status = read_nodes(&s, out, &base);
  if (status == PIOLA_OK) {
    piola__scanner_init(&s, ele_name, ele_data, ele_size, '#');
    status = read_tets(&s, out, base, &lines);
  }
  if (status == PIOLA_OK) status = piola__tet_mesh_finish(out, ele_name, lines);
  free(lines);
  if (status != PIOLA_OK) piola_tet_mesh_free(out);
  return status;
}
