/* Gmsh .msh reader: versions 2.x and 4.1, ASCII and binary.
 *
 * One reader serves all four variants through three primitives (size, int, double) that
 * either scan text or take raw little-endian bytes, because the section layouts are the same
 * in ASCII and binary within a version. Node tags are arbitrary positive integers with gaps
 * and are mapped to 0-based indices. Kept elements: 4-node tets (type 4) and the corner
 * nodes of higher-order tets (types 11, 29, 30, 31; their other nodes stay as unused
 * vertices). Everything else (points, lines, triangles, hexes...) is skipped. Regions: v2
 * uses the first tag (physical group; 0 if none); v4.1 maps the element block's volume
 * entity to its first physical tag through $Entities, or uses the entity tag when there is
 * no $Entities section or the entity has no physical group. Binary files must be
 * little-endian with 8-byte doubles and (v4.1) 8-byte size_t; the other byte order is
 * detected from the endianness marker and refused. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "io/mesh_io_internal.h"
#include "io/text_scanner.h"
#include "mesh/mesh_internal.h"

typedef struct gmsh_reader {
  text_scanner s;
  int binary;
  int version; /* 2 or 4 */
  /* entities (v4.1): volume tag -> first physical tag */
  int64_t *volume_tags;
  int32_t *volume_physical;
  size_t volume_count;
  int have_entities;
  /* nodes */
  uint64_t *node_tags;
  int32_t *node_lines; /* ASCII files: line of each node's tag */
  double *positions;
  size_t node_count, node_capacity;
  /* tets, with node tags until mapped */
  uint64_t *tet_nodes;
  int32_t *tet_regions;
  int32_t *tet_lines; /* ASCII files: line of each tet */
  uint64_t *tet_tags; /* element tag of each tet, for $ElementData */
  size_t tet_count, tet_capacity;
  /* fibres: the $ElementData named "fiber" or "fibers", by element tag until mapped */
  int have_fibers;
  char fiber_name[8];
  long fiber_line;
  uint64_t *fiber_tags;
  double *fiber_values;
  size_t fiber_count;
} gmsh_reader;

static piola_status binary_error(const gmsh_reader *g, const char *format, const char *what) {
  return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: byte %lld: %s %s", g->s.name, (long long)(g->s.p - g->s.begin), format,
                    what);
}

static piola_status need_bytes(gmsh_reader *g, size_t n, const char *what) {
  if ((size_t)(g->s.end - g->s.p) < n) return binary_error(g, "unexpected end of file reading", what);
  return PIOLA_OK;
}

static piola_status get_size(gmsh_reader *g, uint64_t *v, const char *what) {
  if (g->binary && g->version == 4) {
    PIOLA_TRY(need_bytes(g, 8, what));
    memcpy(v, g->s.p, 8);
    g->s.p += 8;
    return PIOLA_OK;
  }
  int64_t x;
  if (g->binary) { /* v2 binary: int32 */
    int32_t y;
    PIOLA_TRY(need_bytes(g, 4, what));
    memcpy(&y, g->s.p, 4);
    g->s.p += 4;
    x = y;
    if (x < 0) return binary_error(g, "negative", what);
  } else {
    PIOLA_TRY(piola__scan_int64(&g->s, &x, what));
    if (x < 0) return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "%s must not be negative", what);
  }
  *v = (uint64_t)x;
  return PIOLA_OK;
}

static piola_status get_int(gmsh_reader *g, int32_t *v, const char *what) {
  if (g->binary) {
    PIOLA_TRY(need_bytes(g, 4, what));
    memcpy(v, g->s.p, 4);
    g->s.p += 4;
    return PIOLA_OK;
  }
  return piola__scan_int32(&g->s, v, what);
}

static piola_status get_double(gmsh_reader *g, double *v, const char *what) {
  if (g->binary) {
    PIOLA_TRY(need_bytes(g, 8, what));
    memcpy(v, g->s.p, 8);
    g->s.p += 8;
    if (!isfinite(*v)) return binary_error(g, "non-finite", what);
    return PIOLA_OK;
  }
  return piola__scan_double(&g->s, v, what);
}

/* A count read from the file must fit in the bytes left (each item needs min_bytes). */
static piola_status check_count(gmsh_reader *g, uint64_t n, size_t min_bytes, const char *what) {
  size_t left = (size_t)(g->s.end - g->s.p);
  if (n > INT32_MAX || n > left / min_bytes) {
    if (g->binary) return binary_error(g, "count does not fit the file:", what);
    return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "%s %llu does not fit the file", what, (unsigned long long)n);
  }
  return PIOLA_OK;
}

