/* The elastic body object and its update: the blocked force loop itself (force_lanes.c) is
 * a kernel built once per instruction set; this file runs it over fixed block ranges and
 * sums them. Layout and determinism design are explained in elastic_body_internal.h. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "force/elastic_body_internal.h"
#include "force/fiber_lanes.h"
#include "force/force_lanes.h"
#include "force/stable_step.h"
#include "material/muscle_kernels.h"

#define B PIOLA_TET_BLOCK

piola_elastic_body_def piola_default_elastic_body_def(void) {
  piola_elastic_body_def def;
  memset(&def, 0, sizeof def);
  def.density = 1000.0;
  return def;
}

piola_status piola_elastic_body_create(const piola_elastic_body_def *def,
                                       piola_elastic_body **out) {
  if (!out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "elastic body out is NULL");
  *out = NULL;
  piola_elastic_body *body = calloc(1, sizeof *body);
  if (!body) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "elastic body: out of memory");
  piola_status status = piola__elastic_body_build_rest_state(body, def, 1);
  if (status != PIOLA_OK) {
    piola__elastic_body_free_arrays(body);
    free(body);
    return status;
  }
  *out = body;
  return PIOLA_OK;
}

piola_status piola__elastic_body_create_split(const piola_elastic_body_def *def,
                                              const piola_work_split *split,
                                              piola_elastic_body **out) {
  if (!out || !split) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "elastic body: NULL argument");
  *out = NULL;
  piola_elastic_body *body = calloc(1, sizeof *body);
  if (!body) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "elastic body: out of memory");
  piola_status status = piola__elastic_body_build_rest_state(body, def, 0);
  if (status == PIOLA_OK) {
    body->state_unwritten = 1;
    status = piola__elastic_body_set_work_split(body, split, 1); /* writes the held state */
  }
  if (status != PIOLA_OK) {
    piola__elastic_body_free_arrays(body);
    free(body);
    return status;
  }
  *out = body;
  return PIOLA_OK;
}

void piola_elastic_body_destroy(piola_elastic_body *body) {
  if (!body) return;
  piola__elastic_body_free_arrays(body);
  free(body);
}

int32_t piola_elastic_body_vertex_count(const piola_elastic_body *body) { return body->vertex_count; }
int32_t piola_elastic_body_tet_count(const piola_elastic_body *body) { return body->tet_count; }
const int32_t *piola_elastic_body_tets(const piola_elastic_body *body) { return body->tets; }
const double *piola_elastic_body_rest_positions(const piola_elastic_body *body) {
  return body->rest_positions;
}
const double *piola_elastic_body_masses(const piola_elastic_body *body) { return body->masses; }
double piola_elastic_body_min_rest_altitude(const piola_elastic_body *body) {
  return body->min_rest_altitude;
}
double piola_elastic_body_max_wave_speed(const piola_elastic_body *body) {
  return body->max_wave_speed;
}
const double *piola_elastic_body_det_f(const piola_elastic_body *body) { return body->det_f; }
/* Computed here, on first request after an update without stats: the energy is not needed
 * to step, so the force loop skips it unless asked. */
const double *piola_elastic_body_energy_density(const piola_elastic_body *body) {
  if (!body->energy_valid) {
    piola_elastic_body *mutable_body = (piola_elastic_body *)body;
    /* a split in the local mode holds the state of its own blocks only */
    const int own_only = piola__local_split(body) != NULL;
    for (int32_t t = 0; t < body->tet_count; ++t) {
      if (own_only && body->split->block_part[t / B] != body->split->part) {
        t = (t / B + 1) * B - 1;
        continue;
      }
      mutable_body->energy_density[t] =
          body->last_stiffness_scale *
          (piola_material_energy_density(&body->materials[body->tet_material[t]], body->fhat + 3 * t) +
           piola__fiber_energy_density(body, t));
    }
    mutable_body->energy_valid = 1;
  }
  return body->energy_density;
}
const double *piola_elastic_body_fhat(const piola_elastic_body *body) { return body->fhat; }

/* The sum of V0 psi over the tets (J), from the energy densities above; on a split in the
 * local mode each process sums its own blocks and the sums are added in process order, so
 * every process gets the same bits (collective there). */
double piola__elastic_body_total_energy(const piola_elastic_body *body) {
  const double *psi = piola_elastic_body_energy_density(body);
  const piola_work_split *local = piola__local_split(body);
  double energy = 0;
  for (int32_t t = 0; t < body->tet_count; ++t) {
    if (local && local->block_part[t / B] != local->part) {
      t = (t / B + 1) * B - 1;
      continue;
    }
    energy += body->rest_volume[t] * psi[t];
  }
  if (local) local->reduce(local->context, &energy, 1, PIOLA_WORK_SPLIT_SUM);
  return energy;
}

