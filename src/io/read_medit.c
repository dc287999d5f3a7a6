/* Medit .mesh reader (ASCII).
 *
 * Keywords: MeshVersionFormatted, Dimension (must be 3), Vertices (x y z ref), Tetrahedra
 * (a b c d ref, 1-based; ref becomes the tet region), End (optional: files may just stop).
 * Other sections with a count (Triangles, Edges, Quadrilaterals, Hexahedra, Corners, ...)
 * are skipped. Sections may be empty; keywords and lines may be indented; '#' comments.
 * Vertices that no tet uses are kept, so indices match the file. */
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "io/mesh_io_internal.h"
#include "io/text_scanner.h"
#include "mesh/mesh_internal.h"

typedef struct section_kind {
  const char *name;
  int values; /* numbers per entry */
} section_kind;

/* Sections we skip, with the numbers per entry. */
static const section_kind skipped[] = {
    {"Triangles", 4},      {"Edges", 3},          {"Quadrilaterals", 5}, {"Hexahedra", 9},
    {"Prisms", 7},         {"Pyramids", 6},       {"Corners", 1},        {"RequiredVertices", 1},
    {"Ridges", 1},         {"RequiredEdges", 1},  {"RequiredTriangles", 1}, {"Normals", 3},
    {"Tangents", 3},       {"NormalAtVertices", 2}, {"TangentAtVertices", 2}, {"Identifier", 0},
};

static piola_status parse(text_scanner *s, piola_tet_mesh *out, int32_t **lines) {
  int have_vertices = 0, have_tets = 0;
  while (piola__scan_skip(s)) {
    const char *tok;
    size_t len;
    PIOLA_TRY(piola__scan_token(s, &tok, &len, "a keyword"));
    char key[40];
    if (len >= sizeof key)
      return piola__scan_error(s, PIOLA_ERROR_PARSE, "unknown keyword '%.30s...'", tok);
    memcpy(key, tok, len);
    key[len] = '\0';
    if (strcmp(key, "End") == 0) break;
    if (strcmp(key, "MeshVersionFormatted") == 0) {
      int64_t v;
      PIOLA_TRY(piola__scan_int64(s, &v, "version"));
      if (v < 1 || v > 2) return piola__scan_error(s, PIOLA_ERROR_UNSUPPORTED, "MeshVersionFormatted %lld not supported", (long long)v);
    } else if (strcmp(key, "Dimension") == 0) {
      int64_t d;
      PIOLA_TRY(piola__scan_int64(s, &d, "dimension"));
      if (d != 3) return piola__scan_error(s, PIOLA_ERROR_UNSUPPORTED, "Dimension %lld, expected 3", (long long)d);
    } else if (strcmp(key, "Vertices") == 0) {
      if (have_vertices) return piola__scan_error(s, PIOLA_ERROR_PARSE, "second Vertices section");
      int64_t n;
      PIOLA_TRY(piola__scan_int64(s, &n, "vertex count"));
      if (n < 0 || n > INT32_MAX || (uint64_t)n > (uint64_t)(s->end - s->p) / 8)
        return piola__scan_error(s, PIOLA_ERROR_PARSE, "vertex count %lld does not fit the file", (long long)n);
      out->positions = malloc((size_t)n * 3 * sizeof(double) + 1);
      if (!out->positions) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", s->name);
      out->vertex_count = (int32_t)n;
      for (int64_t i = 0; i < n; ++i) {
        double ref;
        for (int k = 0; k < 3; ++k) PIOLA_TRY(piola__scan_double(s, &out->positions[3 * i + k], "coordinate"));
        PIOLA_TRY(piola__scan_double(s, &ref, "vertex reference"));
      }
      have_vertices = 1;
    } else if (strcmp(key, "Tetrahedra") == 0) {
      if (have_tets) return piola__scan_error(s, PIOLA_ERROR_PARSE, "second Tetrahedra section");
      if (!have_vertices) return piola__scan_error(s, PIOLA_ERROR_PARSE, "Tetrahedra before Vertices");
      int64_t n;
      PIOLA_TRY(piola__scan_int64(s, &n, "tet count"));
      if (n < 0 || n > INT32_MAX || (uint64_t)n > (uint64_t)(s->end - s->p) / 10)
        return piola__scan_error(s, PIOLA_ERROR_PARSE, "tet count %lld does not fit the file", (long long)n);
      out->tets = malloc((size_t)n * 4 * sizeof(int32_t) + 1);
      out->tet_regions = malloc((size_t)n * sizeof(int32_t) + 1);
      *lines = malloc((size_t)n * sizeof(int32_t) + 1);
      if (!out->tets || !out->tet_regions || !*lines) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", s->name);
      out->tet_count = (int32_t)n;
      for (int64_t t = 0; t < n; ++t) {
        piola__scan_skip(s);
        (*lines)[t] = (int32_t)s->line;
        for (int k = 0; k < 4; ++k) {
          int64_t v;
          PIOLA_TRY(piola__scan_int64(s, &v, "vertex index"));
          if (v < 1 || v > out->vertex_count)
            /* numbered as the checks after reading number tets: from 0, with the file's */
            return piola__scan_error(s, PIOLA_ERROR_PARSE,
                                     "tet %lld (element %lld in the file): vertex %lld out of range [1, %d]",
                                     (long long)t, (long long)(t + 1), (long long)v, (int)out->vertex_count);
          out->tets[4 * t + k] = (int32_t)(v - 1);
        }
        PIOLA_TRY(piola__scan_int32(s, &out->tet_regions[t], "tet reference"));
      }
      have_tets = 1;
    } else {
      int values = -1;
      for (size_t i = 0; i < sizeof skipped / sizeof skipped[0]; ++i)
        if (strcmp(key, skipped[i].name) == 0) values = skipped[i].values;
      if (values < 0) return piola__scan_error(s, PIOLA_ERROR_UNSUPPORTED, "unknown keyword '%s'", key);
      if (values == 0) { /* Identifier "text" */
        piola__scan_next_line(s);
        continue;
      }
      int64_t n;
      PIOLA_TRY(piola__scan_int64(s, &n, "entry count"));
      if (n < 0 || (uint64_t)n > (uint64_t)(s->end - s->p) / (2 * (uint64_t)values))
        return piola__scan_error(s, PIOLA_ERROR_PARSE, "%s count %lld does not fit the file", key, (long long)n);
      for (int64_t i = 0; i < n * values; ++i) {
        double ignored;
        PIOLA_TRY(piola__scan_double(s, &ignored, key));
      }
    }
  }
  if (!have_vertices) return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: no Vertices section", s->name);
  if (!have_tets) return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: no Tetrahedra section (the mesh has no tetrahedra)", s->name);
  return piola__tet_mesh_finish(out, s->name, *lines);
}

piola_status piola__read_medit_mem(const char *name, const char *data, size_t size, piola_tet_mesh *out) {
  memset(out, 0, sizeof *out);
  text_scanner s;
  piola__scanner_init(&s, name, data, size, '#');
  int32_t *lines = NULL;
  piola_status status = parse(&s, out, &lines);
  free(lines);
  if (status != PIOLA_OK) piola_tet_mesh_free(out);
  return status;
}
