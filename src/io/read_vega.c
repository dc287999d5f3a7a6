/* Vega FEM .veg reader.
 *
 * Sections start with '*': *VERTICES ("N 3 0 0", then "id x y z"), *ELEMENTS (a type line,
 * "N nodes_per_element 0", then "id n1..nk", 1-based), *MATERIAL name ("ENU, density, E,
 * nu"), *SET name (comma-separated element ids, trailing comma allowed), *REGION
 * ("setName, materialName" lines; the set allElements is implicit). Only TET elements are
 * read: CUBIC (hexahedra) and others are refused. *INCLUDE is refused. Other sections are
 * skipped. Commas count as whitespace. tet_regions holds the material index per tet (-1:
 * no region covers the tet). Vertex and element ids must run 1, 2, 3, ... */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "io/mesh_io_internal.h"
#include "io/text_scanner.h"
#include "mesh/mesh_internal.h"

typedef struct vega_set {
  char name[64];
  int32_t *ids;
  int32_t *id_lines; /* line of each id, to report one out of range there */
  size_t count, capacity, line_capacity;
} vega_set;

typedef struct vega_region {
  char set[64];
  char material[64];
  long line;
} vega_region;

typedef struct vega_reader {
  text_scanner s;
  int32_t *lines; /* per tet */
  vega_set *sets;
  size_t set_count, set_capacity;
  vega_region *regions;
  size_t region_count, region_capacity;
  piola_vega_material *materials;
  size_t material_count, material_capacity;
} vega_reader;

static int next_is_keyword(text_scanner *s) { return piola__scan_skip(s) && *s->p == '*'; }

static piola_status read_name(text_scanner *s, char *name, const char *what) {
  const char *tok;
  size_t len;
  PIOLA_TRY(piola__scan_token(s, &tok, &len, what));
  if (len >= 64) return piola__scan_error(s, PIOLA_ERROR_PARSE, "%s is longer than 63 characters", what);
  memcpy(name, tok, len);
  name[len] = '\0';
  return PIOLA_OK;
}

static piola_status read_vertices(vega_reader *r, piola_tet_mesh *out) {
  text_scanner *s = &r->s;
  if (out->positions) return piola__scan_error(s, PIOLA_ERROR_PARSE, "second *VERTICES section");
  int64_t n, dim, a, b;
  PIOLA_TRY(piola__scan_int64(s, &n, "vertex count"));
  PIOLA_TRY(piola__scan_int64(s, &dim, "dimension"));
  PIOLA_TRY(piola__scan_int64(s, &a, "vertex header value"));
  PIOLA_TRY(piola__scan_int64(s, &b, "vertex header value"));
  if (dim != 3) return piola__scan_error(s, PIOLA_ERROR_UNSUPPORTED, "dimension %lld, expected 3", (long long)dim);
  if (n <= 0 || n > INT32_MAX || (uint64_t)n > (uint64_t)(s->end - s->p) / 8)
    return piola__scan_error(s, PIOLA_ERROR_PARSE, "vertex count %lld does not fit the file", (long long)n);
  out->positions = malloc((size_t)n * 3 * sizeof(double));
  if (!out->positions) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", s->name);
  out->vertex_count = (int32_t)n;
  for (int64_t i = 0; i < n; ++i) {
    int64_t id;
    PIOLA_TRY(piola__scan_int64(s, &id, "vertex id"));
    if (id != i + 1)
      return piola__scan_error(s, PIOLA_ERROR_PARSE, "vertex id %lld out of sequence, expected %lld", (long long)id,
                               (long long)(i + 1));
    for (int k = 0; k < 3; ++k) PIOLA_TRY(piola__scan_double(s, &out->positions[3 * i + k], "coordinate"));
  }
  return PIOLA_OK;
}

