/* Recovery runs shared by the scramble and collapse benchmarks and the default-inversion test
 * (recovery_runs.h). */
#include "support/recovery_runs.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "force/elastic_body_internal.h"
#include "force/stable_step.h"
#include "piola/diagonalize.h"
#include "piola/elastic_body.h"
#include "piola/mesh_io.h"

const char *const recovery_result_names[RECOVERY_RESULT_COUNT] = {
    "recovered", "slow", "stuck (model)", "stuck (extension)", "diverged"};
const char *const recovery_collapse_names[3] = {"point", "line", "plane"};

piola_material_def recovery_material_def(piola_material_model model) {
  piola_material_def def = piola_default_material_def();
  def.model = model;
  def.youngs_modulus = 1e4;
  def.poisson_ratio = 0.3;
  const double mu = def.youngs_modulus / (2.0 * (1.0 + def.poisson_ratio));
  if (model == PIOLA_MODEL_OGDEN) {
    double mu0 = 0.0; /* Ogden's rest shear modulus, 1/2 sum mu_p alpha_p */
    for (int p = 0; p < def.ogden.term_count; ++p) mu0 += 0.5 * def.ogden.mu[p] * def.ogden.alpha[p];
    for (int p = 0; p < def.ogden.term_count; ++p) def.ogden.mu[p] *= mu / mu0;
  } else if (model == PIOLA_MODEL_MOONEY_RIVLIN) {
    const double scale = mu / (2.0 * (def.mooney_rivlin.c10 + def.mooney_rivlin.c01));
    def.mooney_rivlin.c10 *= scale;
    def.mooney_rivlin.c01 *= scale;
  } else if (model == PIOLA_MODEL_HGO) {
    def.hgo.k1 *= mu / def.hgo.mu;
    def.hgo.mu = mu;
  } else if (model == PIOLA_MODEL_MUSCLE) {
    def.muscle.passive_stiffness *= 0.1;
    def.muscle.max_active_stress *= 0.1;
  }
  return def;
}

int recovery_grid(piola_tet_mesh *mesh) {
  return piola_tet_mesh_box_grid(3, 3, 3, (piola_vec3){1.0 / 3, 1.0 / 3, 1.0 / 3}, mesh) ==
                 PIOLA_OK
             ? 0
             : -1;
}

/* A body of `mesh` with `material`; fibres along x (used by the fibre models only). */
static piola_elastic_body *make_body(const piola_tet_mesh *mesh, const piola_material *material) {
  double *fibers = malloc(sizeof(double) * 3 * (size_t)mesh->tet_count);
  if (!fibers) return NULL;
  for (int32_t t = 0; t < mesh->tet_count; ++t)
    fibers[3 * t] = 1.0, fibers[3 * t + 1] = 0.0, fibers[3 * t + 2] = 0.0;
  piola_elastic_body_def bd = piola_default_elastic_body_def();
  bd.rest_mesh = mesh;
  bd.materials = material;
  bd.material_count = 1;
  const recovery_volume_threshold *vt = &recovery_threshold_by_volume;
  piola_material steps[16];
  if (vt->levels >= 2 && vt->levels <= 16) { /* the experiment's materials, by threshold */
    for (int k = 0; k < vt->levels; ++k) {
      steps[k] = *material;
      steps[k].threshold = material->threshold + (vt->high - material->threshold) * k / (vt->levels - 1);
      steps[k].threshold_compressed = steps[k].threshold; /* each level a fixed threshold */
    }
    bd.materials = steps;
    bd.material_count = vt->levels;
  }
  bd.density = 1000;
  if (material->model == PIOLA_MODEL_MUSCLE || material->model == PIOLA_MODEL_HGO)
    bd.fiber_directions = fibers;
  piola_elastic_body *body = NULL;
  if (piola_elastic_body_create(&bd, &body) != PIOLA_OK) body = NULL;
  if (body && bd.material_count > 1) body->uniform_material = -1; /* tet_material decides */
  free(fibers);
  return body;
}

/* The explicit damping step of the runs below: symplectic Euler with the damping force taken
 * explicitly is stable for a mode of damping rate c and frequency omega while
 * c dt < 2 - (omega dt)^2 / 2, so dt is held to 1 / c_max, c_max the largest eigenvalue of
 * M^-1 D at rest (power iteration in the M inner product, 10% added for its convergence from
 * below and for the damping's change with the current rotations, a few percent): then every
 * state with omega dt < sqrt(2) is stable, twice the margin of the half state-aware bound.
 * The estimate 0.25 rho h^2 / (beta + alpha) from the smallest altitude alone is not a bound:
 * on vega/beam3_tet.veg it gave c dt = 2.11, and every collapse diverged after a few hundred
 * to a few thousand steps (docs/materials.md, "A second real mesh"). */
