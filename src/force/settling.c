/* The settling estimate of piola/settling.h: the lowest non-rigid vibration of the rest mesh
 * by inverse iteration, its modal damping, and the decay rate they give.
 *
 * The rest stiffness is applied per tet without assembly: with g_a the gradients of the
 * corners' shape functions (rows of Dm^-1, g_0 = -g_1 - g_2 - g_3), the strain of a
 * displacement u is eps = sym(sum_a u_a g_a^T), the stress s = 2 m eps + l tr(eps) I, and
 * corner a gets V0 s g_a (K u, the negated elastic force). With (m, l) = (mu, lambda) it is
 * the stiffness, with (beta, alpha) the damping operator of damping.c at rest (there the
 * rotations are the identity and its rigid-rotation projection removes nothing a symmetric
 * strain rate sees).
 *
 * Inverse iteration: x <- P K^+ M x, normalized in M, where P removes the six rigid motions
 * M-orthogonally (K's null space). Each solve is a conjugate-gradient solve of K y = M x,
 * consistent because M x is orthogonal to the rigid motions, preconditioned by K's diagonal
 * (slivers make K's diagonal vary by orders of magnitude). The Rayleigh quotient
 * y^T K y / y^T M y lies between the lowest eigenvalue and the next ones and converges to
 * the lowest as (lambda_1 / lambda_2)^(2k); when the two lowest modes are close (a symmetric
 * body's two ears) either is the answer. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/union_find.h"
#include "force/elastic_body_internal.h"
#include "piola/settling.h"

/* Re-expansion bound of a collapsed body, in wave crossings or relaxation times (measured:
 * docs/time-stepping.md "Recovery"). */
#define REEXPANSION_FACTOR 8.0

enum { MAX_INVERSE_ITERATIONS = 40, RIGID_MODES = 6 };
#define RAYLEIGH_TOLERANCE 1e-4 /* relative change of omega^2 between iterations */
#define SOLVE_TOLERANCE 1e-8    /* CG: |residual| / |right-hand side| */

/* out = K(m, l) u over the body's tets, with (m, l) = (mu, lambda) of each tet's material
 * when viscosities is NULL, else (viscosities[0], viscosities[1]). */
static void rest_operator(const piola_elastic_body *b, const double *viscosities, const double *u,
                          double *out) {
  memset(out, 0, 3 * (size_t)b->vertex_count * sizeof(double));
  for (int32_t t = 0; t < b->tet_count; ++t) {
    const piola_material *mat = &b->materials[b->tet_material[t]];
    const double m = viscosities ? viscosities[0] : mat->mu;
    const double l = viscosities ? viscosities[1] : mat->lambda;
    double g[4][3];
    for (int i = 0; i < 3; ++i) {
      g[0][i] = 0;
      for (int a = 1; a < 4; ++a) g[a][i] = b->dm_inv[3 * (a - 1) + i][t], g[0][i] -= g[a][i];
    }
    double du[3][3] = {{0}}; /* du[i][j] = d u_i / d X_j */
    for (int a = 0; a < 4; ++a) {
      const double *ua = u + 3 * (size_t)b->tet_vertices[a][t];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) du[i][j] += ua[i] * g[a][j];
    }
    const double trace = du[0][0] + du[1][1] + du[2][2];
    double s[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) s[i][j] = m * (du[i][j] + du[j][i]) + (i == j ? l * trace : 0);
    const double v0 = b->rest_volume[t];
    for (int a = 0; a < 4; ++a) {
      double *oa = out + 3 * (size_t)b->tet_vertices[a][t];
      for (int i = 0; i < 3; ++i) oa[i] += v0 * (s[i][0] * g[a][0] + s[i][1] * g[a][1] + s[i][2] * g[a][2]);
    }
  }
}

/* K(mu, lambda)'s diagonal, for the preconditioner: corner a of a tet adds
 * V0 (mu |g_a|^2 + (mu + lambda) g_ai^2) to its entry i. */
