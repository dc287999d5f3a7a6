/* The damping matrix's structure (layout in damping_matrix.h): one block per mesh edge,
 * each tet's 6 edge slots, and the coloring that lets tets be assembled in parallel
 * without two threads adding to one block. Built once per body. */
#include <stdlib.h>
#include <string.h>

#include "common/status_internal.h"
#include "force/damping_matrix.h"
#include "force/elastic_body_internal.h"

/* Tets per assembly chunk, in SIMD blocks: big enough that a color's chunks are worth
 * handing out to threads, small enough that chunks of a well-ordered mesh rarely share an
 * edge, so a few colors suffice. */
#define CHUNK_BLOCKS 32

/* Corner pairs of a tet, in the order of tet_edges and of the assembly's blocks. */
static const int PAIRS[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

static int compare_int32(const void *a, const void *b) {
  int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
  return (x > y) - (x < y);
}

/* Index of edge (i, j), i < j, in the rows (it exists: every pair of a tet is an edge). */
static int32_t find_edge(const piola__damping_matrix *m, int32_t i, int32_t j) {
  int32_t lo = m->row_start[i], hi = m->row_start[i + 1];
  while (hi - lo > 1) {
    int32_t mid = lo + (hi - lo) / 2;
    if (m->col[mid] <= j)
      lo = mid;
    else
      hi = mid;
  }
  return lo;
}

/* Rows: for each vertex the larger vertices it shares a tet with, sorted, without repeats. */
static piola_status build_rows(piola__damping_matrix *m, const int32_t *tets, int32_t tet_count) {
  int32_t nv = m->vertex_count;
  int32_t *count = calloc((size_t)nv + 1, sizeof(int32_t));
  int32_t *all = malloc(sizeof(int32_t) * 6 * (size_t)tet_count);
  if (!count || !all) {
    free(count);
    free(all);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "damping matrix: out of memory");
  }
  for (int32_t t = 0; t < tet_count; ++t)
    for (int p = 0; p < 6; ++p) {
      int32_t a = tets[4 * t + PAIRS[p][0]], b = tets[4 * t + PAIRS[p][1]];
      count[(a < b ? a : b) + 1]++;
    }
  for (int32_t i = 0; i < nv; ++i) count[i + 1] += count[i];
  int32_t *fill = m->row_start; /* scratch: the write position of each row */
  memcpy(fill, count, sizeof(int32_t) * (size_t)nv);
  for (int32_t t = 0; t < tet_count; ++t)
    for (int p = 0; p < 6; ++p) {
      int32_t a = tets[4 * t + PAIRS[p][0]], b = tets[4 * t + PAIRS[p][1]];
      all[fill[a < b ? a : b]++] = a < b ? b : a;
    }
  int32_t edges = 0;
  for (int32_t i = 0; i < nv; ++i) {
    int32_t *row = all + count[i], len = count[i + 1] - count[i];
    qsort(row, (size_t)len, sizeof(int32_t), compare_int32);
    m->row_start[i] = edges;
    for (int32_t k = 0; k < len; ++k)
      if (k == 0 || row[k] != row[k - 1]) all[edges++] = row[k];
  }
  m->row_start[nv] = edges;
  m->edge_count = edges;
  free(count);
  m->col = realloc(all, sizeof(int32_t) * (size_t)(edges > 0 ? edges : 1));
  if (!m->col) {
    m->col = NULL;
    free(all);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "damping matrix: out of memory");
  }
  return PIOLA_OK;
}

/* Each row's edges to smaller vertices, as (edge, other vertex), in increasing edge order. */
static piola_status build_lower(piola__damping_matrix *m) {
  int32_t nv = m->vertex_count;
  int32_t *fill = calloc((size_t)nv + 1, sizeof(int32_t));
  if (!fill) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "damping matrix: out of memory");
  memset(m->lower_start, 0, sizeof(int32_t) * ((size_t)nv + 1));
  for (int32_t k = 0; k < m->edge_count; ++k) m->lower_start[m->col[k] + 1]++;
  for (int32_t i = 0; i < nv; ++i) m->lower_start[i + 1] += m->lower_start[i];
  for (int32_t i = 0; i < nv; ++i)
    for (int32_t k = m->row_start[i]; k < m->row_start[i + 1]; ++k) {
      int32_t j = m->col[k];
      int32_t slot = m->lower_start[j] + fill[j]++;
      m->lower_edge[slot] = k;
      m->lower_col[slot] = i;
    }
  free(fill);
  return PIOLA_OK;
}

/* Greedy coloring of the chunks (no two chunks of a color touch one edge), then which tet
 * writes each block first in the order colors, chunks, tets. More than 64 colors (a mesh
 * whose tet order has no locality at all) falls back to one color run on one thread. */