static double damping_step(piola_elastic_body *body, double beta, double alpha, double density) {
  const int32_t nv = piola_elastic_body_vertex_count(body);
  const double *mass = piola_elastic_body_masses(body), *rest = piola_elastic_body_rest_positions(body);
  const double h = piola_elastic_body_min_rest_altitude(body);
  const double estimate = 0.25 * density * h * h / (beta + alpha);
  double *v = malloc(sizeof(double) * 3 * (size_t)nv), *f = malloc(sizeof(double) * 3 * (size_t)nv);
  double c = 0.0;
  if (v && f && piola_elastic_body_update(body, rest, 1.0, f, NULL) == PIOLA_OK) {
    uint64_t state = 0x2545F4914F6CDD1Dull;
    for (int32_t i = 0; i < 3 * nv; ++i) {
      state ^= state << 13, state ^= state >> 7, state ^= state << 17;
      v[i] = mass[i / 3] > 0 ? (double)(state >> 11) * (1.0 / 9007199254740992.0) - 0.5 : 0.0;
    }
    for (int it = 0; it < 200; ++it) {
      piola_elastic_body_damping_forces(body, v, beta, alpha, f);
      double vmv = 0.0, vdv = 0.0, next = 0.0;
      for (int32_t i = 0; i < 3 * nv; ++i) {
        const double m = mass[i / 3];
        if (!(m > 0)) continue;
        vmv += m * v[i] * v[i];
        vdv -= v[i] * f[i];
        f[i] = -f[i] / m;
        next += m * f[i] * f[i];
      }
      c = vmv > 0 ? vdv / vmv : 0.0;
      if (!(next > 0)) break;
      for (int32_t i = 0; i < 3 * nv; ++i) v[i] = mass[i / 3] > 0 ? f[i] / sqrt(next) : 0.0;
    }
  }
  free(v);
  free(f);
  return c > 0 ? fmin(estimate, 1.0 / (1.1 * c)) : estimate;
}

static uint64_t xorshift(uint64_t *s) {
  uint64_t x = *s;
  x ^= x << 13;
  x ^= x >> 7;
  x ^= x << 17;
  return *s = x;
}

static recovery_result judge(piola_elastic_body *body, const piola_material *material,
                             const double *x, double *fe) {
  piola_elastic_stats stats;
  if (piola_elastic_body_update(body, x, 1.0, fe, &stats) != PIOLA_OK) return RECOVERY_DIVERGED;
  const int32_t nt = piola_elastic_body_tet_count(body);
  const double *fhat = piola_elastic_body_fhat(body);
  double worst = 0.0, smallest = INFINITY;
  for (int32_t t = 0; t < 3 * nt; ++t) {
    worst = fmax(worst, fabs(fhat[t] - 1.0));
    smallest = fmin(smallest, fhat[t]);
  }
  if (worst <= 1e-6 && stats.inverted_count == 0) return RECOVERY_RECOVERED;
  if (stats.elastic_energy < 1e-3) return RECOVERY_SLOW;
  return smallest >= material->threshold ? RECOVERY_STUCK_MODEL : RECOVERY_STUCK_EXTENSION;
}

double recovery_scramble_seconds = 12.0;

recovery_volume_threshold recovery_threshold_by_volume = {0, 0.5, 0.5, 0.9};

/* The experiment's step of each tet for the next update, from this update's J. */
static void choose_thresholds_by_volume(piola_elastic_body *body) {
  const recovery_volume_threshold *vt = &recovery_threshold_by_volume;
  if (vt->levels < 2 || vt->levels > 16) return;
  for (int32_t t = 0; t < body->tet_count; ++t) {
    const double u = (vt->j_high - body->det_f[t]) / (vt->j_high - vt->j_low);
    body->tet_material[t] = (int32_t)(fmin(fmax(u, 0.0), 1.0) * (vt->levels - 1) + 0.5);
  }
}