static void rest_diagonal(const piola_elastic_body *b, double *diag) {
  memset(diag, 0, 3 * (size_t)b->vertex_count * sizeof(double));
  for (int32_t t = 0; t < b->tet_count; ++t) {
    const piola_material *mat = &b->materials[b->tet_material[t]];
    double g[4][3];
    for (int i = 0; i < 3; ++i) {
      g[0][i] = 0;
      for (int a = 1; a < 4; ++a) g[a][i] = b->dm_inv[3 * (a - 1) + i][t], g[0][i] -= g[a][i];
    }
    for (int a = 0; a < 4; ++a) {
      const double g2 = g[a][0] * g[a][0] + g[a][1] * g[a][1] + g[a][2] * g[a][2];
      for (int i = 0; i < 3; ++i)
        diag[3 * (size_t)b->tet_vertices[a][t] + i] +=
            b->rest_volume[t] * (mat->mu * g2 + (mat->mu + mat->lambda) * g[a][i] * g[a][i]);
    }
  }
}

static double dot(const double *a, const double *b, size_t n) {
  double s = 0;
  for (size_t k = 0; k < n; ++k) s += a[k] * b[k];
  return s;
}

/* sum m_v a_v . b_v */
static double mass_dot(const double *mass, const double *a, const double *b, int32_t nv) {
  double s = 0;
  for (int32_t v = 0; v < nv; ++v)
    s += mass[v] * (a[3 * v] * b[3 * v] + a[3 * v + 1] * b[3 * v + 1] + a[3 * v + 2] * b[3 * v + 2]);
  return s;
}

/* The six rigid motions (translations, rotations about the centre of mass), made
 * M-orthonormal; returns how many are independent (fewer for a body on a line). */
static int rigid_basis(const piola_elastic_body *b, double *basis) {
  const int32_t nv = b->vertex_count;
  const size_t n = 3 * (size_t)nv;
  double c[3] = {0}, mt = 0;
  for (int32_t v = 0; v < nv; ++v) {
    mt += b->masses[v];
    for (int i = 0; i < 3; ++i) c[i] += b->masses[v] * b->rest_positions[3 * v + i];
  }
  for (int i = 0; i < 3; ++i) c[i] /= mt;
  int count = 0;
  for (int k = 0; k < RIGID_MODES; ++k) {
    double *r = basis + (size_t)count * n;
    for (int32_t v = 0; v < nv; ++v) {
      const double *x = b->rest_positions + 3 * (size_t)v;
      const double d[3] = {x[0] - c[0], x[1] - c[1], x[2] - c[2]};
      for (int i = 0; i < 3; ++i) r[3 * v + i] = k < 3 ? (i == k) : 0;
      if (k >= 3) { /* e_axis x d */
        const int axis = k - 3, p = (axis + 1) % 3, q = (axis + 2) % 3;
        r[3 * v + p] = -d[q], r[3 * v + q] = d[p];
      }
    }
    const double norm0 = sqrt(mass_dot(b->masses, r, r, nv));
    for (int j = 0; j < count; ++j) {
      const double *e = basis + (size_t)j * n;
      const double p = mass_dot(b->masses, e, r, nv);
      for (size_t q = 0; q < n; ++q) r[q] -= p * e[q];
    }
    const double norm = sqrt(mass_dot(b->masses, r, r, nv));
    if (!(norm > 1e-9 * norm0)) continue;
    for (size_t q = 0; q < n; ++q) r[q] /= norm;
    ++count;
  }
  return count;
}

static void remove_rigid(const piola_elastic_body *b, const double *basis, int count, double *x) {
  const size_t n = 3 * (size_t)b->vertex_count;
  for (int j = 0; j < count; ++j) {
    const double *e = basis + (size_t)j * n;
    const double p = mass_dot(b->masses, e, x, b->vertex_count);
    for (size_t q = 0; q < n; ++q) x[q] -= p * e[q];
  }
}

/* Solves K y = rhs by Jacobi-preconditioned CG from the y given; scratch holds 4 n. */
static void solve_rest(const piola_elastic_body *b, const double *inv_diag, const double *rhs,
                       double *y, double *scratch) {
  const size_t n = 3 * (size_t)b->vertex_count;
  double *r = scratch, *z = scratch + n, *p = scratch + 2 * n, *kp = scratch + 3 * n;
  rest_operator(b, NULL, y, kp);
  for (size_t k = 0; k < n; ++k) r[k] = rhs[k] - kp[k], z[k] = inv_diag[k] * r[k], p[k] = z[k];
  const double target = SOLVE_TOLERANCE * sqrt(dot(rhs, rhs, n));
  double rz = dot(r, z, n);
  /* ~1,000 iterations for armadillo_4k's 3,540 unknowns; a mechanism (tets joined by an
   * edge or a vertex only) leaves the system inconsistent, and the cap ends it */
  for (size_t it = 0; it < 2 * n + 1000 && sqrt(dot(r, r, n)) > target; ++it) {
    rest_operator(b, NULL, p, kp);
    const double pkp = dot(p, kp, n);
    if (!(pkp > 0)) break; /* p in K's null space: a part not joined to the rest */
    const double a = rz / pkp;
    for (size_t k = 0; k < n; ++k) y[k] += a * p[k], r[k] -= a * kp[k], z[k] = inv_diag[k] * r[k];
    const double rz_next = dot(r, z, n);
    for (size_t k = 0; k < n; ++k) p[k] = z[k] + rz_next / rz * p[k];
    rz = rz_next;
  }
}