static int nodes_of_type(int32_t type) {
  static const int table[32] = {0, 2, 3, 4, 4, 8, 6, 5, 3, 6, 9, 10, 27, 18, 14, 1,
                                8, 20, 15, 13, 9, 10, 12, 15, 15, 21, 4, 5, 6, 20, 35, 56};
  if (type >= 1 && type < 32) return table[type];
  if (type == 92) return 64;
  if (type == 93) return 125;
  return 0;
}

static int is_tet_type(int32_t type) { return type == 4 || type == 11 || type == 29 || type == 30 || type == 31; }

static piola_status reserve_tets(gmsh_reader *g, size_t more) {
  size_t cap = g->tet_capacity;
  if (piola__grow((void **)&g->tet_nodes, &cap, g->tet_count + more, 4 * sizeof(uint64_t)) != 0)
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", g->s.name);
  g->tet_capacity = cap;
  int32_t *r = realloc(g->tet_regions, cap * sizeof(int32_t));
  if (!r) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", g->s.name);
  g->tet_regions = r;
  int32_t *l = realloc(g->tet_lines, cap * sizeof(int32_t));
  if (!l) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", g->s.name);
  g->tet_lines = l;
  uint64_t *tags = realloc(g->tet_tags, cap * sizeof(uint64_t));
  if (!tags) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", g->s.name);
  g->tet_tags = tags;
  return PIOLA_OK;
}

static piola_status add_tet(gmsh_reader *g, uint64_t tag, const uint64_t *nodes, int32_t region) {
  if (g->tet_count + 1 > g->tet_capacity) PIOLA_TRY(reserve_tets(g, g->tet_capacity + 1));
  g->tet_lines[g->tet_count] = (int32_t)g->s.line;
  g->tet_tags[g->tet_count] = tag;
  memcpy(g->tet_nodes + 4 * g->tet_count, nodes, 4 * sizeof(uint64_t));
  g->tet_regions[g->tet_count++] = region;
  return PIOLA_OK;
}

static piola_status reserve_nodes(gmsh_reader *g, size_t more) {
  size_t cap = g->node_capacity;
  if (piola__grow((void **)&g->node_tags, &cap, g->node_count + more, sizeof(uint64_t)) != 0)
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", g->s.name);
  size_t cap2 = g->node_capacity;
  if (piola__grow((void **)&g->positions, &cap2, g->node_count + more, 3 * sizeof(double)) != 0)
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", g->s.name);
  size_t cap3 = g->node_capacity;
  if (!g->binary &&
      piola__grow((void **)&g->node_lines, &cap3, g->node_count + more, sizeof(int32_t)) != 0)
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", g->s.name);
  g->node_capacity = cap < cap2 ? cap : cap2;
  if (!g->binary && cap3 < g->node_capacity) g->node_capacity = cap3;
  return PIOLA_OK;
}

/* Moves past "$EndName", skipping anything before it. */
static piola_status skip_section(gmsh_reader *g, const char *name) {
  char end_tag[80];
  snprintf(end_tag, sizeof end_tag, "$End%s", name);
  size_t n = strlen(end_tag);
  const char *p = g->s.p;
  while (p + n <= g->s.end) {
    if (*p == '\n') ++g->s.line;
    if (*p == '$' && memcmp(p, end_tag, n) == 0) {
      g->s.p = p + n;
      return PIOLA_OK;
    }
    ++p;
  }
  g->s.p = g->s.end;
  return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "missing %s", end_tag);
}

static piola_status expect_end(gmsh_reader *g, const char *name) {
  char end_tag[80];
  snprintf(end_tag, sizeof end_tag, "$End%s", name);
  if (!piola__scan_accept(&g->s, end_tag, 0)) {
    if (g->binary) return binary_error(g, "expected", end_tag);
    return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "expected %s (counts do not match the data?)", end_tag);
  }
  return PIOLA_OK;
}

static piola_status check_endianness(gmsh_reader *g) {
  /* After the format line: one int32 equal to 1 in the writer's byte order. */
  piola__scan_next_line(&g->s);
  int32_t one;
  PIOLA_TRY(need_bytes(g, 4, "the endianness marker"));
  memcpy(&one, g->s.p, 4);
  g->s.p += 4;
  if (one == 1) return PIOLA_OK;
  if (one == 0x01000000)
    return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED,
                      "%s: byte %lld: binary file written in the other byte order (big-endian), not supported",
                      g->s.name, (long long)(g->s.p - g->s.begin - 4));
  return binary_error(g, "bad endianness marker (expected int32 1):", "");
}