static piola_status build_coloring(piola__damping_matrix *m, int32_t tet_count, int32_t padded_tet_count) {
  int32_t blocks = padded_tet_count / PIOLA_TET_BLOCK;
  m->chunk_blocks = CHUNK_BLOCKS;
  m->chunk_count = (blocks + CHUNK_BLOCKS - 1) / CHUNK_BLOCKS;
  int32_t nc = m->chunk_count, chunk_tets = CHUNK_BLOCKS * PIOLA_TET_BLOCK;
  uint64_t *used = calloc((size_t)m->edge_count + 1, sizeof(uint64_t));
  int32_t *color = malloc(sizeof(int32_t) * ((size_t)nc + 1));
  uint8_t *seen = calloc((size_t)m->edge_count + 1, 1);
  m->color_chunks = malloc(sizeof(int32_t) * ((size_t)nc + 1));
  m->color_start = calloc(66, sizeof(int32_t));
  if (!used || !color || !seen || !m->color_chunks || !m->color_start) {
    free(used);
    free(color);
    free(seen);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "damping matrix: out of memory");
  }
  int serial = 0;
  for (int32_t c = 0; c < nc && !serial; ++c) {
    int32_t t0 = c * chunk_tets, t1 = t0 + chunk_tets < tet_count ? t0 + chunk_tets : tet_count;
    uint64_t taken = 0;
    for (int32_t t = t0; t < t1; ++t)
      for (int p = 0; p < 6; ++p) taken |= used[m->tet_edges[6 * t + p]];
    if (taken == ~(uint64_t)0) {
      serial = 1;
      break;
    }
    int k = __builtin_ctzll(~taken);
    color[c] = k;
    for (int32_t t = t0; t < t1; ++t)
      for (int p = 0; p < 6; ++p) used[m->tet_edges[6 * t + p]] |= (uint64_t)1 << k;
  }
  if (serial) {
    m->color_count = 1;
    m->color_start[0] = 0;
    m->color_start[1] = nc;
    for (int32_t c = 0; c < nc; ++c) m->color_chunks[c] = c;
  } else {
    int32_t colors = 0;
    for (int32_t c = 0; c < nc; ++c) {
      if (color[c] + 1 > colors) colors = color[c] + 1;
      m->color_start[color[c] + 1]++;
    }
    for (int k = 0; k < colors; ++k) m->color_start[k + 1] += m->color_start[k];
    int32_t fill[64];
    memcpy(fill, m->color_start, sizeof fill);
    for (int32_t c = 0; c < nc; ++c) m->color_chunks[fill[color[c]]++] = c;
    m->color_count = colors;
  }
  m->serial = serial;
  /* first writers, in the order the assembly runs */
  for (int k = 0; k < m->color_count; ++k)
    for (int32_t s = m->color_start[k]; s < m->color_start[k + 1]; ++s) {
      int32_t c = m->color_chunks[s];
      int32_t t0 = c * chunk_tets, t1 = t0 + chunk_tets < tet_count ? t0 + chunk_tets : tet_count;
      for (int32_t t = t0; t < t1; ++t)
        for (int p = 0; p < 6; ++p) {
          int32_t e = m->tet_edges[6 * t + p];
          if (!seen[e]) {
            seen[e] = 1;
            m->tet_flags[t] |= (uint16_t)(1u << (6 + p));
          }
        }
    }
  free(used);
  free(color);
  free(seen);
  return PIOLA_OK;
}

piola_status piola__damping_matrix_init(piola__damping_matrix *m, const piola_elastic_body *body) {
  memset(m, 0, sizeof *m);
  int32_t nv = body->vertex_count, nt = body->tet_count;
  m->vertex_count = nv;
  m->row_start = calloc((size_t)nv + 1, sizeof(int32_t));
  m->lower_start = calloc((size_t)nv + 1, sizeof(int32_t));
  m->tet_edges = malloc(sizeof(int32_t) * 6 * (size_t)nt);
  m->tet_flags = calloc((size_t)nt, sizeof(uint16_t));
  if (!m->row_start || !m->lower_start || !m->tet_edges || !m->tet_flags) {
    piola__damping_matrix_free(m);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "damping matrix: out of memory");
  }
  piola_status st = build_rows(m, body->tets, nt);
  if (st != PIOLA_OK) {
    piola__damping_matrix_free(m);
    return st;
  }
  size_t ne = (size_t)(m->edge_count > 0 ? m->edge_count : 1);
  m->lower_edge = malloc(sizeof(int32_t) * ne);
  m->lower_col = malloc(sizeof(int32_t) * ne);
  m->blocks = malloc(sizeof(double) * 9 * ne);
  if (!m->lower_edge || !m->lower_col || !m->blocks) {
    piola__damping_matrix_free(m);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "damping matrix: out of memory");
  }
  st = build_lower(m);
  if (st != PIOLA_OK) {
    piola__damping_matrix_free(m);
    return st;
  }
  for (int32_t t = 0; t < nt; ++t)
    for (int p = 0; p < 6; ++p) {
      int32_t a = body->tets[4 * t + PAIRS[p][0]], b = body->tets[4 * t + PAIRS[p][1]];
      m->tet_edges[6 * t + p] = a < b ? find_edge(m, a, b) : find_edge(m, b, a);
      if (a > b) m->tet_flags[t] |= (uint16_t)(1u << p);
    }
  st = build_coloring(m, nt, body->padded_tet_count);
  if (st != PIOLA_OK) piola__damping_matrix_free(m);
  return st;
}

void piola__damping_matrix_free(piola__damping_matrix *m) {
  free(m->row_start);
  free(m->col);
  free(m->lower_start);
  free(m->lower_edge);
  free(m->lower_col);
  free(m->tet_edges);
  free(m->tet_flags);
  free(m->color_start);
  free(m->color_chunks);
  free(m->blocks);
  memset(m, 0, sizeof *m);
}