recovery_result recovery_scramble_run(const piola_tet_mesh *mesh, const piola_material *material,
                                      int seed) {
  piola_elastic_body *body = make_body(mesh, material);
  if (!body) return RECOVERY_DIVERGED;
  const int32_t nv = piola_elastic_body_vertex_count(body);
  const double *mass = piola_elastic_body_masses(body);
  const double beta = 300.0, alpha = 100.0, h = piola_elastic_body_min_rest_altitude(body);
  const double dt = fmin(0.5 * h / (piola_elastic_body_max_wave_speed(body) * sqrt(12.0)),
                         0.25 * 1000.0 * h * h / (beta + alpha));
  const int steps = (int)(recovery_scramble_seconds / dt);
  double *x = malloc(sizeof(double) * 3 * (size_t)nv), *v = calloc(3 * (size_t)nv, sizeof(double));
  double *fe = malloc(sizeof(double) * 3 * (size_t)nv), *fd = malloc(sizeof(double) * 3 * (size_t)nv);
  recovery_result result = RECOVERY_DIVERGED;
  if (x && v && fe && fd) {
    uint64_t state = 0x9E3779B97F4A7C15ull * (uint64_t)(seed + 1);
    for (int k = 0; k < 10; ++k) xorshift(&state);
    for (int32_t i = 0; i < 3 * nv; ++i)
      x[i] = (double)(xorshift(&state) >> 11) * (1.0 / 9007199254740992.0);
    /* HGO's fibres stiffen exponentially: a scramble stretches them 5-10x, where no fixed step
     * is stable, so its runs take the fixed step or half the state-aware bound, whichever is
     * shorter, for the same 12 s (the other models keep the fixed step of the tables). */
    const int adaptive = material->model == PIOLA_MODEL_HGO;
    int finite = 1;
    double t = 0.0;
    for (int k = 0; adaptive ? t < recovery_scramble_seconds : k < steps; ++k) {
      finite = piola_elastic_body_update(body, x, 1.0, fe, NULL) == PIOLA_OK;
      if (!finite) break;
      choose_thresholds_by_volume(body);
      const double step =
          adaptive ? fmin(dt, 0.5 / sqrt(piola__elastic_body_state_rate2(body, NULL))) : dt;
      t += step;
      piola_elastic_body_damping_forces(body, v, beta, alpha, fd);
      for (int32_t i = 0; i < 3 * nv; ++i) {
        v[i] += step * (fe[i] + fd[i]) / mass[i / 3];
        x[i] += step * v[i];
      }
    }
    if (finite) result = judge(body, material, x, fe);
  }
  free(x);
  free(v);
  free(fe);
  free(fd);
  piola_elastic_body_destroy(body);
  return result;
}

int recovery_read_unit_mesh(const char *data_dir, const char *relative, piola_tet_mesh *mesh) {
  char path[1024];
  snprintf(path, sizeof path, "%s/%s", data_dir, relative);
  memset(mesh, 0, sizeof *mesh);
  if (piola_tet_mesh_read(path, mesh) != PIOLA_OK) return -1;
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int32_t v = 0; v < mesh->vertex_count; ++v)
    for (int i = 0; i < 3; ++i) {
      lo[i] = fmin(lo[i], mesh->positions[3 * v + i]);
      hi[i] = fmax(hi[i], mesh->positions[3 * v + i]);
    }
  const double side = fmax(hi[0] - lo[0], fmax(hi[1] - lo[1], hi[2] - lo[2]));
  for (int32_t v = 0; v < mesh->vertex_count; ++v)
    for (int i = 0; i < 3; ++i)
      mesh->positions[3 * v + i] = (mesh->positions[3 * v + i] - 0.5 * (lo[i] + hi[i])) / side;
  return 0;
}

double recovery_procrustes_error(const double *x, const double *rest, const double *mass,
                                 int32_t nv) {
  double cx[3] = {0}, cr[3] = {0}, mt = 0;
  for (int32_t v = 0; v < nv; ++v) {
    mt += mass[v];
    for (int i = 0; i < 3; ++i) {
      cx[i] += mass[v] * x[3 * v + i];
      cr[i] += mass[v] * rest[3 * v + i];
    }
  }
  for (int i = 0; i < 3; ++i) cx[i] /= mt, cr[i] /= mt;
  piola_mat3 h, u, w;
  memset(&h, 0, sizeof h);
  for (int32_t v = 0; v < nv; ++v)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        h.m[i][j] += mass[v] * (rest[3 * v + i] - cr[i]) * (x[3 * v + j] - cx[j]);
  piola_vec3 s;
  if (piola_diagonalize3(&h, &u, &s, &w) != PIOLA_OK) return INFINITY;
  double worst = 0;
  for (int32_t v = 0; v < nv; ++v) {
    double d2 = 0;
    for (int i = 0; i < 3; ++i) {
      double y = cr[i];
      for (int j = 0; j < 3; ++j)
        y += (u.m[i][0] * w.m[j][0] + u.m[i][1] * w.m[j][1] + u.m[i][2] * w.m[j][2]) *
             (x[3 * v + j] - cx[j]);
      d2 += (y - rest[3 * v + i]) * (y - rest[3 * v + i]);
    }
    worst = fmax(worst, sqrt(d2));
  }
  return worst;
}