static piola_status read_format(gmsh_reader *g) {
  const char *tok;
  size_t len;
  PIOLA_TRY(piola__scan_token(&g->s, &tok, &len, "the version"));
  if (len >= 1 && tok[0] == '2') g->version = 2;
  else if (len == 3 && memcmp(tok, "4.1", 3) == 0) g->version = 4;
  else
    return piola__scan_error(&g->s, PIOLA_ERROR_UNSUPPORTED, "MSH version '%.*s' not supported (expected 2.2 or 4.1)",
                             (int)(len < 20 ? len : 20), tok);
  int64_t file_type, data_size;
  PIOLA_TRY(piola__scan_int64(&g->s, &file_type, "file type"));
  PIOLA_TRY(piola__scan_int64(&g->s, &data_size, "data size"));
  if (file_type != 0 && file_type != 1)
    return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "file type %lld, expected 0 (ASCII) or 1 (binary)", (long long)file_type);
  if (data_size != 8)
    return piola__scan_error(&g->s, PIOLA_ERROR_UNSUPPORTED, "data size %lld, only 8 is supported", (long long)data_size);
  g->binary = file_type == 1;
  if (g->binary) PIOLA_TRY(check_endianness(g));
  g->binary = 0; /* the section footer is text */
  PIOLA_TRY(expect_end(g, "MeshFormat"));
  g->binary = file_type == 1;
  return PIOLA_OK;
}

/* Text separators: after a text header line, binary data starts on the next line. */
static void to_binary_data(gmsh_reader *g) {
  if (g->binary) piola__scan_next_line(&g->s);
}

static piola_status read_entities(gmsh_reader *g) {
  to_binary_data(g);
  uint64_t counts[4] = {0, 0, 0, 0};
  for (int d = 0; d < 4; ++d) PIOLA_TRY(get_size(g, &counts[d], "entity count"));
  for (int d = 0; d < 4; ++d) PIOLA_TRY(check_count(g, counts[d], 8, "entity count"));
  g->volume_tags = malloc((counts[3] + 1) * sizeof(int64_t));
  g->volume_physical = malloc((counts[3] + 1) * sizeof(int32_t));
  if (!g->volume_tags || !g->volume_physical) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", g->s.name);
  for (int d = 0; d < 4; ++d) {
    for (uint64_t e = 0; e < counts[d]; ++e) {
      int32_t tag;
      double ignored;
      PIOLA_TRY(get_int(g, &tag, "entity tag"));
      for (int k = 0; k < (d == 0 ? 3 : 6); ++k) PIOLA_TRY(get_double(g, &ignored, "entity bounding box"));
      uint64_t nphys = 0;
      PIOLA_TRY(get_size(g, &nphys, "physical tag count"));
      PIOLA_TRY(check_count(g, nphys, 2, "physical tag count"));
      int32_t first_physical = 0;
      for (uint64_t k = 0; k < nphys; ++k) {
        int32_t phys;
        PIOLA_TRY(get_int(g, &phys, "physical tag"));
        if (k == 0) first_physical = phys;
      }
      if (d == 3) {
        g->volume_tags[g->volume_count] = tag;
        g->volume_physical[g->volume_count] = nphys > 0 ? first_physical : tag;
        ++g->volume_count;
      }
      if (d > 0) {
        uint64_t nbound = 0;
        PIOLA_TRY(get_size(g, &nbound, "bounding entity count"));
        PIOLA_TRY(check_count(g, nbound, 2, "bounding entity count"));
        for (uint64_t k = 0; k < nbound; ++k) {
          int32_t b;
          PIOLA_TRY(get_int(g, &b, "bounding entity"));
        }
      }
    }
  }
  g->have_entities = 1;
  return expect_end(g, "Entities");
}

