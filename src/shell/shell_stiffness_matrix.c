/* A shell's implicit system matrix (shell_stiffness.h): its pattern, the assembly of the
 * element derivatives in edge-difference form, and the product. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "math/mat3.h"
#include "piola/threads.h"
#include "shell/shell_body_internal.h"
#include "shell/shell_stiffness.h"

/* Ordered vertex pairs (a, b), a != b, of a triangle and of a hinge, in slot order. */
static const int TRIANGLE_PAIRS[6][2] = {{0, 1}, {0, 2}, {1, 0}, {1, 2}, {2, 0}, {2, 1}};
static int hinge_pair(int k, int *b) {
  const int a = k / 3, r = k % 3;
  *b = r < a ? r : r + 1;
  return a;
}

/* Rows with fewer vertices than this are computed on one thread. */
#define SHELL_MATRIX_PARALLEL_MIN_VERTICES 4096
#define RANGES 16

static int compare_int32(const void *a, const void *b) {
  int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
  return (x > y) - (x < y);
}

static int32_t find_entry(const shell_matrix_pattern *p, int32_t a, int32_t b) {
  const int32_t *row = p->col + p->row_start[a];
  const int32_t *hit = bsearch(&b, row, (size_t)(p->row_start[a + 1] - p->row_start[a]),
                               sizeof(int32_t), compare_int32);
  return (int32_t)(hit - p->col);
}

static piola_status build_pattern(piola_shell_body *body) {
  const int32_t nv = body->vertex_count, nt = body->triangle_count, nh = body->hinge_count;
  shell_matrix_pattern *p = calloc(1, sizeof *p);
  int32_t *count = calloc((size_t)nv + 1, sizeof(int32_t));
  const size_t pairs = 6 * (size_t)nt + 12 * (size_t)nh;
  int32_t *all = malloc(sizeof(int32_t) * (pairs > 0 ? pairs : 1));
  if (p) {
    p->row_start = calloc((size_t)nv + 1, sizeof(int32_t));
    p->triangle_slot = malloc(sizeof(int32_t) * 6 * (size_t)(nt > 0 ? nt : 1));
    p->hinge_slot = malloc(sizeof(int32_t) * 12 * (size_t)(nh > 0 ? nh : 1));
  }
  if (!p || !count || !all || !p->row_start || !p->triangle_slot || !p->hinge_slot) {
    if (p) free(p->row_start), free(p->triangle_slot), free(p->hinge_slot);
    free(p), free(count), free(all);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "shell matrix pattern: out of memory");
  }
  /* every ordered pair of every element, bucketed by its first vertex */
  for (int32_t t = 0; t < nt; ++t)
    for (int k = 0; k < 6; ++k) count[body->triangles[t].v[TRIANGLE_PAIRS[k][0]] + 1]++;
  for (int32_t h = 0; h < nh; ++h)
    for (int k = 0; k < 12; ++k) {
      int b;
      count[body->hinges[h].v[hinge_pair(k, &b)] + 1]++;
    }
  for (int32_t i = 0; i < nv; ++i) count[i + 1] += count[i];
  int32_t *fill = p->row_start; /* scratch: each row's write position */
  memcpy(fill, count, sizeof(int32_t) * (size_t)nv);
  for (int32_t t = 0; t < nt; ++t)
    for (int k = 0; k < 6; ++k) {
      const int32_t *v = body->triangles[t].v;
      all[fill[v[TRIANGLE_PAIRS[k][0]]]++] = v[TRIANGLE_PAIRS[k][1]];
    }
  for (int32_t h = 0; h < nh; ++h)
    for (int k = 0; k < 12; ++k) {
      int b;
      const int a = hinge_pair(k, &b);
      all[fill[body->hinges[h].v[a]]++] = body->hinges[h].v[b];
    }
  int32_t entries = 0;
  for (int32_t i = 0; i < nv; ++i) {
    int32_t *row = all + count[i], len = count[i + 1] - count[i];
    qsort(row, (size_t)len, sizeof(int32_t), compare_int32);
    p->row_start[i] = entries;
    for (int32_t k = 0; k < len; ++k)
      if (k == 0 || row[k] != row[k - 1]) all[entries++] = row[k];
  }
  p->row_start[nv] = entries;
  p->entry_count = entries;
  free(count);
  int32_t *col = realloc(all, sizeof(int32_t) * (size_t)(entries > 0 ? entries : 1));
  p->col = col ? col : all;
  for (int32_t t = 0; t < nt; ++t)
    for (int k = 0; k < 6; ++k) {
      const int32_t *v = body->triangles[t].v;
      p->triangle_slot[6 * t + k] = find_entry(p, v[TRIANGLE_PAIRS[k][0]], v[TRIANGLE_PAIRS[k][1]]);
    }
  for (int32_t h = 0; h < nh; ++h)
    for (int k = 0; k < 12; ++k) {
      int b;
      const int a = hinge_pair(k, &b);
      p->hinge_slot[12 * h + k] = find_entry(p, body->hinges[h].v[a], body->hinges[h].v[b]);
    }
  body->pattern = p;
  return PIOLA_OK;
}

