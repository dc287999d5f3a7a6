/* Muscle fibre forces for one block of tets (see fiber_lanes.h for the why), the fibre
 * energy and the fibre directions: a kernel, compiled once per instruction set (common/isa.h). */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("fp-contract=fast")
#endif
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "force/fiber_lanes.h"
#include "force/svd_kernel.h"
#include "material/hgo_kernels.h"
#include "material/muscle_kernels.h"

#define B PIOLA_TET_BLOCK

/* One lane: tet base + l with material m (a muscle). Adds its forces to tf, returns the
 * energy density. */
PIOLA_KERNEL_INLINE double fiber_lane(const piola_elastic_body *body, const piola_muscle_def *m,
                                      double activation, int32_t base, int l,
                                      double fhat[3][B], double scale, double *tf) {
  const long stride = body->padded_tet_count;
  const double *u = body->u[0] + base, *v = body->v[0] + base;
  const int32_t t = base + l;
  const double a0 = body->fiber[0][t], a1 = body->fiber[1][t], a2 = body->fiber[2][t];
  /* ahat = V^T a (v[3 j + k] is V_jk) */
  const double h0 = v[0 * stride + l] * a0 + v[3 * stride + l] * a1 + v[6 * stride + l] * a2;
  const double h1 = v[1 * stride + l] * a0 + v[4 * stride + l] * a1 + v[7 * stride + l] * a2;
  const double h2 = v[2 * stride + l] * a0 + v[5 * stride + l] * a1 + v[8 * stride + l] * a2;
  const double f0 = fhat[0][l], f1 = fhat[1][l], f2 = fhat[2][l];
  double energy;
  const double r = muscle_fiber_factor(m, f0, f1, f2, h0, h1, h2, activation, &energy);
  /* y = U Fhat ahat (= F a), b = Dm^-1 a; G_f = -V0 scale r y b^T */
  const double x0 = f0 * h0, x1 = f1 * h1, x2 = f2 * h2;
  double y[3], b[3];
  for (int i = 0; i < 3; ++i) {
    y[i] = u[(3 * i) * stride + l] * x0 + u[(3 * i + 1) * stride + l] * x1 +
           u[(3 * i + 2) * stride + l] * x2;
    b[i] = body->dm_inv[3 * i][t] * a0 + body->dm_inv[3 * i + 1][t] * a1 +
           body->dm_inv[3 * i + 2][t] * a2;
  }
  const double w = -body->rest_volume[t] * scale * r;
  for (int i = 0; i < 3; ++i) {
    double g0 = 0.0;
    for (int j = 0; j < 3; ++j) {
      const double g = w * y[i] * b[j];
      tf[(3 * (j + 1) + i) * B + l] += g;
      g0 -= g;
    }
    tf[i * B + l] += g0;
  }
  return energy;
}

/* One lane of an HGO material: its two fibre families from the tet's fibre direction, the
 * stress P_f = g F + sum_a r_a (F a)(a)^T (hgo_kernels.h) in world space, and its forces
 * G_f = -V0 scale P_f Dm^-T added to tf. Returns the energy density. */