static piola_status read_nodes_v4(gmsh_reader *g) {
  to_binary_data(g);
  uint64_t blocks = 0, total = 0, min_tag = 0, max_tag = 0;
  PIOLA_TRY(get_size(g, &blocks, "node block count"));
  PIOLA_TRY(get_size(g, &total, "node count"));
  PIOLA_TRY(get_size(g, &min_tag, "minimum node tag"));
  PIOLA_TRY(get_size(g, &max_tag, "maximum node tag"));
  PIOLA_TRY(check_count(g, blocks, 8, "node block count"));
  PIOLA_TRY(check_count(g, total, 8, "node count"));
  PIOLA_TRY(reserve_nodes(g, total));
  for (uint64_t b = 0; b < blocks; ++b) {
    int32_t dim, entity, parametric;
    uint64_t n = 0;
    PIOLA_TRY(get_int(g, &dim, "entity dimension"));
    PIOLA_TRY(get_int(g, &entity, "entity tag"));
    PIOLA_TRY(get_int(g, &parametric, "parametric flag"));
    PIOLA_TRY(get_size(g, &n, "nodes in block"));
    PIOLA_TRY(check_count(g, n, 8, "nodes in block"));
    if (dim < 0 || dim > 3 || (parametric != 0 && parametric != 1)) {
      if (g->binary) return binary_error(g, "bad node block header", "");
      return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "bad node block header (dimension %d, parametric %d)", dim, parametric);
    }
    PIOLA_TRY(reserve_nodes(g, n));
    size_t first = g->node_count;
    for (uint64_t i = 0; i < n; ++i) {
      uint64_t tag = 0;
      PIOLA_TRY(get_size(g, &tag, "node tag"));
      g->node_tags[first + i] = tag;
      if (!g->binary) g->node_lines[first + i] = (int32_t)g->s.line;
    }
    int extra = parametric ? dim : 0;
    for (uint64_t i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) PIOLA_TRY(get_double(g, &g->positions[3 * (first + i) + k], "coordinate"));
      for (int k = 0; k < extra; ++k) {
        double ignored;
        PIOLA_TRY(get_double(g, &ignored, "parametric coordinate"));
      }
    }
    g->node_count += n;
  }
  if (g->node_count != total)
    return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "$Nodes announces %llu nodes but its blocks hold %zu",
                             (unsigned long long)total, g->node_count);
  return expect_end(g, "Nodes");
}

static int32_t region_of_entity(const gmsh_reader *g, int32_t entity) {
  for (size_t i = 0; i < g->volume_count; ++i)
    if (g->volume_tags[i] == entity) return g->volume_physical[i];
  return entity;
}

static piola_status read_elements_v4(gmsh_reader *g) {
  to_binary_data(g);
  uint64_t blocks = 0, total = 0, min_tag = 0, max_tag = 0;
  PIOLA_TRY(get_size(g, &blocks, "element block count"));
  PIOLA_TRY(get_size(g, &total, "element count"));
  PIOLA_TRY(get_size(g, &min_tag, "minimum element tag"));
  PIOLA_TRY(get_size(g, &max_tag, "maximum element tag"));
  PIOLA_TRY(check_count(g, blocks, 8, "element block count"));
  PIOLA_TRY(check_count(g, total, 4, "element count"));
  PIOLA_TRY(reserve_tets(g, total));
  uint64_t seen = 0;
  for (uint64_t b = 0; b < blocks; ++b) {
    int32_t dim, entity, type;
    uint64_t n = 0;
    PIOLA_TRY(get_int(g, &dim, "entity dimension"));
    PIOLA_TRY(get_int(g, &entity, "entity tag"));
    PIOLA_TRY(get_int(g, &type, "element type"));
    PIOLA_TRY(get_size(g, &n, "elements in block"));
    int npe = nodes_of_type(type);
    if (npe == 0) {
      if (g->binary) return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED, "%s: byte %lld: unknown element type %d", g->s.name,
                                       (long long)(g->s.p - g->s.begin), type);
      return piola__scan_error(&g->s, PIOLA_ERROR_UNSUPPORTED, "unknown element type %d", type);
    }
    PIOLA_TRY(check_count(g, n, 2 * (size_t)(npe + 1), "elements in block"));
    int keep = is_tet_type(type);
    int32_t region = keep ? (g->have_entities ? region_of_entity(g, entity) : entity) : 0;
    for (uint64_t e = 0; e < n; ++e) {
      uint64_t tag = 0, nodes[4] = {0, 0, 0, 0};
      PIOLA_TRY(get_size(g, &tag, "element tag"));
      for (int k = 0; k < npe; ++k) {
        uint64_t v = 0;
        PIOLA_TRY(get_size(g, &v, "element node"));
        if (k < 4) nodes[k] = v;
      }
      if (keep) PIOLA_TRY(add_tet(g, tag, nodes, region));
    }
    seen += n;
  }
  if (seen != total)
    return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "$Elements announces %llu elements but its blocks hold %llu",
                             (unsigned long long)total, (unsigned long long)seen);
  return expect_end(g, "Elements");
}

