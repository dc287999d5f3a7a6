/* The damping matrix's structure (layout in damping_matrix.h): one block per mesh edge, and
 * where each tet writes its 6 pairs so that tet ranges can be assembled in parallel without
 * two threads adding to one block. Built once per body. */
#include <stdlib.h>
#include <string.h>

#include "common/status_internal.h"
#include "force/damping_matrix.h"
#include "force/elastic_body_internal.h"

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

/* The range (of PIOLA_DAMPING_PARTS) that tet t belongs to. */
static int tet_part(int32_t t, int32_t blocks) {
  int32_t b = t / PIOLA_TET_BLOCK;
  int k = (int)((int64_t)b * PIOLA_DAMPING_PARTS / (blocks > 0 ? blocks : 1));
  while (k > 0 && b < piola__damping_part_start(blocks, k)) --k;
  while (k + 1 < PIOLA_DAMPING_PARTS && b >= piola__damping_part_start(blocks, k + 1)) ++k;
  return k;
}

/* Where each tet writes each pair: the edge's block, or for an edge that more than one range
 * touches, that range's private slot; and which tet writes each slot first. */
static piola_status build_slots(piola__damping_matrix *m, int32_t tet_count, int32_t blocks,
                                const int32_t *tet_edge) {
  const int32_t ne = m->edge_count;
  int8_t *last = malloc((size_t)ne + 1);
  int32_t *parts = calloc((size_t)ne + 1, sizeof(int32_t));
  if (!last || !parts) {
    free(last);
    free(parts);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "damping matrix: out of memory");
  }
  /* ranges touching each edge (tets come in range order, so a change of range is new) */
  memset(last, -1, (size_t)ne + 1);
  for (int32_t t = 0; t < tet_count; ++t) {
    int k = tet_part(t, blocks);
    for (int p = 0; p < 6; ++p) {
      int32_t e = tet_edge[6 * t + p];
      if (last[e] != k) last[e] = (int8_t)k, parts[e]++;
    }
  }
  int32_t shared = 0, slots = ne;
  for (int32_t e = 0; e < ne; ++e) shared += parts[e] > 1;
  m->shared_count = shared;
  m->shared_edge = malloc(sizeof(int32_t) * ((size_t)shared + 1));
  m->shared_slot_start = malloc(sizeof(int32_t) * ((size_t)shared + 1));
  /* reuse parts: for a shared edge, the next private slot to hand out */
  if (m->shared_edge && m->shared_slot_start) {
    int32_t k = 0;
    for (int32_t e = 0; e < ne; ++e) {
      if (parts[e] < 2) {
        parts[e] = -1;
        continue;
      }
      m->shared_edge[k] = e;
      m->shared_slot_start[k++] = slots;
      int32_t count = parts[e];
      parts[e] = slots;
      slots += count;
    }
    m->shared_slot_start[shared] = slots;
  }
  m->store = malloc(sizeof(double) * 9 * (size_t)slots);
  uint8_t *written = calloc((size_t)slots, 1);
  if (!m->shared_edge || !m->shared_slot_start || !m->store || !written) {
    free(last);
    free(parts);
    free(written);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "damping matrix: out of memory");
  }
  m->blocks = m->store;
  memset(last, -1, (size_t)ne + 1);
  for (int32_t t = 0; t < tet_count; ++t) {
    int k = tet_part(t, blocks);
    for (int p = 0; p < 6; ++p) {
      int32_t e = tet_edge[6 * t + p], slot = e;
      if (parts[e] >= 0) { /* shared: this range's private slot, the next one on a new range */
        if (last[e] != k && last[e] >= 0) parts[e]++;
        last[e] = (int8_t)k;
        slot = parts[e];
      }
      m->tet_slot[6 * t + p] = slot;
      if (!written[slot]) {
        written[slot] = 1;
        m->tet_flags[t] |= (uint16_t)(1u << (6 + p));
      }
    }
  }
  free(last);
  free(parts);
  free(written);
  return PIOLA_OK;
}

piola_status piola__damping_matrix_init(piola__damping_matrix *m, const piola_elastic_body *body) {
  memset(m, 0, sizeof *m);
  int32_t nv = body->vertex_count, nt = body->tet_count;
  m->vertex_count = nv;
  m->row_start = calloc((size_t)nv + 1, sizeof(int32_t));
  m->lower_start = calloc((size_t)nv + 1, sizeof(int32_t));
  m->tet_slot = malloc(sizeof(int32_t) * 6 * (size_t)nt);
  m->tet_flags = calloc((size_t)nt, sizeof(uint16_t));
  if (!m->row_start || !m->lower_start || !m->tet_slot || !m->tet_flags) {
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
  int32_t *tet_edge = malloc(sizeof(int32_t) * 6 * (size_t)(nt > 0 ? nt : 1));
  if (!m->lower_edge || !m->lower_col || !tet_edge) {
    free(tet_edge);
    piola__damping_matrix_free(m);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "damping matrix: out of memory");
  }
  st = build_lower(m);
  for (int32_t t = 0; t < nt && st == PIOLA_OK; ++t)
    for (int p = 0; p < 6; ++p) {
      int32_t a = body->tets[4 * t + PAIRS[p][0]], b = body->tets[4 * t + PAIRS[p][1]];
      tet_edge[6 * t + p] = a < b ? find_edge(m, a, b) : find_edge(m, b, a);
      if (a > b) m->tet_flags[t] |= (uint16_t)(1u << p);
    }
  if (st == PIOLA_OK) st = build_slots(m, nt, body->padded_tet_count / PIOLA_TET_BLOCK, tet_edge);
  free(tet_edge);
  if (st != PIOLA_OK) piola__damping_matrix_free(m);
  return st;
}

void piola__damping_matrix_free(piola__damping_matrix *m) {
  free(m->row_start);
  free(m->col);
  free(m->lower_start);
  free(m->lower_edge);
  free(m->lower_col);
  free(m->tet_slot);
  free(m->tet_flags);
  free(m->shared_edge);
  free(m->shared_slot_start);
  free(m->store);
  memset(m, 0, sizeof *m);
}
