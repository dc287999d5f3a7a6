/* The plastic state: creation, the once-per-step update (return mapping, limit, control)
 * and measurements. Design in plastic_state.h, return_mapping.h and plasticity_control.h. */
#include "plasticity/plastic_state.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "force/effective_dm_inv.h"
#include "force/elastic_body_internal.h"
#include "piola/diagonalize.h"
#include "plasticity/plasticity_control.h"

piola_plasticity_def piola_default_plasticity_def(void) {
  piola_plasticity_def def;
  memset(&def, 0, sizeof def);
  def.yield = 0.05;
  def.limit = 1.0;
  def.hardening = 0.0;
  def.volume_preserving = false;
  def.control.goal = PIOLA_PLASTIC_GOAL_NONE;
  def.control.goal_map = (piola_mat3){{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  def.control.strength = 0.0;
  return def;
}

static void mul33(const double a[9], const double b[9], double out[9]) {
  double r[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
  memcpy(out, r, sizeof r);
}

static double det33(const double a[9]) {
  return a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
         a[2] * (a[3] * a[7] - a[4] * a[6]);
}

/* The interval of Fhat entries inside which tet t cannot yield (plastic_state.h). */
static void quick_bounds(const piola_plastic_state *s, int32_t t, double *lo, double *hi) {
  if (s->params.hardening == 0) {
    *lo = s->quick_lo0, *hi = s->quick_hi0;
    return;
  }
  double r = (s->params.yield + s->params.hardening * s->alpha[t]) / sqrt(3.0);
  *lo = exp(-r), *hi = exp(r);
}

static void rest_dm_inv(const piola_plastic_state *s, int32_t t, double out[9]) {
  for (int k = 0; k < 9; ++k) out[k] = piola__plastic_rest_entry(s, t, k);
}

void piola__plastic_commit_tet(piola_plastic_state *s, int32_t t) {
  double eff[9], rest[9];
  rest_dm_inv(s, t, rest);
  mul33(rest, s->fp_inv + 9 * t, eff);
  piola__elastic_body_set_dm_inv(s->body, t, eff);
}

static piola_status validate(const piola_elastic_body *body, const piola_plasticity_def *def) {
  if (!body || !def) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "plasticity: NULL argument");
  if (!(def->yield > 0) || !isfinite(def->yield))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "plasticity yield must be > 0 (log strain), got %g",
                      def->yield);
  if (!(def->limit > 0) || !isfinite(def->limit) || def->limit > 20)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "plasticity limit must be in (0, 20] (log stretch), got %g",
                      def->limit);
  if (!(def->hardening >= 0) || !isfinite(def->hardening))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "plasticity hardening must be >= 0, got %g",
                      def->hardening);
  const piola_plasticity_control_def *c = &def->control;
  if ((int)c->goal < 0 || c->goal > PIOLA_PLASTIC_GOAL_MESH)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "plasticity control goal type %d is unknown", (int)c->goal);
  if (c->goal != PIOLA_PLASTIC_GOAL_NONE) {
    if (def->volume_preserving)
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "plasticity volume_preserving cannot be used with control (the goal rarely "
                        "preserves volume)");
    if (!(c->strength >= 0) || !isfinite(c->strength))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "plasticity control strength must be >= 0 1/s, got %g",
                        c->strength);
  }
  if (c->goal == PIOLA_PLASTIC_GOAL_MESH) {
    if (!c->goal_positions)
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "plasticity control goal mesh has no positions");
    if (c->goal_vertex_count != piola_elastic_body_vertex_count(body))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "plasticity control goal mesh has %d vertices, the solid has %d",
                        (int)c->goal_vertex_count, (int)piola_elastic_body_vertex_count(body));
    for (int32_t i = 0; i < 3 * c->goal_vertex_count; ++i)
      if (!isfinite(c->goal_positions[i]))
        return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "plasticity control goal vertex %d is not finite", (int)(i / 3));
  }
  return PIOLA_OK;
}