static piola_status read_nodes_v2(gmsh_reader *g) {
  uint64_t n = 0;
  PIOLA_TRY(piola__scan_int64(&g->s, (int64_t *)&n, "node count"));
  PIOLA_TRY(check_count(g, n, 8, "node count"));
  to_binary_data(g);
  PIOLA_TRY(reserve_nodes(g, n));
  for (uint64_t i = 0; i < n; ++i) {
    int64_t tag;
    if (g->binary) {
      int32_t t32;
      PIOLA_TRY(get_int(g, &t32, "node tag"));
      tag = t32;
    } else {
      PIOLA_TRY(piola__scan_int64(&g->s, &tag, "node tag"));
    }
    if (tag < 0) return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "negative node tag %lld", (long long)tag);
    g->node_tags[g->node_count] = (uint64_t)tag;
    if (!g->binary) g->node_lines[g->node_count] = (int32_t)g->s.line;
    for (int k = 0; k < 3; ++k) PIOLA_TRY(get_double(g, &g->positions[3 * g->node_count + k], "coordinate"));
    ++g->node_count;
  }
  return expect_end(g, "Nodes");
}

static piola_status read_element_body_v2(gmsh_reader *g, int32_t id, int32_t type, int32_t ntags) {
  int npe = nodes_of_type(type);
  if (npe == 0) {
    if (g->binary) return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED, "%s: byte %lld: unknown element type %d", g->s.name,
                                     (long long)(g->s.p - g->s.begin), type);
    return piola__scan_error(&g->s, PIOLA_ERROR_UNSUPPORTED, "unknown element type %d", type);
  }
  if (ntags < 0 || ntags > 1000) return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "bad tag count %d", ntags);
  int32_t region = 0;
  for (int32_t k = 0; k < ntags; ++k) {
    int32_t t;
    PIOLA_TRY(get_int(g, &t, "element tag"));
    if (k == 0) region = t;
  }
  uint64_t nodes[4];
  for (int k = 0; k < npe; ++k) {
    int32_t v;
    PIOLA_TRY(get_int(g, &v, "element node"));
    if (v < 0) return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "negative node tag %d", v);
    if (k < 4) nodes[k] = (uint64_t)v;
  }
  if (is_tet_type(type)) PIOLA_TRY(add_tet(g, (uint64_t)(uint32_t)id, nodes, region));
  return PIOLA_OK;
}

static piola_status read_elements_v2(gmsh_reader *g) {
  uint64_t n = 0;
  PIOLA_TRY(piola__scan_int64(&g->s, (int64_t *)&n, "element count"));
  PIOLA_TRY(check_count(g, n, 8, "element count"));
  to_binary_data(g);
  if (!g->binary) {
    for (uint64_t e = 0; e < n; ++e) {
      int32_t id, type, ntags;
      PIOLA_TRY(get_int(g, &id, "element id"));
      PIOLA_TRY(get_int(g, &type, "element type"));
      PIOLA_TRY(get_int(g, &ntags, "tag count"));
      PIOLA_TRY(read_element_body_v2(g, id, type, ntags));
      if (piola__scan_more_on_line(&g->s))
        return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "element %d: more values than its type %d and %d tags need", id,
                                 type, ntags);
    }
  } else {
    uint64_t seen = 0;
    while (seen < n) {
      int32_t type, count, ntags;
      PIOLA_TRY(get_int(g, &type, "element type"));
      PIOLA_TRY(get_int(g, &count, "elements in block"));
      PIOLA_TRY(get_int(g, &ntags, "tag count"));
      if (count <= 0 || (uint64_t)count > n - seen) return binary_error(g, "bad element block count", "");
      for (int32_t e = 0; e < count; ++e) {
        int32_t id;
        PIOLA_TRY(get_int(g, &id, "element id"));
        PIOLA_TRY(read_element_body_v2(g, id, type, ntags));
      }
      seen += (uint64_t)count;
    }
  }
  return expect_end(g, "Elements");
}

/* Orders (tag, index) pairs by tag. */
static int cmp_pair(const void *a, const void *b) {
  const uint64_t *x = a, *y = b;
  return x[0] < y[0] ? -1 : x[0] > y[0];
}

/* $ElementData: a text header (string tags: the name first; real tags: the time; integer
 * tags: time step, component count, entry count[, partition]) and then, per entry, an
 * element tag and the values (binary in binary files: a 4-byte int tag, also in 4.1). Only a view named "fiber" or
 * "fibers" is kept, as the tets' fibre directions; any other view is skipped. */
