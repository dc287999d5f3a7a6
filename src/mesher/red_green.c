#include "mesher/red_green.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "mesher/tet_topology.h"
#include "piola/threads.h"

/* Edge -> midpoint vertex, open addressing on the packed sorted pair. */
typedef struct edge_map {
  uint64_t *keys; /* 0 = empty (vertex pair (0, 0) never occurs) */
  int32_t *values;
  size_t capacity, count;
} edge_map;

static uint64_t edge_key(int32_t a, int32_t b) {
  return a < b ? ((uint64_t)a << 32 | (uint32_t)b) : ((uint64_t)b << 32 | (uint32_t)a);
}

static size_t edge_slot(uint64_t key, size_t capacity) {
  uint64_t x = key * 0x9E3779B97F4A7C15ull;
  return (size_t)(x >> 17) & (capacity - 1);
}

static int32_t edge_map_get(const edge_map *m, int32_t a, int32_t b) {
  uint64_t key = edge_key(a, b);
  for (size_t i = edge_slot(key, m->capacity);; i = (i + 1) & (m->capacity - 1)) {
    if (m->keys[i] == key) return m->values[i];
    if (m->keys[i] == 0) return -1;
  }
}

static int edge_map_grow(edge_map *m) {
  size_t cap = m->capacity ? m->capacity * 2 : 1 << 16;
  uint64_t *keys = calloc(cap, sizeof(uint64_t));
  int32_t *values = malloc(cap * sizeof(int32_t));
  if (!keys || !values) {
    free(keys);
    free(values);
    return 0;
  }
  for (size_t i = 0; i < m->capacity; ++i) {
    if (!m->keys[i]) continue;
    size_t j = edge_slot(m->keys[i], cap);
    while (keys[j]) j = (j + 1) & (cap - 1);
    keys[j] = m->keys[i];
    values[j] = m->values[i];
  }
  free(m->keys);
  free(m->values);
  m->keys = keys;
  m->values = values;
  m->capacity = cap;
  return 1;
}

typedef struct refiner {
  piola__tet_soup *soup;
  uint8_t *level;   /* per tet */
  uint8_t *alive;   /* per tet: 1 = a leaf */
  edge_map edges;
  int failed;
} refiner;

static int reserve_tets(refiner *r, int32_t extra) {
  piola__tet_soup *s = r->soup;
  if ((int64_t)s->tet_count + extra <= s->tet_capacity) return 1;
  int64_t cap = (int64_t)s->tet_capacity * 2 + extra;
  if (cap > INT32_MAX / 4) return 0;
  int32_t *tets = realloc(s->tets, (size_t)cap * 4 * sizeof(int32_t));
  if (!tets) return 0;
  s->tets = tets;
  uint8_t *level = realloc(r->level, (size_t)cap);
  if (!level) return 0;
  r->level = level;
  uint8_t *alive = realloc(r->alive, (size_t)cap);
  if (!alive) return 0;
  r->alive = alive;
  s->tet_capacity = (int32_t)cap;
  return 1;
}

static int32_t midpoint(refiner *r, int32_t a, int32_t b) {
  int32_t found = edge_map_get(&r->edges, a, b);
  if (found >= 0) return found;
  piola__tet_soup *s = r->soup;
  if ((r->edges.count + 1) * 2 > r->edges.capacity && !edge_map_grow(&r->edges)) {
    r->failed = 1;
    return a;
  }
  if (s->vertex_count == s->vertex_capacity) {
    int64_t cap = (int64_t)s->vertex_capacity * 2 + 1024;
    if (cap > INT32_MAX / 4) {
      r->failed = 1;
      return a;
    }
    double *p = realloc(s->positions, (size_t)cap * 3 * sizeof(double));
    if (p) s->positions = p;
    double *phi = realloc(s->phi, (size_t)cap * sizeof(double));
    if (phi) s->phi = phi;
    if (!p || !phi) {
      r->failed = 1;
      return a;
    }
    s->vertex_capacity = (int32_t)cap;
  }
  int32_t v = s->vertex_count++;
  vec3 x = vec3_scale(vec3_add(vec3_load(s->positions + 3 * (size_t)a), vec3_load(s->positions + 3 * (size_t)b)), 0.5);
  vec3_store(s->positions + 3 * (size_t)v, x);
  s->phi[v] = NAN; /* evaluated in parallel later */
  uint64_t key = edge_key(a, b);
  size_t i = edge_slot(key, r->edges.capacity);
  while (r->edges.keys[i]) i = (i + 1) & (r->edges.capacity - 1);
  r->edges.keys[i] = key;
  r->edges.values[i] = v;
  r->edges.count++;
  return v;
}