/* Goal Fp of tet t: the goal map, or Dg Dm^-1 of the goal mesh. */
static void goal_fp(const piola_elastic_body *body, const piola_plastic_state *s,
                    const piola_plasticity_control_def *c, int32_t t, double fp[9]) {
  if (c->goal == PIOLA_PLASTIC_GOAL_MAP) {
    for (int k = 0; k < 9; ++k) fp[k] = c->goal_map.m[k / 3][k % 3];
    return;
  }
  const int32_t *idx = piola_elastic_body_tets(body) + 4 * t;
  const double *g = c->goal_positions;
  double dg[9], rest[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) dg[3 * i + j] = g[3 * idx[j + 1] + i] - g[3 * idx[0] + i];
  rest_dm_inv(s, t, rest);
  mul33(dg, rest, fp);
}

void piola_plastic_state_destroy(piola_plastic_state *s) {
  if (!s) return;
  if (s->body && s->rest_lanes)
    for (int32_t t = 0; t < s->tet_count; ++t) {
      double rest[9];
      rest_dm_inv(s, t, rest);
      piola__elastic_body_set_dm_inv(s->body, t, rest);
    }
  free(s->rest_lanes), free(s->fp_inv), free(s->alpha), free(s->block_bound);
  free(s->stretch_bound), free(s->goal_log), free(s->log_fp);
  free(s);
}

/* Sizes the per-tet arrays of s (params and controlled set) for the tets of body: Fp = I,
 * no plastic strain, bounds 1, the body's current Dm^-1 as the rest one. */
static piola_status allocate_tets(piola_plastic_state *s, const piola_elastic_body *body) {
  int32_t nt = s->tet_count = piola_elastic_body_tet_count(body);
  size_t n = nt > 0 ? (size_t)nt : 1;
  s->padded_count = (nt + PIOLA_PLASTIC_LANES - 1) / PIOLA_PLASTIC_LANES * PIOLA_PLASTIC_LANES;
  size_t np = s->padded_count > 0 ? (size_t)s->padded_count : PIOLA_PLASTIC_LANES;
  s->rest_lanes = calloc(9 * np, sizeof(double));
  s->fp_inv = malloc(9 * np * sizeof(double)); /* padded: the blocked update reads whole blocks */
  s->alpha = calloc(np, sizeof(double));
  s->stretch_bound = malloc(np * sizeof(double));
  s->block_bound = malloc(np / PIOLA_PLASTIC_LANES * sizeof(double));
  if (s->controlled) {
    s->goal_log = malloc(6 * n * sizeof(double));
    s->log_fp = calloc(6 * n, sizeof(double));
  }
  if (!s->rest_lanes || !s->fp_inv || !s->alpha || !s->block_bound || !s->stretch_bound ||
      (s->controlled && (!s->goal_log || !s->log_fp)))
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "plasticity for %d tets: out of memory", (int)nt);
  for (size_t i = 0; i < np; ++i) s->stretch_bound[i] = 1.0;
  for (size_t b = 0; b < np / PIOLA_PLASTIC_LANES; ++b) s->block_bound[b] = 1.0;
  for (size_t t = 0; t < np; ++t)
    for (int k = 0; k < 9; ++k) s->fp_inv[9 * t + k] = (k % 4 == 0) ? 1.0 : 0.0;
  for (int32_t t = 0; t < nt; ++t) {
    double rest[9];
    piola__elastic_body_get_dm_inv(body, t, rest);
    for (int k = 0; k < 9; ++k)
      s->rest_lanes[(size_t)(t / PIOLA_PLASTIC_LANES) * 9 * PIOLA_PLASTIC_LANES + (size_t)k * PIOLA_PLASTIC_LANES +
                    (size_t)(t % PIOLA_PLASTIC_LANES)] = rest[k];
  }
  return PIOLA_OK;
}