static piola_status read_element_data(gmsh_reader *g) {
  long line = g->s.line;
  int binary = g->binary;
  g->binary = 0; /* the header is text in both encodings */
  int32_t nstrings = 0, nreals = 0, nints = 0;
  char name[64] = "";
  PIOLA_TRY(get_int(g, &nstrings, "string tag count"));
  if (nstrings < 0 || nstrings > 100) return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "bad string tag count %d", nstrings);
  for (int32_t k = 0; k < nstrings; ++k) {
    /* a quoted string; it may hold blanks, so take tokens up to the closing quote */
    char text[64] = "";
    size_t used = 0;
    for (;;) {
      const char *tok;
      size_t len;
      if (!piola__scan_skip(&g->s)) return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "unexpected end of $ElementData");
      PIOLA_TRY(piola__scan_token(&g->s, &tok, &len, "a string tag"));
      if (used > 0 && used + 1 < sizeof text) text[used++] = ' ';
      for (size_t c = 0; c < len && used + 1 < sizeof text; ++c) text[used++] = tok[c];
      text[used] = '\0';
      if (text[0] != '"' || (used >= 2 && text[used - 1] == '"')) break;
    }
    if (k == 0) {
      const char *b = text[0] == '"' ? text + 1 : text;
      snprintf(name, sizeof name, "%s", b);
      size_t n = strlen(name);
      while (n > 0 && (name[n - 1] == '"' || name[n - 1] == ' ')) name[--n] = '\0';
    }
  }
  PIOLA_TRY(get_int(g, &nreals, "real tag count"));
  if (nreals < 0 || nreals > 100) return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "bad real tag count %d", nreals);
  for (int32_t k = 0; k < nreals; ++k) {
    double ignored;
    PIOLA_TRY(get_double(g, &ignored, "real tag"));
  }
  PIOLA_TRY(get_int(g, &nints, "integer tag count"));
  if (nints < 0 || nints > 100) return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "bad integer tag count %d", nints);
  int32_t ints[4] = {0, 0, 0, 0};
  long component_line = g->s.line;
  for (int32_t k = 0; k < nints; ++k) {
    int32_t v;
    PIOLA_TRY(get_int(g, &v, "integer tag"));
    if (k < 4) ints[k] = v;
    if (k == 1) component_line = g->s.line;
  }
  int fiber = strcmp(name, "fiber") == 0 || strcmp(name, "fibers") == 0;
  if (!fiber) {
    g->binary = binary;
    return skip_section(g, "ElementData");
  }
  if (g->have_fibers)
    return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "a second $ElementData named \"%s\" (the first is \"%s\" at line %ld)",
                             name, g->fiber_name, g->fiber_line);
  if (nints < 3)
    return piola__scan_error(&g->s, PIOLA_ERROR_PARSE,
                             "$ElementData \"%s\" needs the integer tags time step, component count and entry count", name);
  if (ints[1] != 3)
    return PIOLA_FAIL(PIOLA_ERROR_PARSE,
                      "%s:%ld: $ElementData \"%s\" has %d components, expected 3 (a fibre direction per element)",
                      g->s.name, component_line, name, (int)ints[1]);
  if (ints[2] < 0) return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "$ElementData \"%s\": negative entry count", name);
  g->binary = binary;
  size_t count = (size_t)ints[2];
  PIOLA_TRY(check_count(g, count, 8, "$ElementData entry count")); /* "1 0 0 0\n" */
  g->have_fibers = 1;
  g->fiber_line = line;
  snprintf(g->fiber_name, sizeof g->fiber_name, "%s", name);
  g->fiber_tags = malloc((count + 1) * sizeof(uint64_t));
  g->fiber_values = malloc((3 * count + 1) * sizeof(double));
  if (!g->fiber_tags || !g->fiber_values) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", g->s.name);
  to_binary_data(g);
  for (size_t e = 0; e < count; ++e) {
    /* post-processing views keep 4-byte element tags in binary, in 4.1 too */
    int32_t tag32;
    int64_t tag64;
    if (g->binary) {
      PIOLA_TRY(get_int(g, &tag32, "element tag"));
      tag64 = tag32;
    } else {
      PIOLA_TRY(piola__scan_int64(&g->s, &tag64, "element tag"));
    }
    if (tag64 < 0) return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "negative element tag %lld", (long long)tag64);
    g->fiber_tags[e] = (uint64_t)tag64;
    for (int k = 0; k < 3; ++k) PIOLA_TRY(get_double(g, &g->fiber_values[3 * e + (size_t)k], "fibre component"));
    g->fiber_count = e + 1;
    if (!g->binary && piola__scan_more_on_line(&g->s))
      return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "$ElementData \"%s\": more than 3 values for element %llu",
                               name, (unsigned long long)g->fiber_tags[e]);
  }
  return expect_end(g, "ElementData");
}

/* Gives every tet its fibre from the $ElementData entries (matched by element tag); entries
 * of other elements (triangles...) are ignored, and a tet without one is an error. */
