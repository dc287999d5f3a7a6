/* The damping matrix's structure (layout in damping_matrix.h): one block per mesh edge, and
 * where each tet writes its 6 pairs so that tet ranges can be assembled in parallel without
 * two threads adding to one block. Built once per body. */
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "force/damping_matrix.h"
#include "force/elastic_body_internal.h"

/* Corner pairs of a tet, in the order of tet_edges and of the assembly's blocks. */
static const int PAIRS[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

/* Sorts v[0 .. n-1] ascending. A row lists each of its edges once per tet around it, a few
 * dozen entries: insertion sort does them in a fraction of qsort's time, which the pattern
 * of every body built or rebuilt (a cut, docs/fracture.md) spent most of its sorting in. */
static void sort_row(int32_t *v, int32_t n) {
  for (int32_t i = 1; i < n; ++i) {
    const int32_t x = v[i];
    int32_t j = i;
    for (; j > 0 && v[j - 1] > x; --j) v[j] = v[j - 1];
    v[j] = x;
  }
}

/* Index of the edge between vertices a and b (it exists: every pair of a tet is an edge):
 * in the row of the one ranked first, the other's entry. */
static int32_t find_edge(const piola__damping_matrix *m, int32_t a, int32_t b) {
  if (m->rank[a] > m->rank[b]) {
    int32_t t = a;
    a = b;
    b = t;
  }
  int32_t lo = m->row_start[m->rank[a]], hi = m->row_start[m->rank[a] + 1];
  while (hi - lo > 1) {
    int32_t mid = lo + (hi - lo) / 2;
    if (m->col[mid] <= b)
      lo = mid;
    else
      hi = mid;
  }
  return lo;
}

/* Rows, in rank order: for each vertex the vertices ranked after it that it shares a tet
 * with, sorted by index, without repeats. */
static piola_status build_rows(piola__damping_matrix *m, const int32_t *tets, int32_t tet_count) {
  int32_t nv = m->vertex_count;
  const int32_t *rank = m->rank;
  int32_t *count = calloc((size_t)nv + 1, sizeof(int32_t));
  int32_t *all = malloc(sizeof(int32_t) * 6 * (size_t)(tet_count > 0 ? tet_count : 1));
  if (!count || !all) {
    free(count);
    free(all);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "damping matrix: out of memory");
  }
  for (int32_t t = 0; t < tet_count; ++t)
    for (int p = 0; p < 6; ++p) {
      int32_t ra = rank[tets[4 * t + PAIRS[p][0]]], rb = rank[tets[4 * t + PAIRS[p][1]]];
      count[(ra < rb ? ra : rb) + 1]++;
    }
  for (int32_t r = 0; r < nv; ++r) count[r + 1] += count[r];
  int32_t *fill = m->row_start; /* scratch: the write position of each row */
  memcpy(fill, count, sizeof(int32_t) * (size_t)nv);
  for (int32_t t = 0; t < tet_count; ++t)
    for (int p = 0; p < 6; ++p) {
      int32_t a = tets[4 * t + PAIRS[p][0]], b = tets[4 * t + PAIRS[p][1]];
      if (rank[a] < rank[b])
        all[fill[rank[a]]++] = b;
      else
        all[fill[rank[b]]++] = a;
    }
  int32_t edges = 0;
  for (int32_t r = 0; r < nv; ++r) {
    int32_t *row = all + count[r], len = count[r + 1] - count[r];
    sort_row(row, len);
    m->row_start[r] = edges;
    for (int32_t k = 0; k < len; ++k)
      if (k == 0 || row[k] != row[k - 1]) all[edges++] = row[k];
  }
  m->row_start[nv] = edges;
  m->edge_count = edges;
  free(count);
  int32_t *col = realloc(all, sizeof(int32_t) * (size_t)(edges > 0 ? edges : 1));
  m->col = col ? col : all;
  return PIOLA_OK;
}

/* For each row, its edges to vertices ranked before it, as (edge, other vertex), in
 * increasing edge order. */