piola_status piola__shell_stiffness_matrix_init(piola__stiffness_matrix *m, piola_shell_body *body) {
  memset(m, 0, sizeof *m);
  if (!body->pattern) PIOLA_TRY(build_pattern(body));
  const size_t nv = (size_t)(body->vertex_count > 0 ? body->vertex_count : 1);
  m->vertex_count = body->vertex_count;
  m->slot_count = body->pattern->entry_count;
  m->blocks = malloc(sizeof(double) * 9 * (size_t)(m->slot_count > 0 ? m->slot_count : 1));
  m->diagonal = malloc(sizeof(double) * 9 * nv);
  m->inverse_diagonal = malloc(sizeof(double) * 9 * nv);
  if (!m->blocks || !m->diagonal || !m->inverse_diagonal) {
    piola__stiffness_matrix_free(m);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "shell matrix: out of memory");
  }
  return PIOLA_OK;
}

/* blocks[slot] += weight * the (a, b) block of an element matrix of `size` vertices. */
static void add_block(double *blocks, int32_t slot, const double *element, int size, int a, int b,
                      double weight) {
  double *dst = blocks + 9 * (size_t)slot;
  const int stride = 3 * size;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) dst[3 * i + j] += weight * element[stride * (3 * a + i) + 3 * b + j];
}

void piola__shell_stiffness_matrix_assemble(piola__stiffness_matrix *m, const piola_shell_body *body,
                                            double stiffness_weight, double damping_weight,
                                            double beta, double alpha, const double *mass,
                                            double mass_weight) {
  const shell_matrix_pattern *p = body->pattern;
  memset(m->blocks, 0, sizeof(double) * 9 * (size_t)m->slot_count);
  const int damp_plane = damping_weight != 0 && (beta != 0 || alpha != 0);
  double k[144], d[144];
  for (int32_t t = 0; t < body->triangle_count; ++t) {
    piola__shell_triangle_stiffness(body, t, 1, k);
    if (damp_plane) piola__shell_triangle_damping(body, t, beta, alpha, d);
    for (int s = 0; s < 6; ++s) {
      const int a = TRIANGLE_PAIRS[s][0], b = TRIANGLE_PAIRS[s][1];
      const int32_t slot = p->triangle_slot[6 * t + s];
      add_block(m->blocks, slot, k, 3, a, b, stiffness_weight);
      if (damp_plane) add_block(m->blocks, slot, d, 3, a, b, damping_weight);
    }
  }
  const int bend = body->bending.stiffness > 0 && stiffness_weight != 0;
  const int damp_bend = body->bending.damping > 0 && damping_weight != 0;
  for (int32_t h = 0; h < body->hinge_count && (bend || damp_bend); ++h) {
    if (bend) piola__shell_hinge_stiffness(body, h, k);
    if (damp_bend) piola__shell_hinge_damping(body, h, d);
    for (int s = 0; s < 12; ++s) {
      int b;
      const int a = hinge_pair(s, &b);
      const int32_t slot = p->hinge_slot[12 * h + s];
      if (bend) add_block(m->blocks, slot, k, 4, a, b, stiffness_weight);
      if (damp_bend) add_block(m->blocks, slot, d, 4, a, b, damping_weight);
    }
  }
  /* diagonal blocks: A_ii = m_w m_i I + sum_j S_ij (rows sum to zero) */
  for (int32_t i = 0; i < body->vertex_count; ++i) {
    double a[9] = {0};
    for (int32_t e = p->row_start[i]; e < p->row_start[i + 1]; ++e)
      for (int c = 0; c < 9; ++c) a[c] += m->blocks[9 * (size_t)e + c];
    for (int c = 0; c < 3; ++c) a[4 * c] += mass_weight * mass[i];
    memcpy(m->diagonal + 9 * (size_t)i, a, sizeof a);
    piola__invert3_or_diagonal(a, m->inverse_diagonal + 9 * (size_t)i);
  }
}

void piola__shell_stiffness_matrix_apply(const piola__stiffness_matrix *m,
                                         const piola_shell_body *body, const double *mass,
                                         double mass_weight, const double *p, double *out) {
  const shell_matrix_pattern *pt = body->pattern;
  const int32_t nv = body->vertex_count;
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) \
    if (nv >= SHELL_MATRIX_PARALLEL_MIN_VERTICES)
  for (int r = 0; r < RANGES; ++r)
    for (int32_t i = (int32_t)((int64_t)nv * r / RANGES); i < (int32_t)((int64_t)nv * (r + 1) / RANGES); ++i) {
      const double p0 = p[3 * i], p1 = p[3 * i + 1], p2 = p[3 * i + 2];
      double f0 = 0, f1 = 0, f2 = 0;
      for (int32_t e = pt->row_start[i]; e < pt->row_start[i + 1]; ++e) {
        const double *a = m->blocks + 9 * (size_t)e, *pj = p + 3 * (size_t)pt->col[e];
        const double d0 = pj[0] - p0, d1 = pj[1] - p1, d2 = pj[2] - p2;
        f0 += a[0] * d0 + a[1] * d1 + a[2] * d2;
        f1 += a[3] * d0 + a[4] * d1 + a[5] * d2;
        f2 += a[6] * d0 + a[7] * d1 + a[8] * d2;
      }
      const double mi = mass_weight * mass[i];
      out[3 * i] = mi * p0 - f0;
      out[3 * i + 1] = mi * p1 - f1;
      out[3 * i + 2] = mi * p2 - f2;
    }
}