static piola_status map_fibers(gmsh_reader *g, piola_tet_mesh *out) {
  size_t nt = g->tet_count;
  uint64_t *pairs = malloc(2 * nt * sizeof(uint64_t) + 1);
  uint8_t *given = calloc(nt + 1, 1);
  out->tet_fibers = malloc(3 * nt * sizeof(double) + 1);
  if (!pairs || !given || !out->tet_fibers) {
    free(pairs);
    free(given);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", g->s.name);
  }
  for (size_t t = 0; t < nt; ++t) pairs[2 * t] = g->tet_tags[t], pairs[2 * t + 1] = t;
  qsort(pairs, nt, 2 * sizeof(uint64_t), cmp_pair);
  size_t missing = nt;
  for (size_t e = 0; e < g->fiber_count; ++e) {
    size_t lo = 0, hi = nt;
    while (lo < hi) {
      size_t mid = (lo + hi) / 2;
      if (pairs[2 * mid] < g->fiber_tags[e]) lo = mid + 1;
      else hi = mid;
    }
    if (lo >= nt || pairs[2 * lo] != g->fiber_tags[e]) continue; /* not a tet */
    size_t t = pairs[2 * lo + 1];
    memcpy(out->tet_fibers + 3 * t, g->fiber_values + 3 * e, 3 * sizeof(double));
    if (!given[t]) --missing;
    given[t] = 1;
  }
  size_t first = 0;
  while (first < nt && given[first]) ++first;
  free(pairs);
  free(given);
  if (missing)
    return PIOLA_FAIL(PIOLA_ERROR_PARSE,
                      "%s:%ld: $ElementData \"%s\" has %zu entries but %zu of the %zu tets have no fibre "
                      "(the first is element %llu)",
                      g->s.name, g->fiber_line, g->fiber_name, g->fiber_count, missing, nt,
                      (unsigned long long)g->tet_tags[first]);
  return PIOLA_OK;
}

/* A tet naming a node tag $Nodes lacks: at the tet's line in an ASCII file. */
static piola_status missing_tag(const gmsh_reader *g, size_t tet, uint64_t tag) {
  if (!g->binary)
    return PIOLA_FAIL(PIOLA_ERROR_PARSE,
                      "%s:%d: tet %zu uses node tag %llu, which is not in $Nodes", g->s.name,
                      (int)g->tet_lines[tet], tet, (unsigned long long)tag);
  return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: tet %zu uses node tag %llu, which is not in $Nodes",
                    g->s.name, tet, (unsigned long long)tag);
}

/* Node `second` repeats the tag of node `first` (first < second): at its line in an ASCII file. */
static piola_status duplicate_tag(const gmsh_reader *g, size_t first, size_t second) {
  unsigned long long tag = (unsigned long long)g->node_tags[second];
  if (!g->binary)
    return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s:%d: node tag %llu appears twice (first at line %d)",
                      g->s.name, (int)g->node_lines[second], tag, (int)g->node_lines[first]);
  return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: node tag %llu appears twice", g->s.name, tag);
}

/* Tag -> index: a dense table when tags are compact, else a sorted list. */

static piola_status map_tags(gmsh_reader *g, piola_tet_mesh *out) {
  size_t n = g->node_count;
  uint64_t max_tag = 0;
  for (size_t i = 0; i < n; ++i)
    if (g->node_tags[i] > max_tag) max_tag = g->node_tags[i];
  size_t nt = g->tet_count;
  out->tets = malloc(4 * nt * sizeof(int32_t) + 1);
  if (!out->tets) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", g->s.name);
  out->tet_count = (int32_t)nt;
  if (max_tag <= 4 * (uint64_t)n + 1024) {
    int32_t *dense = malloc(((size_t)max_tag + 1) * sizeof(int32_t));
    if (!dense) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", g->s.name);
    for (size_t i = 0; i <= max_tag; ++i) dense[i] = -1;
    for (size_t i = 0; i < n; ++i) {
      if (dense[g->node_tags[i]] >= 0) {
        size_t first = (size_t)dense[g->node_tags[i]];
        free(dense);
        return duplicate_tag(g, first, i);
      }
      dense[g->node_tags[i]] = (int32_t)i;
    }
    for (size_t k = 0; k < 4 * nt; ++k) {
      uint64_t tag = g->tet_nodes[k];
      int32_t v = tag <= max_tag ? dense[tag] : -1;
      if (v < 0) {
        free(dense);
        return missing_tag(g, k / 4, tag);
      }
      out->tets[k] = v;
    }
    free(dense);
    return PIOLA_OK;
  }
  uint64_t *pairs = malloc(2 * n * sizeof(uint64_t) + 1);
  if (!pairs) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", g->s.name);
  for (size_t i = 0; i < n; ++i) {
    pairs[2 * i] = g->node_tags[i];
    pairs[2 * i + 1] = i;
  }
  qsort(pairs, n, 2 * sizeof(uint64_t), cmp_pair);
  for (size_t i = 1; i < n; ++i)
    if (pairs[2 * i] == pairs[2 * i - 2]) {
      size_t a = (size_t)pairs[2 * i - 1], b = (size_t)pairs[2 * i + 1];
      free(pairs);
      return duplicate_tag(g, a < b ? a : b, a < b ? b : a);
    }
  for (size_t k = 0; k < 4 * nt; ++k) {
    uint64_t tag = g->tet_nodes[k];
    size_t lo = 0, hi = n;
    while (lo < hi) {
      size_t mid = (lo + hi) / 2;
      if (pairs[2 * mid] < tag) lo = mid + 1;
      else hi = mid;
    }
    if (lo >= n || pairs[2 * lo] != tag) {
      free(pairs);
      return missing_tag(g, k / 4, tag);
    }
    out->tets[k] = (int32_t)pairs[2 * lo + 1];
  }
  free(pairs);
  return PIOLA_OK;
}