piola_status piola_plastic_state_create(piola_elastic_body *body, const piola_plasticity_def *def,
                                        piola_plastic_state **out) {
  if (!out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "plasticity: out is NULL");
  *out = NULL;
  PIOLA_TRY(validate(body, def));
  piola_plastic_state *s = calloc(1, sizeof *s);
  if (!s) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "plasticity: out of memory");
  s->params = (plastic_params){def->yield, def->hardening, def->limit, def->volume_preserving};
  s->limit_cap = exp(def->limit);
  s->quick_lo0 = exp(-def->yield / sqrt(3.0));
  s->quick_hi0 = exp(def->yield / sqrt(3.0));
  s->controlled = def->control.goal != PIOLA_PLASTIC_GOAL_NONE;
  s->strength = def->control.strength;
  piola_status st = allocate_tets(s, body);
  if (st != PIOLA_OK) {
    piola_plastic_state_destroy(s);
    return st;
  }
  const int32_t nt = s->tet_count;
  if (s->controlled) {
    for (int32_t t = 0; t < nt; ++t) {
      double fp[9];
      goal_fp(body, s, &def->control, t, fp);
      if (piola__plastic_goal_log(fp, def->limit, s->goal_log + 6 * t) != PIOLA_OK) {
        piola_plastic_state_destroy(s);
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                          "plasticity control goal of tet %d is flat or inverted (det Fp,goal = %g)",
                          (int)t, det33(fp));
      }
    }
  }
  s->body = body; /* bound only now: destroy on the errors above must not touch the body */
  *out = s;
  return PIOLA_OK;
}

piola_status piola_plastic_state_create_from(piola_elastic_body *body,
                                             const piola_plastic_state *parent,
                                             const int32_t *tet_parent,
                                             piola_plastic_state **out) {
  if (!out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "plasticity: out is NULL");
  *out = NULL;
  if (!body || !parent || !tet_parent)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "plasticity create_from: NULL argument");
  const int32_t nt = piola_elastic_body_tet_count(body);
  for (int32_t t = 0; t < nt; ++t)
    if (tet_parent[t] < -1 || tet_parent[t] >= parent->tet_count || (parent->controlled && tet_parent[t] < 0))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "plasticity create_from: tet %d has parent %d, outside [%d, %d)", (int)t,
                        (int)tet_parent[t], parent->controlled ? 0 : -1, (int)parent->tet_count);
  piola_plastic_state *s = calloc(1, sizeof *s);
  if (!s) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "plasticity: out of memory");
  s->params = parent->params;
  s->limit_cap = parent->limit_cap;
  s->quick_lo0 = parent->quick_lo0, s->quick_hi0 = parent->quick_hi0;
  s->controlled = parent->controlled;
  s->strength = parent->strength;
  piola_status st = allocate_tets(s, body);
  if (st != PIOLA_OK) {
    piola_plastic_state_destroy(s);
    return st;
  }
  for (int32_t t = 0; t < nt; ++t) {
    const int32_t p = tet_parent[t];
    if (p < 0) continue; /* Fp = I, no strain */
    memcpy(s->fp_inv + 9 * t, parent->fp_inv + 9 * (size_t)p, 9 * sizeof(double));
    s->alpha[t] = parent->alpha[p];
    s->stretch_bound[t] = parent->stretch_bound[p];
    if (s->controlled) {
      memcpy(s->goal_log + 6 * t, parent->goal_log + 6 * (size_t)p, 6 * sizeof(double));
      memcpy(s->log_fp + 6 * t, parent->log_fp + 6 * (size_t)p, 6 * sizeof(double));
    }
  }
  for (int32_t b = 0; b < s->padded_count / PIOLA_PLASTIC_LANES; ++b) {
    double m = 1.0;
    for (int l = 0; l < PIOLA_PLASTIC_LANES; ++l) m = fmax(m, s->stretch_bound[PIOLA_PLASTIC_LANES * b + l]);
    s->block_bound[b] = m;
  }
  s->body = body;
  for (int32_t t = 0; t < nt; ++t) piola__plastic_commit_tet(s, t); /* Dm^-1 Fp^-1 */
  *out = s;
  return PIOLA_OK;
}