static int positions_are_finite(const double *x, int32_t n) {
  int finite = 1;
  for (int32_t i = 0; i < n; ++i) finite &= isfinite(x[i]);
  return finite;
}

void piola__elastic_body_sum_block_ranges(piola_elastic_body *body, const double *x,
                                          double stiffness_scale, int want_energy,
                                          int32_t count, piola__block_range_update *update,
                                          double *forces) {
  const int64_t n = 3 * (int64_t)body->vertex_count;
  if (count < PIOLA_PARALLEL_MIN_BLOCKS || !body->chunk_forces) {
    for (int64_t i = 0; i < n; ++i) forces[i] = 0.0;
    update(body, x, stiffness_scale, want_energy, 0, count, forces);
    return;
  }
  /* Determinism without a per-tet buffer: PIOLA_FORCE_CHUNKS fixed ranges of blocks, each
   * summed in tet order into its own array, the arrays added in chunk order; which thread
   * runs a chunk changes nothing. */
  double *partial = body->chunk_forces;
#pragma omp parallel num_threads(piola_thread_count())
  {
#pragma omp for schedule(static)
    for (int k = 0; k < PIOLA_FORCE_CHUNKS; ++k) {
      double *fk = partial + (size_t)k * (size_t)n;
      for (int64_t i = 0; i < n; ++i) fk[i] = 0.0;
      update(body, x, stiffness_scale, want_energy,
             (int32_t)((int64_t)count * k / PIOLA_FORCE_CHUNKS),
             (int32_t)((int64_t)count * (k + 1) / PIOLA_FORCE_CHUNKS), fk);
    }
#pragma omp for schedule(static)
    for (int64_t i = 0; i < n; ++i) {
      double sum = partial[i];
      for (int k = 1; k < PIOLA_FORCE_CHUNKS; ++k) sum += partial[(size_t)k * (size_t)n + i];
      forces[i] = sum;
    }
  }
}

piola_status piola_elastic_body_update(piola_elastic_body *body, const double *x,
                                       double stiffness_scale, double *forces,
                                       piola_elastic_stats *stats) {
  if (!body || !x || !forces)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "elastic body update: NULL argument");
  if (!(stiffness_scale >= 0) || !isfinite(stiffness_scale))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "stiffness_scale must be >= 0, got %g",
                      stiffness_scale);
  if (!positions_are_finite(x, 3 * body->vertex_count)) {
    for (int32_t i = 0; i < 3 * body->vertex_count; ++i)
      if (!isfinite(x[i]))
        return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "position of vertex %d is not finite",
                          (int)(i / 3));
  }
  if (body->split_partial && !piola__local_split(body))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "elastic body update: the body was split among processes (local mode) and "
                      "holds only its part; it cannot step without that split");
  int32_t blocks = body->padded_tet_count / B;
  if (body->step_cache) { /* the blocks this update forms carry its generation as their key */
    ++body->step_generation;
    (void)piola__elastic_body_step_weights(body); /* NULL (out of memory): no block is cached */
  }
  if (body->split) {
    piola__elastic_body_split_update(body, x, stiffness_scale, stats != NULL, forces);
  } else {
    piola__elastic_body_sum_block_ranges(body, x, stiffness_scale, stats != NULL, blocks,
                                         piola__force_block_range, forces);
  }
  body->has_state = 1;
  body->damping.ready = 0;
  memcpy(body->positions, x, sizeof(double) * 3 * (size_t)body->vertex_count);
  body->energy_valid = stats != NULL;
  body->last_stiffness_scale = stiffness_scale;
  if (stats) {
    double energy = 0, min_det = INFINITY;
    int32_t inverted = 0;
    const piola_work_split *local = piola__local_split(body);
    for (int32_t b = 0; b < blocks; ++b) {
      if (local && local->block_part[b] != local->part) continue; /* held elsewhere */
      energy += body->block_energy[b];
      inverted += body->block_inverted[b];
      min_det = fmin(min_det, body->block_min_det[b]);
    }
    if (local) {
      double sums[2] = {energy, inverted};
      local->reduce(local->context, sums, 2, PIOLA_WORK_SPLIT_SUM);
      local->reduce(local->context, &min_det, 1, PIOLA_WORK_SPLIT_MIN);
      energy = sums[0];
      inverted = (int32_t)sums[1];
    }
    stats->elastic_energy = energy;
    stats->inverted_count = inverted;
    stats->min_det_f = min_det;
  }
  return PIOLA_OK;
}

void piola_elastic_body_set_activation(piola_elastic_body *body, double activation) {
  if (body) body->activation = muscle_clamp_activation(activation);
}

double piola_elastic_body_activation(const piola_elastic_body *body) {
  return body ? body->activation : 0.0;
}

const double *piola_elastic_body_fiber_directions(const piola_elastic_body *body) {
  return body ? body->fiber_aos : NULL;
}