static piola_status build_lower(piola__damping_matrix *m) {
  int32_t nv = m->vertex_count;
  size_t ne = (size_t)(m->edge_count > 0 ? m->edge_count : 1);
  int32_t *fill = calloc((size_t)nv + 1, sizeof(int32_t));
  m->lower_edge = malloc(sizeof(int32_t) * ne);
  m->lower_col = malloc(sizeof(int32_t) * ne);
  if (!fill || !m->lower_edge || !m->lower_col) {
    free(fill);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "damping matrix: out of memory");
  }
  memset(m->lower_start, 0, sizeof(int32_t) * ((size_t)nv + 1));
  for (int32_t k = 0; k < m->edge_count; ++k) m->lower_start[m->rank[m->col[k]] + 1]++;
  for (int32_t r = 0; r < nv; ++r) m->lower_start[r + 1] += m->lower_start[r];
  for (int32_t r = 0; r < nv; ++r)
    for (int32_t k = m->row_start[r]; k < m->row_start[r + 1]; ++k) {
      int32_t rj = m->rank[m->col[k]];
      int32_t slot = m->lower_start[rj] + fill[rj]++;
      m->lower_edge[slot] = k;
      m->lower_col[slot] = m->order[r];
    }
  free(fill);
  return PIOLA_OK;
}

static int32_t degree(const piola__damping_matrix *m, int32_t i) {
  int32_t r = m->rank[i];
  return m->row_start[r + 1] - m->row_start[r] + m->lower_start[r + 1] - m->lower_start[r];
}

/* Breadth-first order from start over the unvisited vertices of its component, neighbors
 * by increasing degree (Cuthill-McKee); appends to order from *count. Returns the last
 * vertex reached. */
static int32_t breadth_first(const piola__damping_matrix *m, int32_t start, uint8_t *visited,
                             int32_t *order, int32_t *count) {
  int32_t head = *count, last = start;
  order[(*count)++] = start;
  visited[start] = 1;
  while (head < *count) {
    int32_t i = order[head++], r = m->rank[i], first = *count;
    last = i;
    for (int32_t k = m->row_start[r]; k < m->row_start[r + 1]; ++k)
      if (!visited[m->col[k]]) visited[m->col[k]] = 1, order[(*count)++] = m->col[k];
    for (int32_t k = m->lower_start[r]; k < m->lower_start[r + 1]; ++k)
      if (!visited[m->lower_col[k]])
        visited[m->lower_col[k]] = 1, order[(*count)++] = m->lower_col[k];
    /* insertion sort of the new ones by degree, then index */
    for (int32_t a = first + 1; a < *count; ++a) {
      int32_t v = order[a], b = a, dv = degree(m, v);
      while (b > first) {
        int32_t u = order[b - 1], du = degree(m, u);
        if (du < dv || (du == dv && u < v)) break;
        order[b] = u;
        --b;
      }
      order[b] = v;
    }
  }
  return last;
}

/* The mean distance in rank between the ends of an edge, under rank (NULL: the rows' own). */
static double edge_spread(const piola__damping_matrix *m, const int32_t *rank) {
  double sum = 0;
  for (int32_t r = 0; r < m->vertex_count; ++r)
    for (int32_t k = m->row_start[r]; k < m->row_start[r + 1]; ++k) {
      int32_t a = m->order[r], b = m->col[k];
      sum += rank ? abs(rank[a] - rank[b]) : abs(m->rank[a] - m->rank[b]);
    }
  return m->edge_count > 0 ? sum / m->edge_count : 0.0;
}

/* Reverse Cuthill-McKee ranks of the vertices, from the rows built in index order: the
 * product then reads the blocks of a row's earlier edges soon after their own row read
 * them, so from cache, whatever order the mesh file had. Each component starts from the
 * far end of a first sweep (a pseudo-peripheral vertex). */