/* Bounds on the singular values of a (row-major) from B = a a^T; returns the upper one. */
static double singular_bounds(const double a[9], double *lower) {
  double b00 = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
  double b11 = a[3] * a[3] + a[4] * a[4] + a[5] * a[5];
  double b22 = a[6] * a[6] + a[7] * a[7] + a[8] * a[8];
  double b01 = a[0] * a[3] + a[1] * a[4] + a[2] * a[5];
  double b02 = a[0] * a[6] + a[1] * a[7] + a[2] * a[8];
  double b12 = a[3] * a[6] + a[4] * a[7] + a[5] * a[8];
  double m = (b00 + b11 + b22) / 3.0;
  double dev = sqrt((b00 - m) * (b00 - m) + (b11 - m) * (b11 - m) + (b22 - m) * (b22 - m) +
                    2.0 * (b01 * b01 + b02 * b02 + b12 * b12));
  double r = sqrt(2.0 / 3.0) * dev;
  double hi = m + r;
  double det = det33(a);
  double lo = fmax(m - r, det * det / (hi * hi));
  *lower = sqrt(fmax(lo, 0.0));
  return sqrt(hi);
}

/* Exact limit: SVD a = W Sigma Q^T, clamp log Sigma, a <- W Sigma' W^T (rotation dropped).
 * Returns the largest singular value after clamping. */
double piola__plastic_exact_limit(double a[9], const plastic_params *p) {
  piola_mat3 m, w, q;
  piola_vec3 s;
  for (int k = 0; k < 9; ++k) m.m[k / 3][k % 3] = a[k];
  (void)piola_diagonalize3(&m, &w, &s, &q);
  double l[3] = {log(fmax(s.x, 1e-300)), log(fmax(s.y, 1e-300)), log(fmax(s.z, 1e-300))};
  piola__plastic_clamp_log_stretches(l, p->limit, p->volume_preserving);
  double d[3] = {exp(l[0]), exp(l[1]), exp(l[2])};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      a[3 * i + j] = w.m[i][0] * d[0] * w.m[j][0] + w.m[i][1] * d[1] * w.m[j][1] + w.m[i][2] * d[2] * w.m[j][2];
  return fmax(fmax(d[0], d[1]), d[2]);
}

/* One tet; returns 1 when it yielded and counts limit projections in *limited. */
static int update_tet(piola_plastic_state *s, const double *fhat_all, int32_t t, double pull,
                      int *limited) {
  const double *fh = fhat_all + 3 * t;
  int drift = s->controlled && pull > 0;
  double lo, hi;
  quick_bounds(s, t, &lo, &hi);
  if (!drift && fh[0] >= lo && fh[0] <= hi && fh[1] >= lo && fh[1] <= hi && fh[2] >= lo && fh[2] <= hi)
    return 0;
  double delta[3], dl;
  int yielded = piola__plastic_return_map(&s->params, fh, s->alpha[t], delta, &dl);
  if (!yielded && !drift) return 0;
  double *a = s->fp_inv + 9 * t;
  if (yielded) {
    /* Fp <- V exp(delta) V^T Fp, so Fp^-1 <- Fp^-1 V exp(-delta) V^T */
    double v[9], m[9];
    piola__elastic_body_get_rotations(s->body, t, NULL, v);
    double d[3] = {exp(-delta[0]), exp(-delta[1]), exp(-delta[2])};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        m[3 * i + j] = v[3 * i] * d[0] * v[3 * j] + v[3 * i + 1] * d[1] * v[3 * j + 1] +
                       v[3 * i + 2] * d[2] * v[3 * j + 2];
    mul33(a, m, a);
    s->alpha[t] += dl;
    double lower, upper = singular_bounds(a, &lower);
    if (!(upper <= s->limit_cap && lower >= 1.0 / s->limit_cap)) {
      upper = piola__plastic_exact_limit(a, &s->params);
      *limited += 1;
    }
    s->stretch_bound[t] = upper;
  }
  if (s->controlled) {
    double lt[6], *lcur = s->log_fp + 6 * t;
    if (yielded) piola__plastic_log_from_fp_inverse(a, lt);
    else memcpy(lt, lcur, sizeof lt);
    piola__plastic_control_select(lcur, lt, s->goal_log + 6 * t, pull, lcur);
    double largest = piola__plastic_fp_inverse_from_log(lcur, s->params.limit, a);
    s->stretch_bound[t] = exp(largest);
  }
  piola__plastic_commit_tet(s, t);
  return yielded;
}