static piola_status parse(gmsh_reader *g, piola_tet_mesh *out) {
  if (!piola__scan_accept(&g->s, "$MeshFormat", 0))
    return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "not a Gmsh file: expected $MeshFormat");
  PIOLA_TRY(read_format(g));
  int have_nodes = 0, have_elements = 0;
  while (piola__scan_skip(&g->s)) {
    const char *tok;
    size_t len;
    PIOLA_TRY(piola__scan_token(&g->s, &tok, &len, "a section"));
    if (len < 2 || tok[0] != '$' || len > 60)
      return piola__scan_error(&g->s, PIOLA_ERROR_PARSE, "expected a $Section, got '%.*s'", (int)(len < 40 ? len : 40), tok);
    char name[64];
    memcpy(name, tok + 1, len - 1);
    name[len - 1] = '\0';
    if (strcmp(name, "Nodes") == 0) {
      if (have_nodes) return piola__scan_error(&g->s, PIOLA_ERROR_UNSUPPORTED, "more than one $Nodes section");
      PIOLA_TRY(g->version == 4 ? read_nodes_v4(g) : read_nodes_v2(g));
      have_nodes = 1;
    } else if (strcmp(name, "Elements") == 0) {
      if (have_elements) return piola__scan_error(&g->s, PIOLA_ERROR_UNSUPPORTED, "more than one $Elements section");
      PIOLA_TRY(g->version == 4 ? read_elements_v4(g) : read_elements_v2(g));
      have_elements = 1;
    } else if (strcmp(name, "ElementData") == 0) {
      PIOLA_TRY(read_element_data(g));
    } else if (strcmp(name, "Entities") == 0 && g->version == 4 && !g->have_entities) {
      PIOLA_TRY(read_entities(g));
    } else {
      PIOLA_TRY(skip_section(g, name));
    }
  }
  if (!have_nodes) return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: no $Nodes section", g->s.name);
  if (!have_elements) return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: no $Elements section", g->s.name);
  if (g->tet_count == 0) return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: the mesh has no tetrahedra", g->s.name);
  if (g->node_count > INT32_MAX || g->tet_count > INT32_MAX)
    return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED, "%s: mesh too large", g->s.name);
  PIOLA_TRY(map_tags(g, out));
  out->vertex_count = (int32_t)g->node_count;
  out->positions = g->positions;
  g->positions = NULL;
  out->tet_regions = g->tet_regions;
  g->tet_regions = NULL;
  if (g->have_fibers) PIOLA_TRY(map_fibers(g, out));
  if (!out->positions) {
    out->positions = malloc(1);
    if (!out->positions) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", g->s.name);
  }
  return piola__tet_mesh_finish(out, g->s.name, g->binary ? NULL : g->tet_lines);
}

piola_status piola__read_gmsh_mem(const char *name, const char *data, size_t size, piola_tet_mesh *out) {
  memset(out, 0, sizeof *out);
  gmsh_reader g;
  memset(&g, 0, sizeof g);
  piola__scanner_init(&g.s, name, data, size, 0);
  piola_status status = parse(&g, out);
  free(g.volume_tags);
  free(g.volume_physical);
  free(g.node_tags);
  free(g.node_lines);
  free(g.positions);
  free(g.tet_nodes);
  free(g.tet_regions);
  free(g.tet_lines);
  free(g.tet_tags);
  free(g.fiber_tags);
  free(g.fiber_values);
  if (status != PIOLA_OK) piola_tet_mesh_free(out);
  return status;
}