static double hgo_lane(const piola_elastic_body *body, const piola_material *mat, int32_t base, int l,
                       double fhat[3][B], double scale, double *tf) {
  const long stride = body->padded_tet_count;
  const double *u = body->u[0] + base, *v = body->v[0] + base;
  const int32_t t = base + l;
  const double m[3] = {body->fiber[0][t], body->fiber[1][t], body->fiber[2][t]};
  double fam[2][3], ahat[2][3];
  const piola_hgo_def *h = &mat->hgo;
  (void)hgo_families_from_fiber(mat, m, fam); /* checked when the body was built */
  for (int a = 0; a < 2; ++a)
    for (int k = 0; k < 3; ++k)
      ahat[a][k] = v[k * stride + l] * fam[a][0] + v[(3 + k) * stride + l] * fam[a][1] +
                   v[(6 + k) * stride + l] * fam[a][2];
  const double f[3] = {fhat[0][l], fhat[1][l], fhat[2][l]};
  double g, r[2], modulus;
  const double energy = hgo_fiber_terms_modulus(h, f[0], f[1], f[2], ahat, &g, r, &modulus);
  if (body->hgo_cache) { /* the step bound's fibre term (hgo_kernels.h) */
    const long slot = base + l;
    for (int k = 0; k < 3; ++k) body->hgo_cache[slot + (HGO_CACHE_KEY + k) * stride] = f[k];
    body->hgo_cache[slot + HGO_CACHE_MODULUS * stride] = modulus;
  }
  /* P = U [g Fhat + sum_a r_a (Fhat ahat_a) ahat_a^T] V^T */
  double ph[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      ph[i][j] = (i == j ? g * f[i] : 0.0) + f[i] * (r[0] * ahat[0][i] * ahat[0][j] + r[1] * ahat[1][i] * ahat[1][j]);
  double pv[3][3], p[3][3]; /* ph V^T, then U (ph V^T) */
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      pv[i][j] = ph[i][0] * v[(3 * j) * stride + l] + ph[i][1] * v[(3 * j + 1) * stride + l] +
                 ph[i][2] * v[(3 * j + 2) * stride + l];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      p[i][j] = u[(3 * i) * stride + l] * pv[0][j] + u[(3 * i + 1) * stride + l] * pv[1][j] +
                u[(3 * i + 2) * stride + l] * pv[2][j];
  const double w = -body->rest_volume[t] * scale;
  for (int i = 0; i < 3; ++i) {
    double g0 = 0.0;
    for (int j = 0; j < 3; ++j) {
      const double gij = w * (p[i][0] * body->dm_inv[3 * j][t] + p[i][1] * body->dm_inv[3 * j + 1][t] +
                              p[i][2] * body->dm_inv[3 * j + 2][t]);
      tf[(3 * (j + 1) + i) * B + l] += gij;
      g0 -= gij;
    }
    tf[i * B + l] += g0;
  }
  return energy;
}

PIOLA_WIDE_VECTORS void PIOLA_ISA_NAME(piola__fiber_forces_lanes)(const piola_elastic_body *body, int32_t base,
                                                  double fhat[3][B], double scale,
                                                  double *tf, double *psi) {
  const double activation = body->activation;
  double energy[B];
  if (body->uniform_material >= 0) {
    const piola_material *mat = &body->materials[body->uniform_material];
    if (mat->model == PIOLA_MODEL_HGO) {
      for (int l = 0; l < B; ++l) energy[l] = hgo_lane(body, mat, base, l, fhat, scale, tf);
      if (psi)
        for (int l = 0; l < B; ++l) psi[l] += energy[l];
      return;
    }
    if (mat->model != PIOLA_MODEL_MUSCLE) return;
    const piola_muscle_def m = mat->muscle;
#pragma omp simd
    for (int l = 0; l < B; ++l) energy[l] = fiber_lane(body, &m, activation, base, l, fhat, scale, tf);
  } else {
    for (int l = 0; l < B; ++l) {
      const piola_material *mat = &body->materials[body->tet_material[base + l]];
      energy[l] = mat->model == PIOLA_MODEL_MUSCLE
                      ? fiber_lane(body, &mat->muscle, activation, base, l, fhat, scale, tf)
                  : mat->model == PIOLA_MODEL_HGO ? hgo_lane(body, mat, base, l, fhat, scale, tf)
                                                  : 0.0;
    }
  }
  if (psi)
    for (int l = 0; l < B; ++l) psi[l] += energy[l];
}

double PIOLA_ISA_NAME(piola__fiber_energy_density)(const piola_elastic_body *body, int32_t t) {
  if (!body->fiber[0]) return 0.0;
  const piola_material *mat = &body->materials[body->tet_material[t]];
  const long stride = body->padded_tet_count;
  const double *v = body->v[0] + t;
  if (mat->model == PIOLA_MODEL_HGO) {
    const double m[3] = {body->fiber[0][t], body->fiber[1][t], body->fiber[2][t]};
    double fam[2][3], ahat[2][3], g, r[2];
    (void)hgo_families_from_fiber(mat, m, fam);
    for (int a = 0; a < 2; ++a)
      for (int k = 0; k < 3; ++k)
        ahat[a][k] = v[k * stride] * fam[a][0] + v[(3 + k) * stride] * fam[a][1] + v[(6 + k) * stride] * fam[a][2];
    const double *f = body->fhat + 3 * (size_t)t;
    return hgo_fiber_terms_diagonal(&mat->hgo, f[0], f[1], f[2], ahat, &g, r);
  }
  if (mat->model != PIOLA_MODEL_MUSCLE) return 0.0;
  double ahat[3];
  for (int k = 0; k < 3; ++k)
    ahat[k] = v[k * stride] * body->fiber[0][t] + v[(3 + k) * stride] * body->fiber[1][t] +
              v[(6 + k) * stride] * body->fiber[2][t];
  return piola_material_fiber_energy_density(mat, body->fhat + 3 * (size_t)t, ahat,
                                             body->activation);
}

piola_status PIOLA_ISA_NAME(piola__fiber_copy)(piola_elastic_body *body, const piola_elastic_body_def *def) {
  if (!def->fiber_directions) return PIOLA_OK;
  const int32_t nt = body->tet_count, np = body->padded_tet_count;
  for (int k = 0; k < 3; ++k)
    if (!(body->fiber[k] = calloc((size_t)np, sizeof(double))))
      return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fiber directions: out of memory");
  if (!(body->fiber_aos = calloc(3 * (size_t)nt, sizeof(double))))
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "fiber directions: out of memory");
  for (int32_t t = 0; t < nt; ++t) {
    const double *a = def->fiber_directions + 3 * (size_t)t;
    const double n = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    if (!isfinite(n))
      return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "fiber direction of tet %d is not finite", (int)t);
    if (!(n > 0.0))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "fiber direction of tet %d is zero", (int)t);
    for (int k = 0; k < 3; ++k) {
      body->fiber[k][t] = a[k] / n;
      body->fiber_aos[3 * (size_t)t + k] = a[k] / n;
    }
    const piola_material *mat = &body->materials[body->tet_material[t]];
    double unit[3] = {a[0] / n, a[1] / n, a[2] / n}, fam[2][3];
    if (mat->model == PIOLA_MODEL_HGO && !hgo_families_from_fiber(mat, unit, fam))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "fiber direction of tet %d is parallel to material.hgo.axis: the plane of "
                        "the two fibre families is undefined",
                        (int)t);
  }
  return PIOLA_OK;
}