/* Whether the tets join every vertex with mass into one piece (else a piece moves freely
 * against the others: a zero frequency). -1 when out of memory. */
static int one_piece(const piola_elastic_body *b) {
  int32_t *parent = malloc((size_t)b->vertex_count * sizeof(int32_t));
  if (!parent) return -1;
  for (int32_t v = 0; v < b->vertex_count; ++v) parent[v] = v;
  for (int32_t t = 0; t < b->tet_count; ++t)
    for (int c = 1; c < 4; ++c) piola__union_find_join(parent, b->tets[4 * t], b->tets[4 * t + c]);
  int32_t root = -1;
  int joined = 1;
  for (int32_t v = 0; v < b->vertex_count && joined; ++v) {
    if (!(b->masses[v] > 0)) continue;
    const int32_t r = piola__union_find_root(parent, v);
    if (root < 0) root = r;
    joined = r == root;
  }
  free(parent);
  return joined;
}

/* The decay rate of x'' + c x' + w^2 x = 0: its slower root's real part. */
static double modal_decay_rate(double w, double c) {
  if (!(w > 0)) return 0; /* a free motion: nothing brings it back */
  if (c < 2 * w) return 0.5 * c;
  return 2 * w * w / (c + sqrt(c * c - 4 * w * w)); /* (c - sqrt(c^2 - 4 w^2)) / 2, stably */
}