static piola_status read_elements(vega_reader *r, piola_tet_mesh *out) {
  text_scanner *s = &r->s;
  if (out->tets) return piola__scan_error(s, PIOLA_ERROR_PARSE, "second *ELEMENTS section");
  if (!out->positions) return piola__scan_error(s, PIOLA_ERROR_PARSE, "*ELEMENTS before *VERTICES");
  char type[64];
  PIOLA_TRY(read_name(s, type, "element type"));
  if (strcmp(type, "TET") != 0) {
    if (strcmp(type, "CUBIC") == 0)
      return piola__scan_error(s, PIOLA_ERROR_UNSUPPORTED,
                               "element type CUBIC (8-node hexahedra) is not supported: piola needs TET elements");
    return piola__scan_error(s, PIOLA_ERROR_UNSUPPORTED, "element type '%s' is not supported: piola needs TET elements",
                             type);
  }
  int64_t n, npe, zero;
  PIOLA_TRY(piola__scan_int64(s, &n, "element count"));
  PIOLA_TRY(piola__scan_int64(s, &npe, "nodes per element"));
  PIOLA_TRY(piola__scan_int64(s, &zero, "element header value"));
  if (npe != 4) return piola__scan_error(s, PIOLA_ERROR_PARSE, "TET elements with %lld nodes, expected 4", (long long)npe);
  if (n == 0)
    return piola__scan_error(s, PIOLA_ERROR_PARSE, "element count 0: the mesh has no tetrahedra");
  if (n < 0 || n > INT32_MAX || (uint64_t)n > (uint64_t)(s->end - s->p) / 10)
    return piola__scan_error(s, PIOLA_ERROR_PARSE, "element count %lld does not fit the file", (long long)n);
  out->tets = malloc((size_t)n * 4 * sizeof(int32_t));
  r->lines = malloc((size_t)n * sizeof(int32_t));
  if (!out->tets || !r->lines) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", s->name);
  out->tet_count = (int32_t)n;
  for (int64_t t = 0; t < n; ++t) {
    int64_t id;
    PIOLA_TRY(piola__scan_int64(s, &id, "element id"));
    r->lines[t] = (int32_t)s->line;
    if (id != t + 1)
      return piola__scan_error(s, PIOLA_ERROR_PARSE, "element id %lld out of sequence, expected %lld", (long long)id,
                               (long long)(t + 1));
    for (int k = 0; k < 4; ++k) {
      int64_t v;
      PIOLA_TRY(piola__scan_int64(s, &v, "vertex index"));
      if (v < 1 || v > out->vertex_count)
        return piola__scan_error(s, PIOLA_ERROR_PARSE, "element %lld: vertex %lld out of range [1, %d]", (long long)id,
                                 (long long)v, (int)out->vertex_count);
      out->tets[4 * t + k] = (int32_t)(v - 1);
    }
  }
  return PIOLA_OK;
}

static piola_status read_material(vega_reader *r) {
  text_scanner *s = &r->s;
  if (piola__grow((void **)&r->materials, &r->material_capacity, r->material_count + 1, sizeof(piola_vega_material)))
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", s->name);
  piola_vega_material *m = &r->materials[r->material_count];
  memset(m, 0, sizeof *m);
  PIOLA_TRY(read_name(s, m->name, "material name"));
  char kind[64];
  PIOLA_TRY(read_name(s, kind, "material kind"));
  memcpy(m->kind, kind, sizeof m->kind - 1);
  m->kind[sizeof m->kind - 1] = '\0';
  if (strcmp(kind, "ENU") == 0) {
    PIOLA_TRY(piola__scan_double(s, &m->density, "density"));
    PIOLA_TRY(piola__scan_double(s, &m->youngs_modulus, "Young's modulus"));
    PIOLA_TRY(piola__scan_double(s, &m->poisson_ratio, "Poisson's ratio"));
  } else {
    while (piola__scan_skip(s) && *s->p != '*') piola__scan_next_line(s);
  }
  ++r->material_count;
  return PIOLA_OK;
}

static piola_status read_set(vega_reader *r) {
  text_scanner *s = &r->s;
  if (piola__grow((void **)&r->sets, &r->set_capacity, r->set_count + 1, sizeof(vega_set)))
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", s->name);
  vega_set *set = &r->sets[r->set_count++];
  memset(set, 0, sizeof *set);
  PIOLA_TRY(read_name(s, set->name, "set name"));
  while (piola__scan_skip(s) && *s->p != '*') {
    int32_t id;
    PIOLA_TRY(piola__scan_int32(s, &id, "set element id"));
    if (piola__grow((void **)&set->ids, &set->capacity, set->count + 1, sizeof(int32_t)) ||
        piola__grow((void **)&set->id_lines, &set->line_capacity, set->count + 1, sizeof(int32_t)))
      return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", s->name);
    set->id_lines[set->count] = (int32_t)s->line;
    set->ids[set->count++] = id;
  }
  return PIOLA_OK;
}