void piola__plastic_state_update_scalar(piola_plastic_state *s, double dt, piola_plastic_stats *stats) {
  const double *fhat = piola_elastic_body_fhat(s->body);
  double pull = s->controlled ? fmin(1.0, s->strength * dt) : 0.0;
  int32_t yielded = 0, limited = 0;
  double bound = 1.0;
  const int32_t nt = s->tet_count;
#pragma omp parallel for schedule(static) reduction(+ : yielded, limited) reduction(max : bound) \
    num_threads(piola_thread_count()) if (nt >= PIOLA_PARALLEL_MIN_BLOCKS * PIOLA_PLASTIC_LANES)
  for (int32_t t = 0; t < nt; ++t) {
    int lim = 0;
    yielded += update_tet(s, fhat, t, pull, &lim);
    limited += lim;
    bound = fmax(bound, s->stretch_bound[t]);
  }
  /* keep the blocked path's per-block maxima right (the two paths share the state) */
  for (int32_t b = 0; b < s->padded_count / PIOLA_PLASTIC_LANES; ++b) {
    double m = 1.0;
    for (int l = 0; l < PIOLA_PLASTIC_LANES; ++l) m = fmax(m, s->stretch_bound[PIOLA_PLASTIC_LANES * b + l]);
    s->block_bound[b] = m;
  }
  if (stats) {
    stats->yielded_count = yielded;
    stats->limited_count = limited;
    stats->max_fp_stretch = bound;
  }
}

piola_status piola_plastic_state_update(piola_plastic_state *s, double dt, piola_plastic_stats *stats) {
  if (!s) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "plasticity update: NULL state");
  if (!(dt >= 0) || !isfinite(dt))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "plasticity update: dt must be >= 0 s, got %g", dt);
  if (s->controlled) {
    piola__plastic_state_update_scalar(s, dt, stats);
    return PIOLA_OK;
  }
  int32_t yielded = 0, limited = 0;
  double bound = 1.0;
  /* ranges of 64 blocks: big enough for the blocked kernel's two phases, small enough to
   * share out; the counts and the maximum do not depend on how they are shared */
  const int32_t blocks = s->padded_count / PIOLA_PLASTIC_LANES, range = 64;
  const int32_t ranges = (blocks + range - 1) / range;
#pragma omp parallel for schedule(static) reduction(+ : yielded, limited) reduction(max : bound) \
    num_threads(piola_thread_count()) if (blocks >= PIOLA_PARALLEL_MIN_BLOCKS)
  for (int32_t r = 0; r < ranges; ++r) {
    int32_t end = (r + 1) * range < blocks ? (r + 1) * range : blocks;
    double b = 1.0;
    yielded += piola__plastic_update_blocks(s, r * range, end, &limited, &b);
    bound = fmax(bound, b);
  }
  s->refresh_phase = (s->refresh_phase + 1) & (PIOLA_PLASTIC_REFRESH - 1);
  if (stats) {
    stats->yielded_count = yielded;
    stats->limited_count = limited;
    stats->max_fp_stretch = bound;
  }
  return PIOLA_OK;
}