piola_status piola_elastic_body_settling_estimate(const piola_elastic_body *body,
                                                  double shear_viscosity,
                                                  double bulk_viscosity,
                                                  piola_settling_estimate *out) {
  if (!body || !out)
    return piola_fail(PIOLA_ERROR_INVALID_ARGUMENT, "settling estimate: body and out are required");
  if (!(shear_viscosity >= 0 && bulk_viscosity >= 0 && isfinite(shear_viscosity) && isfinite(bulk_viscosity)))
    return piola_fail(PIOLA_ERROR_INVALID_ARGUMENT,
                      "settling estimate: viscosities must be finite and >= 0 (got %g, %g Pa s)",
                      shear_viscosity, bulk_viscosity);
  memset(out, 0, sizeof *out);
  const int32_t nv = body->vertex_count;
  const size_t n = 3 * (size_t)nv;
  double *work = malloc((RIGID_MODES + 9) * n * sizeof(double));
  if (!work) return piola_fail(PIOLA_ERROR_OUT_OF_MEMORY, "settling estimate: out of memory");
  double *basis = work, *x = basis + RIGID_MODES * n, *y = x + n, *rhs = y + n, *inv_diag = rhs + n,
         *kx = inv_diag + n, *scratch = kx + n;

  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int32_t v = 0; v < nv; ++v)
    for (int i = 0; i < 3; ++i)
      lo[i] = fmin(lo[i], body->rest_positions[3 * v + i]), hi[i] = fmax(hi[i], body->rest_positions[3 * v + i]);
  out->diagonal = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                       (hi[2] - lo[2]) * (hi[2] - lo[2]));
  /* the slowest material's dilatational speed, fibres left out (they add nothing in the
   * compression a collapsed body re-expands from) */
  double speed = INFINITY;
  for (int32_t k = 0; k < body->material_count; ++k)
    speed = fmin(speed, sqrt((body->materials[k].lambda + 2 * body->materials[k].mu) / body->density));
  out->crossing_time = out->diagonal / speed;

  const int joined = one_piece(body);
  if (joined < 0) {
    free(work);
    return piola_fail(PIOLA_ERROR_OUT_OF_MEMORY, "settling estimate: out of memory");
  }
  rest_diagonal(body, inv_diag);
  for (size_t k = 0; k < n; ++k) inv_diag[k] = inv_diag[k] > 0 ? 1 / inv_diag[k] : 0;
  const int rigid = rigid_basis(body, basis);
  /* start: a fixed pseudo-random field (every mode present), vertices without mass held */
  uint64_t seed = 0x9e3779b97f4a7c15u;
  for (size_t k = 0; k < n; ++k) {
    seed = seed * 6364136223846793005u + 1442695040888963407u;
    x[k] = body->masses[k / 3] > 0 ? (double)(seed >> 11) / 9007199254740992.0 - 0.5 : 0;
  }
  remove_rigid(body, basis, rigid, x);
  double omega2 = INFINITY;
  memset(y, 0, n * sizeof(double));
  for (int it = 0; joined && it < MAX_INVERSE_ITERATIONS; ++it) {
    const double norm = sqrt(mass_dot(body->masses, x, x, nv));
    if (!(norm > 0)) break;
    for (size_t k = 0; k < n; ++k) x[k] /= norm;
    for (int32_t v = 0; v < nv; ++v)
      for (int i = 0; i < 3; ++i) rhs[3 * v + i] = body->masses[v] * x[3 * v + i];
    /* the previous iterate scaled by 1 / omega^2 is close to the solution */
    for (size_t k = 0; k < n; ++k) y[k] = isfinite(omega2) && omega2 > 0 ? x[k] / omega2 : 0;
    solve_rest(body, inv_diag, rhs, y, scratch);
    remove_rigid(body, basis, rigid, y);
    memcpy(x, y, n * sizeof(double));
    rest_operator(body, NULL, x, kx);
    const double next = dot(x, kx, n) / mass_dot(body->masses, x, x, nv);
    out->iterations = it + 1;
    const int settled = fabs(next - omega2) <= RAYLEIGH_TOLERANCE * next;
    omega2 = next;
    if (settled) break;
  }
  const double xmx = mass_dot(body->masses, x, x, nv);
  out->lowest_frequency = isfinite(omega2) && omega2 > 0 ? sqrt(omega2) : 0;
  const double viscosities[2] = {shear_viscosity, bulk_viscosity};
  rest_operator(body, viscosities, x, kx);
  out->lowest_damping = joined && xmx > 0 ? dot(x, kx, n) / xmx : 0;
  out->lowest_decay_rate = modal_decay_rate(out->lowest_frequency, out->lowest_damping);
  /* K_e = mu A + lambda B and C_e = beta A + alpha B (A, B >= 0): omega^2 / c >= the smaller
   * ratio, term by term */
  double relax = INFINITY;
  for (int32_t k = 0; k < body->material_count; ++k) {
    const piola_material *m = &body->materials[k];
    if (shear_viscosity > 0) relax = fmin(relax, m->mu / shear_viscosity);
    if (bulk_viscosity > 0 && m->lambda > 0) relax = fmin(relax, m->lambda / bulk_viscosity);
    /* without lambda the shear term alone restores volume: tr(eps)^2 <= 3 |eps|^2 */
    if (bulk_viscosity > 0 && !(m->lambda > 0))
      relax = fmin(relax, 2 * m->mu / (2 * shear_viscosity + 3 * bulk_viscosity));
  }
  out->relaxation_rate = relax;
  out->decay_rate = fmin(out->lowest_decay_rate, relax);
  /* measured on the unit ball, the octahedron and armadillo_4k (docs/time-stepping.md):
   * up to 5.4 wave crossings when the re-expansion is inertial, 4.8 relaxation times when it
   * is overdamped (line collapses; how long depends on the run's last bits, which differ
   * between instruction sets); on Gmsh's bunny.msh, whose inverted slivers linger, 7.8
   * relaxation times: so eight of the slower */
  out->reexpansion_time = REEXPANSION_FACTOR * fmax(out->crossing_time, relax > 0 ? 1 / relax : INFINITY);
  free(work);
  return PIOLA_OK;
}

double piola_settling_time(const piola_settling_estimate *estimate, double initial_error,
                           double tolerance) {
  if (!(initial_error > tolerance)) return 0;
  if (!(estimate->decay_rate > 0)) return INFINITY;
  return estimate->reexpansion_time + log(initial_error / tolerance) / estimate->decay_rate;
}