double recovery_collapse_seconds = 12.0;

recovery_collapse_outcome recovery_collapse_run(const piola_tet_mesh *mesh,
                                                const piola_material *material,
                                                recovery_collapse_kind kind) {
  recovery_collapse_outcome out = {RECOVERY_DIVERGED, INFINITY, INFINITY, 0, 0, NAN, NAN};
  piola_elastic_body *body = make_body(mesh, material);
  if (!body) return out;
  const int32_t nv = piola_elastic_body_vertex_count(body), nt = piola_elastic_body_tet_count(body);
  const double *mass = piola_elastic_body_masses(body), *rest = piola_elastic_body_rest_positions(body);
  const double beta = 1000.0, alpha = 300.0, density = 1000.0; /* Pa s, Pa s, kg/m^3 */
  const double dt_damping = damping_step(body, beta, alpha, density);
  double *x = malloc(sizeof(double) * 3 * (size_t)nv), *v = calloc(3 * (size_t)nv, sizeof(double));
  double *fe = malloc(sizeof(double) * 3 * (size_t)nv), *fd = malloc(sizeof(double) * 3 * (size_t)nv);
  if (x && v && fe && fd) {
    for (int32_t i = 0; i < nv; ++i) {
      const double *p = rest + 3 * i;
      double *q = x + 3 * i;
      q[0] = kind == COLLAPSE_TO_POINT ? 0.1 : p[0];
      q[1] = kind == COLLAPSE_TO_PLANE ? p[1] : 0.1;
      q[2] = 0.1;
    }
    int finite = 1, s = 0;
    for (double t = 0; t < recovery_collapse_seconds && finite; ++s) {
      piola_elastic_stats start;
      finite = piola_elastic_body_update(body, x, 1.0, fe, s == 0 ? &start : NULL) == PIOLA_OK;
      if (s == 0 && finite) out.start_energy = start.elastic_energy;
      /* the simulator's own state-aware bound (docs/time-stepping.md) at half its CFL number */
      const double dt = fmin(dt_damping, 0.5 / sqrt(piola__elastic_body_state_rate2(body, NULL)));
      t += dt;
      piola_elastic_body_damping_forces(body, v, beta, alpha, fd);
      for (int32_t i = 0; i < 3 * nv; ++i) {
        v[i] += dt * (fe[i] + fd[i]) / mass[i / 3];
        x[i] += dt * v[i];
        finite = finite && isfinite(x[i]);
      }
    }
    out.steps = s;
    piola_elastic_stats stats;
    if (finite && piola_elastic_body_update(body, x, 1.0, fe, &stats) == PIOLA_OK) {
      const double *fhat = piola_elastic_body_fhat(body);
      out.position_error = recovery_procrustes_error(x, rest, mass, nv);
      out.fhat_error = 0.0;
      for (int32_t t = 0; t < 3 * nt; ++t) out.fhat_error = fmax(out.fhat_error, fabs(fhat[t] - 1.0));
      out.inverted = stats.inverted_count;
      out.end_energy = stats.elastic_energy;
      double smallest = INFINITY;
      for (int32_t t = 0; t < 3 * nt; ++t) smallest = fmin(smallest, fhat[t]);
      if (out.position_error <= 1e-3 && out.fhat_error <= 1e-3 && out.inverted == 0)
        out.result = RECOVERY_RECOVERED;
      else if (stats.elastic_energy < 1e-3)
        out.result = RECOVERY_SLOW;
      else
        out.result = smallest >= material->threshold ? RECOVERY_STUCK_MODEL : RECOVERY_STUCK_EXTENSION;
    }
  }
  free(x);
  free(v);
  free(fe);
  free(fd);
  piola_elastic_body_destroy(body);
  return out;
}