static piola_status read_region(vega_reader *r) {
  text_scanner *s = &r->s;
  while (piola__scan_skip(s) && *s->p != '*') {
    if (piola__grow((void **)&r->regions, &r->region_capacity, r->region_count + 1, sizeof(vega_region)))
      return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", s->name);
    vega_region *g = &r->regions[r->region_count++];
    g->line = s->line;
    PIOLA_TRY(read_name(s, g->set, "set name"));
    PIOLA_TRY(read_name(s, g->material, "material name"));
  }
  return PIOLA_OK;
}

static piola_status resolve_regions(vega_reader *r, piola_tet_mesh *out) {
  out->tet_regions = malloc((size_t)out->tet_count * sizeof(int32_t));
  if (!out->tet_regions) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", r->s.name);
  for (int32_t t = 0; t < out->tet_count; ++t) out->tet_regions[t] = -1;
  for (size_t i = 0; i < r->region_count; ++i) {
    const vega_region *g = &r->regions[i];
    int32_t material = -1;
    for (size_t m = 0; m < r->material_count; ++m)
      if (strcmp(r->materials[m].name, g->material) == 0) material = (int32_t)m;
    if (material < 0)
      return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s:%ld: *REGION names unknown material '%s'", r->s.name, g->line, g->material);
    if (strcmp(g->set, "allElements") == 0) {
      for (int32_t t = 0; t < out->tet_count; ++t) out->tet_regions[t] = material;
      continue;
    }
    const vega_set *set = NULL;
    for (size_t k = 0; k < r->set_count; ++k)
      if (strcmp(r->sets[k].name, g->set) == 0) set = &r->sets[k];
    if (!set) return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s:%ld: *REGION names unknown set '%s'", r->s.name, g->line, g->set);
    for (size_t k = 0; k < set->count; ++k) {
      int32_t id = set->ids[k];
      if (id < 1 || id > out->tet_count)
        return PIOLA_FAIL(PIOLA_ERROR_PARSE,
                          "%s:%d: set '%s' lists element %d, out of range [1, %d]", r->s.name,
                          (int)set->id_lines[k], set->name, (int)id, (int)out->tet_count);
      out->tet_regions[id - 1] = material;
    }
  }
  return PIOLA_OK;
}

static piola_status parse(vega_reader *r, piola_tet_mesh *out) {
  text_scanner *s = &r->s;
  while (piola__scan_skip(s)) {
    char key[64];
    PIOLA_TRY(read_name(s, key, "a *SECTION"));
    if (key[0] != '*') return piola__scan_error(s, PIOLA_ERROR_PARSE, "expected a *SECTION keyword, got '%s'", key);
    if (strcmp(key, "*VERTICES") == 0) PIOLA_TRY(read_vertices(r, out));
    else if (strcmp(key, "*ELEMENTS") == 0) PIOLA_TRY(read_elements(r, out));
    else if (strcmp(key, "*MATERIAL") == 0) PIOLA_TRY(read_material(r));
    else if (strcmp(key, "*SET") == 0) PIOLA_TRY(read_set(r));
    else if (strcmp(key, "*REGION") == 0) PIOLA_TRY(read_region(r));
    else if (strcmp(key, "*INCLUDE") == 0)
      return piola__scan_error(s, PIOLA_ERROR_UNSUPPORTED, "*INCLUDE is not supported");
    else
      while (!next_is_keyword(s) && piola__scan_skip(s)) piola__scan_next_line(s);
  }
  if (!out->positions) return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: no *VERTICES section", s->name);
  if (!out->tets) return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: no *ELEMENTS section (the mesh has no tetrahedra)", s->name);
  PIOLA_TRY(resolve_regions(r, out));
  return piola__tet_mesh_finish(out, s->name, r->lines);
}

piola_status piola__read_vega_mem(const char *name, const char *data, size_t size, piola_tet_mesh *out,
                                  piola_vega_material **materials, int32_t *material_count) {
  memset(out, 0, sizeof *out);
  *materials = NULL;
  *material_count = 0;
  vega_reader r;
  memset(&r, 0, sizeof r);
  piola__scanner_init(&r.s, name, data, size, '#');
  r.s.comma_is_space = 1;
  piola_status status = parse(&r, out);
  for (size_t i = 0; i < r.set_count; ++i) {
    free(r.sets[i].ids);
    free(r.sets[i].id_lines);
  }
  free(r.sets);
  free(r.regions);
  free(r.lines);
  if (status == PIOLA_OK) {
    *materials = r.materials;
    *material_count = (int32_t)r.material_count;
  } else {
    free(r.materials);
    piola_tet_mesh_free(out);
  }
  return status;
}