static vec3 pos(const refiner *r, int32_t v) { return vec3_load(r->soup->positions + 3 * (size_t)v); }

/* Appends a tet, swapping two vertices if it came out negatively oriented. */
static void add_tet(refiner *r, int32_t a, int32_t b, int32_t c, int32_t d, uint8_t level) {
  piola__tet_soup *s = r->soup;
  if (piola__tet_volume(pos(r, a), pos(r, b), pos(r, c), pos(r, d)) < 0) {
    int32_t t = c;
    c = d;
    d = t;
  }
  int32_t *tet = s->tets + 4 * (size_t)s->tet_count;
  tet[0] = a;
  tet[1] = b;
  tet[2] = c;
  tet[3] = d;
  r->level[s->tet_count] = level;
  r->alive[s->tet_count] = 1;
  s->tet_count++;
}

/* Local edges of a tet: (0,1) (0,2) (0,3) (1,2) (1,3) (2,3). */
static const int edge_ends[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

static void red_refine(refiner *r, int32_t t) {
  if (!reserve_tets(r, 8)) {
    r->failed = 1;
    return;
  }
  int32_t v[4];
  memcpy(v, r->soup->tets + 4 * (size_t)t, sizeof v);
  int32_t m[6];
  for (int e = 0; e < 6; ++e) m[e] = midpoint(r, v[edge_ends[e][0]], v[edge_ends[e][1]]);
  if (r->failed) return;
  uint8_t level = (uint8_t)(r->level[t] + 1);
  r->alive[t] = 0;
  /* m indices: 0:01 1:02 2:03 3:12 4:13 5:23 */
  add_tet(r, v[0], m[0], m[1], m[2], level);
  add_tet(r, m[0], v[1], m[3], m[4], level);
  add_tet(r, m[1], m[3], v[2], m[5], level);
  add_tet(r, m[2], m[4], m[5], v[3], level);
  /* The inner octahedron, cut along its shortest diagonal (the BCC-consistent one). */
  static const int diagonal[3][2] = {{0, 5}, {1, 4}, {2, 3}};
  static const int ring[3][4] = {{1, 2, 4, 3}, {0, 2, 5, 3}, {0, 1, 5, 4}};
  int best = 0;
  double best_len = INFINITY;
  for (int d = 0; d < 3; ++d) {
    double len = vec3_norm2(vec3_sub(pos(r, m[diagonal[d][0]]), pos(r, m[diagonal[d][1]])));
    if (len < best_len * (1 - 1e-9)) {
      best_len = len;
      best = d;
    }
  }
  for (int k = 0; k < 4; ++k)
    add_tet(r, m[diagonal[best][0]], m[diagonal[best][1]], m[ring[best][k]], m[ring[best][(k + 1) % 4]], level);
}

/* Split edges of leaf t as a bit mask; sets *double_split when a half of a split edge is
 * itself split (a jump of two levels across that edge). */
static int split_mask(const refiner *r, int32_t t, int *double_split) {
  const int32_t *v = r->soup->tets + 4 * (size_t)t;
  int mask = 0;
  *double_split = 0;
  for (int e = 0; e < 6; ++e) {
    int32_t a = v[edge_ends[e][0]], b = v[edge_ends[e][1]];
    int32_t mid = edge_map_get(&r->edges, a, b);
    if (mid < 0) continue;
    mask |= 1 << e;
    if (edge_map_get(&r->edges, a, mid) >= 0 || edge_map_get(&r->edges, mid, b) >= 0) *double_split = 1;
  }
  return mask;
}

/* The masks of the three edges of each face, and the vertex opposite it. */
static int face_mask(int f) {
  int mask = 0;
  for (int e = 0; e < 6; ++e)
    if (edge_ends[e][0] != 3 - f && edge_ends[e][1] != 3 - f) mask |= 1 << e;
  return mask;
}

static int popcount6(int mask) {
  int n = 0;
  for (int e = 0; e < 6; ++e) n += (mask >> e) & 1;
  return n;
}

static int green_pattern(int mask) {
  int n = popcount6(mask);
  if (n <= 2) return 1; /* one edge, two edges of a face, or two opposite edges */
  for (int f = 0; f < 4; ++f)
    if (mask == face_mask(f)) return 1;
  return 0;
}

static void evaluate_new_phi(piola__tet_soup *s, const piola__shape_union *shapes) {
#pragma omp parallel for schedule(dynamic, 256) num_threads(piola_thread_count())
  for (int32_t v = 0; v < s->vertex_count; ++v)
    if (isnan(s->phi[v])) s->phi[v] = piola__shape_union_phi(shapes, vec3_load(s->positions + 3 * (size_t)v), NULL);
}

static void green_close(refiner *r, int32_t t, int mask) {
  if (!reserve_tets(r, 4)) {
    r->failed = 1;
    return;
  }
  int32_t v[4];
  memcpy(v, r->soup->tets + 4 * (size_t)t, sizeof v);
  uint8_t level = r->level[t];
  r->alive[t] = 0;
  if ((mask & (mask - 1)) == 0) {
    int e = 0;
    while (!(mask & (1 << e))) ++e;
    int i = edge_ends[e][0], j = edge_ends[e][1];
    int32_t m = edge_map_get(&r->edges, v[i], v[j]);
    int32_t a[4], b[4];
    memcpy(a, v, sizeof a);
    memcpy(b, v, sizeof b);
    a[i] = m;
    b[j] = m;
    add_tet(r, a[0], a[1], a[2], a[3], level);
    add_tet(r, b[0], b[1], b[2], b[3], level);
    return;
  }
  if (popcount6(mask) == 2) {
    int e1 = 0, e2;
    while (!(mask & (1 << e1))) ++e1;
    e2 = e1 + 1;
    while (!(mask & (1 << e2))) ++e2;
    int i1 = edge_ends[e1][0], j1 = edge_ends[e1][1], i2 = edge_ends[e2][0], j2 = edge_ends[e2][1];
    int32_t m1 = edge_map_get(&r->edges, v[i1], v[j1]), m2 = edge_map_get(&r->edges, v[i2], v[j2]);
    int shared = (i1 == i2 || i1 == j2) ? i1 : ((j1 == i2 || j1 == j2) ? j1 : -1);
    if (shared < 0) {
      /* Opposite edges: bisect by the first, then each half by the second. */
      int32_t a[4], b[4];
      memcpy(a, v, sizeof a);
      memcpy(b, v, sizeof b);
      a[i1] = m1;
      b[j1] = m1;
      int32_t halves[2][4];
      memcpy(halves[0], a, sizeof a);
      memcpy(halves[1], b, sizeof b);
      for (int h = 0; h < 2; ++h) {
        int32_t c[4], d[4];
        memcpy(c, halves[h], sizeof c);
        memcpy(d, halves[h], sizeof d);
        c[i2] = m2;
        d[j2] = m2;
        add_tet(r, c[0], c[1], c[2], c[3], level);
        add_tet(r, d[0], d[1], d[2], d[3], level);
      }
      return;
    }
    /* Two edges of one face meeting at `shared`: cut the corner there, and split the
     * remaining pyramid along the diagonal of its quad that both tets sharing the face
     * choose (the shorter one; ties broken by vertex ids, so the choice depends on the face
     * alone). */
    int x1 = i1 == shared ? j1 : i1, x2 = i2 == shared ? j2 : i2;
    int apex = 0 + 1 + 2 + 3 - shared - x1 - x2;
    double l1 = vec3_norm2(vec3_sub(pos(r, m1), pos(r, v[x2])));
    double l2 = vec3_norm2(vec3_sub(pos(r, m2), pos(r, v[x1])));
    int use_m1;
    if (fabs(l1 - l2) > 1e-9 * (l1 + l2))
      use_m1 = l1 < l2;
    else
      use_m1 = v[x1] < v[x2];
    add_tet(r, v[shared], m1, m2, v[apex], level);
    if (use_m1) {
      add_tet(r, m1, v[x1], v[x2], v[apex], level);
      add_tet(r, m1, v[x2], m2, v[apex], level);
    } else {
      add_tet(r, m2, v[x1], v[x2], v[apex], level);
      add_tet(r, m1, v[x1], m2, v[apex], level);
    }
    return;
  }
  int f = 0;
  while (mask != face_mask(f)) ++f;
  int d = 3 - f, p = (d + 1) % 4, q = (d + 2) % 4, s = (d + 3) % 4;
  int32_t mpq = edge_map_get(&r->edges, v[p], v[q]);
  int32_t mqs = edge_map_get(&r->edges, v[q], v[s]);
  int32_t msp = edge_map_get(&r->edges, v[s], v[p]);
  add_tet(r, v[d], v[p], mpq, msp, level);
  add_tet(r, v[d], mpq, v[q], mqs, level);
  add_tet(r, v[d], msp, mqs, v[s], level);
  add_tet(r, v[d], mpq, mqs, msp, level);
}

piola_status piola__red_green_refine(piola__tet_soup *soup, const piola__shape_union *shapes,
                                     int levels, double cell_size) {
  refiner r = {.soup = soup};
  r.level = calloc((size_t)soup->tet_capacity + 1, 1);
  r.alive = malloc((size_t)soup->tet_capacity + 1);
  if (!r.level || !r.alive || !edge_map_grow(&r.edges)) {
    free(r.level);
    free(r.alive);
    free(r.edges.keys);
    free(r.edges.values);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "mesher: refinement");
  }
  memset(r.alive, 1, (size_t)soup->tet_count);
  for (int l = 0; l < levels && !r.failed; ++l) {
    double hl = cell_size / (double)(1 << l);
    int32_t count = soup->tet_count;
    for (int32_t t = 0; t < count && !r.failed; ++t) {
      if (!r.alive[t] || r.level[t] != l) continue;
      const int32_t *v = soup->tets + 4 * (size_t)t;
      double lo = INFINITY, hi = -INFINITY, near = INFINITY;
      for (int k = 0; k < 4; ++k) {
        double p = soup->phi[v[k]];
        lo = fmin(lo, p);
        hi = fmax(hi, p);
        near = fmin(near, fabs(p));
      }
      if ((lo <= 0 && hi >= 0) || near < 0.5 * hl) red_refine(&r, t);
    }
    /* Closure: red-refine leaves that no green pattern can close. */
    for (int changed = 1; changed && !r.failed;) {
      changed = 0;
      int32_t n = soup->tet_count;
      for (int32_t t = 0; t < n && !r.failed; ++t) {
        if (!r.alive[t]) continue;
        int twice;
        int mask = split_mask(&r, t, &twice);
        if (twice || !green_pattern(mask)) {
          red_refine(&r, t);
          changed = 1;
        }
      }
    }
    evaluate_new_phi(soup, shapes);
  }
  int32_t n = soup->tet_count;
  for (int32_t t = 0; t < n && !r.failed; ++t) {
    if (!r.alive[t]) continue;
    int twice;
    int mask = split_mask(&r, t, &twice);
    if (mask) green_close(&r, t, mask);
  }
  piola_status status = PIOLA_OK;
  if (r.failed) {
    status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "mesher: refinement ran out of memory");
  } else {
    /* Drop the refined parents. */
    int32_t kept = 0;
    for (int32_t t = 0; t < soup->tet_count; ++t) {
      if (!r.alive[t]) continue;
      memmove(soup->tets + 4 * (size_t)kept, soup->tets + 4 * (size_t)t, 4 * sizeof(int32_t));
      kept++;
    }
    soup->tet_count = kept;
  }
  free(r.level);
  free(r.alive);
  free(r.edges.keys);
  free(r.edges.values);
  return status;
}