static piola_status rank_vertices(piola__damping_matrix *m, int32_t *rank) {
  int32_t nv = m->vertex_count, count = 0;
  uint8_t *visited = calloc((size_t)nv + 1, 1);
  int32_t *order = malloc(sizeof(int32_t) * ((size_t)nv + 1));
  if (!visited || !order) {
    free(visited);
    free(order);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "damping matrix: out of memory");
  }
  for (int32_t i = 0; i < nv; ++i) {
    if (visited[i]) continue;
    int32_t begin = count;
    int32_t far = breadth_first(m, i, visited, order, &count);
    for (int32_t k = begin; k < count; ++k) visited[order[k]] = 0;
    count = begin;
    breadth_first(m, far, visited, order, &count);
  }
  for (int32_t k = 0; k < nv; ++k) rank[order[nv - 1 - k]] = k;
  free(visited);
  free(order);
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
  m->blocks = malloc(sizeof(double) * 9 * (size_t)slots);
  uint8_t *written = calloc((size_t)slots, 1);
  if (!m->shared_edge || !m->shared_slot_start || !m->blocks || !written) {
    free(last);
    free(parts);
    free(written);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "damping matrix: out of memory");
  }
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
  m->rank = malloc(sizeof(int32_t) * ((size_t)nv + 1));
  m->order = malloc(sizeof(int32_t) * ((size_t)nv + 1));
  m->tet_slot = malloc(sizeof(int32_t) * 6 * (size_t)(nt > 0 ? nt : 1));
  m->tet_flags = calloc((size_t)(nt > 0 ? nt : 1), sizeof(uint16_t));
  int32_t *tet_edge = malloc(sizeof(int32_t) * 6 * (size_t)(nt > 0 ? nt : 1));
  int32_t *rank = malloc(sizeof(int32_t) * ((size_t)nv + 1));
  piola_status st = PIOLA_OK;
  if (!m->row_start || !m->lower_start || !m->rank || !m->order || !m->tet_slot || !m->tet_flags ||
      !tet_edge || !rank)
    st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "damping matrix: out of memory");
  /* rows in index order first, for the adjacency the ranking walks; then in rank order */
  for (int pass = 0; pass < 2 && st == PIOLA_OK; ++pass) {
    for (int32_t i = 0; i < nv; ++i) m->rank[i] = pass ? rank[i] : i;
    for (int32_t i = 0; i < nv; ++i) m->order[m->rank[i]] = i;
    free(m->col), free(m->lower_edge), free(m->lower_col);
    m->col = m->lower_edge = m->lower_col = NULL;
    st = build_rows(m, body->tets, nt);
    if (st == PIOLA_OK) st = build_lower(m);
    if (st == PIOLA_OK && pass == 0) {
      st = rank_vertices(m, rank);
      /* keep the file's numbering where it is about as local already (a structured or
       * TetGen mesh often is, and the tets' order follows it, which the assembly likes) */
      if (st == PIOLA_OK && edge_spread(m, rank) * 2 > edge_spread(m, NULL)) break;
    }
  }
  for (int32_t t = 0; t < nt && st == PIOLA_OK; ++t)
    for (int p = 0; p < 6; ++p) {
      int32_t a = body->tets[4 * t + PAIRS[p][0]], b = body->tets[4 * t + PAIRS[p][1]];
      tet_edge[6 * t + p] = find_edge(m, a, b);
      if (m->rank[a] > m->rank[b]) m->tet_flags[t] |= (uint16_t)(1u << p);
    }
  if (st == PIOLA_OK) st = build_slots(m, nt, body->padded_tet_count / PIOLA_TET_BLOCK, tet_edge);
  free(tet_edge);
  free(rank);
  if (st != PIOLA_OK) piola__damping_matrix_free(m);
  return st;
}

void piola__damping_matrix_free(piola__damping_matrix *m) {
  free(m->row_start);
  free(m->rank);
  free(m->order);
  free(m->col);
  free(m->lower_start);
  free(m->lower_edge);
  free(m->lower_col);
  free(m->tet_slot);
  free(m->tet_flags);
  free(m->shared_edge);
  free(m->shared_slot_start);
  free(m->blocks);
  memset(m, 0, sizeof *m);
}