int32_t piola_plastic_state_tet_count(const piola_plastic_state *s) { return s->tet_count; }
const double *piola_plastic_state_fp_inverse(const piola_plastic_state *s) { return s->fp_inv; }
const double *piola_plastic_state_plastic_strain(const piola_plastic_state *s) { return s->alpha; }

/* The relative rounding of a log stretch measured again after the limit clamped it (above). */
#define LIMIT_ROUNDING 1e-9

void piola_plastic_state_measure(const piola_plastic_state *s, double *max_log_stretch, double *min_det_fp) {
  double largest = 0, min_det = INFINITY;
  for (int32_t t = 0; t < s->tet_count; ++t) {
    const double *a = s->fp_inv + 9 * t;
    piola_mat3 m, w, q;
    piola_vec3 sv;
    for (int k = 0; k < 9; ++k) m.m[k / 3][k % 3] = a[k];
    (void)piola_diagonalize3(&m, &w, &sv, &q);
    double vals[3] = {sv.x, sv.y, sv.z};
    for (int i = 0; i < 3; ++i) largest = fmax(largest, vals[i] > 0 ? fabs(log(vals[i])) : INFINITY);
    double det = det33(a);
    min_det = fmin(min_det, det != 0 ? 1.0 / det : -INFINITY);
  }
  /* the limit stores Fp^-1 = W Sigma' W^T with Sigma' clamped to e^+-limit exactly; measured
   * again through an SVD a limited tet reads the limit plus a rounding (1e-15), which is the
   * limit */
  if (largest > s->params.limit && largest <= s->params.limit * (1 + LIMIT_ROUNDING))
    largest = s->params.limit;
  if (max_log_stretch) *max_log_stretch = largest;
  if (min_det_fp) *min_det_fp = min_det;
}

double piola_plastic_state_goal_distance(const piola_plastic_state *s, const double *x) {
  static const double zero[6] = {0, 0, 0, 0, 0, 0};
  const int32_t *tets = piola_elastic_body_tets(s->body);
  const double *volume = piola__elastic_body_rest_volumes(s->body);
  double sum = 0, total = 0;
  for (int32_t t = 0; t < s->tet_count; ++t) {
    const int32_t *idx = tets + 4 * t;
    double ds[9], f[9], rest[9];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) ds[3 * i + j] = x[3 * idx[j + 1] + i] - x[3 * idx[0] + i];
    rest_dm_inv(s, t, rest);
    mul33(ds, rest, f);
    piola_mat3 m, u, v;
    piola_vec3 sv;
    for (int k = 0; k < 9; ++k) m.m[k / 3][k % 3] = f[k];
    (void)piola_diagonalize3(&m, &u, &sv, &v);
    /* log sqrt(F^T F) = V log|Sigma| V^T; flat and inverted entries read as the floor */
    double d[3] = {log(fmax(sv.x, PIOLA_PLASTIC_FLAT_FLOOR)), log(fmax(sv.y, PIOLA_PLASTIC_FLAT_FLOOR)),
                   log(fmax(sv.z, PIOLA_PLASTIC_FLAT_FLOOR))};
    double l[6];
    static const int rows[6] = {0, 1, 2, 0, 0, 1}, cols[6] = {0, 1, 2, 1, 2, 2};
    for (int k = 0; k < 6; ++k) {
      int i = rows[k], j = cols[k];
      l[k] = v.m[i][0] * d[0] * v.m[j][0] + v.m[i][1] * d[1] * v.m[j][1] + v.m[i][2] * d[2] * v.m[j][2];
    }
    double dist = piola__plastic_sym_distance(l, s->controlled ? s->goal_log + 6 * t : zero);
    sum += volume[t] * dist * dist;
    total += volume[t];
  }
  return total > 0 ? sqrt(sum / total) : 0.0;
}
