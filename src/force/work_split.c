/* The elastic body's work split among processes (piola/work_split.h).
 *
 * The force loop runs on this process's blocks only, in the order and pairing the whole loop
 * uses: the blocks are cut into PIOLA_FORCE_CHUNKS fixed ranges of the process's block
 * list, each summed in tet order into its own array, the arrays added in range order. With
 * one process the list is every block and the ranges are the whole loop's: no bit changes.
 * Then the split's operations make the forces and the per-tet state whole on every process.
 *
 * Per-tet state exchanged per block: U and V (9 each), Fhat (3), det F, and with stats the
 * energy density and the block's three statistics: what the damping assembly, the step
 * bound, plasticity, the getters and the frames read. */
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "force/elastic_body_internal.h"
#include "force/stable_step_modulus.h"
#include "material/hgo_kernels.h"
#include "material/material_kernels.h"

#define B PIOLA_TET_BLOCK
#define STATE_WIDTH (B * (9 + 9 + 3 + 1))
#define STATE_WIDTH_MAX (STATE_WIDTH + B + 3)

_Static_assert(PIOLA_WORK_SPLIT_BLOCK == PIOLA_TET_BLOCK, "a split block is a force-loop block");

int32_t piola_elastic_body_block_count(const piola_elastic_body *body) {
  return body ? body->padded_tet_count / B : 0;
}

const piola_work_split *piola_elastic_body_work_split(const piola_elastic_body *body) {
  return body ? body->split : NULL;
}

void piola__elastic_body_split_free(piola_elastic_body *body) {
  free(body->split_blocks);
  free(body->split_buffer);
  free(body->split_held);
  body->split_blocks = NULL;
  body->split_buffer = NULL;
  body->split_held = NULL;
  body->split = NULL;
  body->split_block_count = 0;
  body->split_local = 0;
}

/* Local mode: which blocks this process holds, its own and those with a tet on one of its
 * nodes (their rotations enter its nodes' damping rows). */
static void mark_held(piola_elastic_body *body, const piola_work_split *split) {
  const int32_t blocks = body->padded_tet_count / B;
  for (int32_t b = 0; b < blocks; ++b) {
    int held = split->block_part[b] == split->part;
    for (int32_t t = b * B; !held && t < (b + 1) * B && t < body->tet_count; ++t)
      for (int c = 0; c < 4; ++c) held |= split->node_part[body->tet_vertices[c][t]] == split->part;
    body->split_held[b] = (uint8_t)held;
  }
}

/* Local mode: fresh per-tet state arrays (U, V, Fhat, det F, energy density) in which only
 * the held blocks are written, so the memory of the other blocks is never touched (calloc
 * leaves fresh pages unmapped until written); the old arrays, written for every tet, are
 * freed. From here on the body is partial: it can only step with this split
 * (piola_elastic_body_update refuses it without one). */
static int localize_state(piola_elastic_body *body) {
  const size_t np = (size_t)body->padded_tet_count;
  body->split_partial = 1; /* also when this fails half way */
  double *u = calloc(9 * np, sizeof(double)), *v = calloc(9 * np, sizeof(double));
  double *fhat = calloc(3 * np, sizeof(double)), *det = calloc(np, sizeof(double));
  double *psi = calloc(np, sizeof(double));
  if (!u || !v || !fhat || !det || !psi) {
    free(u), free(v), free(fhat), free(det), free(psi);
    return 0;
  }
  const double *u0 = body->u[0], *v0 = body->v[0];
  for (size_t b = 0; b < np / B; ++b) {
    if (!body->split_held[b]) continue;
    for (size_t t = b * B; t < (b + 1) * B; ++t) {
      for (int k = 0; k < 9; ++k) {
        u[k * np + t] = u0[k * np + t];
        v[k * np + t] = v0[k * np + t];
      }
      for (int k = 0; k < 3; ++k) fhat[3 * t + k] = body->fhat[3 * t + k];
      det[t] = body->det_f[t];
      psi[t] = body->energy_density[t];
    }
  }
  free(body->u[0]), free(body->v[0]), free(body->fhat), free(body->det_f);
  free(body->energy_density);
  if (body->ogden_cache) { /* fresh too: only the held blocks' slots get written */
    free(body->ogden_cache);
    body->ogden_cache = calloc(OGDEN_CACHE_SLOTS * np, sizeof(double)); /* NULL: no cache */
  }
  if (body->hgo_cache) {
    free(body->hgo_cache);
    body->hgo_cache = calloc(HGO_CACHE_SLOTS * np, sizeof(double));
  }
  if (body->step_cache) {
    free(body->step_cache);
    body->step_cache = calloc(STEP_CACHE_SLOTS * (np / B), sizeof(double));
  }
  for (int k = 0; k < 9; ++k) {
    body->u[k] = u + (size_t)k * np;
    body->v[k] = v + (size_t)k * np;
  }
  body->fhat = fhat;
  body->det_f = det;
  body->energy_density = psi;
  return 1;
}

/* The rest data only held blocks read: Dm^-1 and the damping matrix's tet slots, copied
 * into fresh arrays written for the held blocks only. The step bound's per-tet weights are
 * built from every tet's Dm^-1 before this (world_solids.c). */
piola_status piola__elastic_body_split_localize_rest(piola_elastic_body *body) {
  if (!body || !body->split_held || body->rest_localized) return PIOLA_OK; /* not local */
  const size_t np = (size_t)body->padded_tet_count;
  for (int k = 0; k < 9; ++k) {
    double *d = calloc(np, sizeof(double));
    if (!d) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "work split: out of memory");
    for (size_t b = 0; b < np / B; ++b)
      if (body->split_held[b]) memcpy(d + b * B, body->dm_inv[k] + b * B, B * sizeof(double));
    free(body->dm_inv[k]);
    body->dm_inv[k] = d;
  }
  const size_t nt = (size_t)body->tet_count;
  piola__damping_matrix *m = &body->damping;
  int32_t *slot = calloc(6 * (nt > 0 ? nt : 1), sizeof(int32_t));
  uint16_t *flags = calloc(nt > 0 ? nt : 1, sizeof(uint16_t));
  if (!slot || !flags) {
    free(slot), free(flags);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "work split: out of memory");
  }
  for (size_t t = 0; t < nt; ++t)
    if (body->split_held[t / B]) {
      memcpy(slot + 6 * t, m->tet_slot + 6 * t, 6 * sizeof(int32_t));
      flags[t] = m->tet_flags[t];
    }
  free(m->tet_slot), free(m->tet_flags);
  m->tet_slot = slot;
  m->tet_flags = flags;
  body->rest_localized = 1;
  return PIOLA_OK;
}

int piola_elastic_body_split_is_local(const piola_elastic_body *body) {
  return body && piola__local_split(body) != NULL;
}

piola_status piola_elastic_body_set_work_split(piola_elastic_body *body,
                                               const piola_work_split *split) {
  return piola__elastic_body_set_work_split(body, split, 1);
}

piola_status piola__elastic_body_set_work_split(piola_elastic_body *body,
                                                const piola_work_split *split, int allow_local) {
  if (!body) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "work split: body is NULL");
  piola__elastic_body_split_free(body);
  if (!split) return PIOLA_OK;
  if (body->split_partial)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "work split: the body holds only its part of an earlier split (local mode)");
  if (split->part_count < 1 || split->part < 0 || split->part >= split->part_count ||
      !split->block_part || !split->node_part || !split->sum_nodes || !split->share_nodes ||
      !split->share_blocks)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "work split: part %d of %d, or a NULL array or operation", (int)split->part,
                      (int)split->part_count);
  const int local_ops = split->share_ghosts && split->reduce && split->collect_blocks;
  if (!local_ops && (split->share_ghosts || split->reduce || split->collect_blocks))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "work split: the local mode needs share_ghosts, reduce and collect_blocks");
  const int32_t blocks = body->padded_tet_count / B;
  int32_t mine = 0;
  for (int32_t b = 0; b < blocks; ++b) {
    if (split->block_part[b] < 0 || split->block_part[b] >= split->part_count)
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "work split: block %d has part %d of %d",
                        (int)b, (int)split->block_part[b], (int)split->part_count);
    mine += split->block_part[b] == split->part;
  }
  for (int32_t i = 0; i < body->vertex_count; ++i)
    if (split->node_part[i] < 0 || split->node_part[i] >= split->part_count)
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "work split: node %d has part %d of %d",
                        (int)i, (int)split->node_part[i], (int)split->part_count);
  const int local = allow_local && local_ops && split->part_count > 1;
  body->split_blocks = malloc(sizeof(int32_t) * (size_t)(mine > 0 ? mine : 1));
  if (local)
    body->split_held = malloc((size_t)(blocks > 0 ? blocks : 1));
  else
    body->split_buffer = malloc(sizeof(double) * STATE_WIDTH_MAX * (size_t)(blocks > 0 ? blocks : 1));
  if (!body->split_blocks || (local ? !body->split_held : !body->split_buffer)) {
    piola__elastic_body_split_free(body);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "work split: out of memory");
  }
  if (local) {
    mark_held(body, split);
    if (body->state_unwritten) { /* built for this split: write the held blocks only */
      piola__elastic_body_rest_rotations(body, body->split_held);
      body->split_partial = 1;
    } else if (!localize_state(body) || piola__elastic_body_split_localize_rest(body) != PIOLA_OK) {
      piola__elastic_body_split_free(body);
      return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "work split: out of memory");
    }
  } else {
    if (body->state_unwritten) piola__elastic_body_rest_rotations(body, NULL);
    /* the replicated mode's bound reads no force-loop cache (stable_step.c,
     * readable_force_loop_cache): its force loop need not form them. The forces are the
     * same bits without them (implicit_worlds_form_no_bound_caches). */
    piola__elastic_body_drop_step_caches(body);
  }
  body->state_unwritten = 0;
  for (int32_t b = 0; b < blocks; ++b)
    if (split->block_part[b] == split->part) body->split_blocks[body->split_block_count++] = b;
  body->split = split;
  body->split_local = local;
  body->damping.ready = 0;
  return PIOLA_OK;
}

/* The blocks list[k0 .. k1) in pairs of consecutive blocks, as update_block_range pairs a
 * range. */
static void update_listed(piola_elastic_body *body, const double *x, double scale,
                          int want_energy, int32_t k0, int32_t k1, double *out) {
  const int32_t *list = body->split_blocks;
  for (int32_t k = k0; k < k1;) {
    const int pair = k + 1 < k1 && list[k + 1] == list[k] + 1;
    piola__elastic_body_update_block_pair(body, x, scale, want_energy, list[k], pair ? 2 : 1, out);
    k += pair ? 2 : 1;
  }
}

static void pack_state(const piola_elastic_body *body, int32_t b, int want_energy, double *o) {
  const size_t base = (size_t)b * B, stride = (size_t)body->padded_tet_count;
  for (int k = 0; k < 9; ++k) memcpy(o + k * B, body->u[0] + k * stride + base, B * sizeof(double));
  for (int k = 0; k < 9; ++k) memcpy(o + (9 + k) * B, body->v[0] + k * stride + base, B * sizeof(double));
  memcpy(o + 18 * B, body->fhat + 3 * base, 3 * B * sizeof(double));
  memcpy(o + 21 * B, body->det_f + base, B * sizeof(double));
  if (!want_energy) return;
  memcpy(o + STATE_WIDTH, body->energy_density + base, B * sizeof(double));
  o[STATE_WIDTH + B] = body->block_energy[b];
  o[STATE_WIDTH + B + 1] = body->block_inverted[b];
  o[STATE_WIDTH + B + 2] = body->block_min_det[b];
}

static void unpack_state(piola_elastic_body *body, int32_t b, int want_energy, const double *o) {
  const size_t base = (size_t)b * B, stride = (size_t)body->padded_tet_count;
  for (int k = 0; k < 9; ++k) memcpy(body->u[0] + k * stride + base, o + k * B, B * sizeof(double));
  for (int k = 0; k < 9; ++k) memcpy(body->v[0] + k * stride + base, o + (9 + k) * B, B * sizeof(double));
  memcpy(body->fhat + 3 * base, o + 18 * B, 3 * B * sizeof(double));
  memcpy(body->det_f + base, o + 21 * B, B * sizeof(double));
  if (!want_energy) return;
  memcpy(body->energy_density + base, o + STATE_WIDTH, B * sizeof(double));
  body->block_energy[b] = o[STATE_WIDTH + B];
  body->block_inverted[b] = (int32_t)o[STATE_WIDTH + B + 1];
  body->block_min_det[b] = o[STATE_WIDTH + B + 2];
}

/* Local mode: a ghost block's U and V, what the damping assembly reads of it. */
#define ROTATION_WIDTH (B * 18)
static void pack_rotations(void *owner, int32_t b, double *o) {
  const piola_elastic_body *body = owner;
  const size_t base = (size_t)b * B, stride = (size_t)body->padded_tet_count;
  for (int k = 0; k < 9; ++k) memcpy(o + k * B, body->u[0] + k * stride + base, B * sizeof(double));
  for (int k = 0; k < 9; ++k) memcpy(o + (9 + k) * B, body->v[0] + k * stride + base, B * sizeof(double));
}
static void unpack_rotations(void *owner, int32_t b, const double *o) {
  piola_elastic_body *body = owner;
  const size_t base = (size_t)b * B, stride = (size_t)body->padded_tet_count;
  for (int k = 0; k < 9; ++k) memcpy(body->u[0] + k * stride + base, o + k * B, B * sizeof(double));
  for (int k = 0; k < 9; ++k) memcpy(body->v[0] + k * stride + base, o + (9 + k) * B, B * sizeof(double));
}

/* Local mode: a ghost block's Fhat. The update does not share it (the force loop and the
 * damping rows read only U and V of a ghost block), but the stiffness assembly does: with
 * the Fhat a ghost block had when last collected, a node's row on its owner differed from
 * the neighbouring rows on the other process, so the split Newton matrix was not symmetric
 * (2-4% in the Frobenius norm on the quasistatic bar of docs/mpi.md) and its CG could
 * return a direction that ascends (docs/mpi.md). */
#define FHAT_WIDTH (B * 3)
static void pack_fhat(void *owner, int32_t b, double *o) {
  const piola_elastic_body *body = owner;
  memcpy(o, body->fhat + 3 * (size_t)b * B, 3 * B * sizeof(double));
}
static void unpack_fhat(void *owner, int32_t b, const double *o) {
  piola_elastic_body *body = owner;
  memcpy(body->fhat + 3 * (size_t)b * B, o, 3 * B * sizeof(double));
}

void piola__elastic_body_split_share_fhat(piola_elastic_body *body) {
  const piola_work_split *split = piola__local_split(body);
  if (split) split->share_ghosts(split->context, body, pack_fhat, unpack_fhat, FHAT_WIDTH);
}

/* For the frames: a block's Fhat, det F and energy density. */
#define FRAME_WIDTH (B * 5)
static void pack_frame(void *owner, int32_t b, double *o) {
  const piola_elastic_body *body = owner;
  const size_t base = (size_t)b * B;
  memcpy(o, body->fhat + 3 * base, 3 * B * sizeof(double));
  memcpy(o + 3 * B, body->det_f + base, B * sizeof(double));
  memcpy(o + 4 * B, body->energy_density + base, B * sizeof(double));
}
static void unpack_frame(void *owner, int32_t b, const double *o) {
  piola_elastic_body *body = owner;
  const size_t base = (size_t)b * B;
  memcpy(body->fhat + 3 * base, o, 3 * B * sizeof(double));
  memcpy(body->det_f + base, o + 3 * B, B * sizeof(double));
  memcpy(body->energy_density + base, o + 4 * B, B * sizeof(double));
}

void piola__elastic_body_split_collect(piola_elastic_body *body) {
  const piola_work_split *split = piola__local_split(body);
  if (!split) return;
  (void)piola_elastic_body_energy_density(body); /* this process's tets */
  split->collect_blocks(split->context, body, pack_frame, unpack_frame, FRAME_WIDTH);
}

void piola__elastic_body_split_update(piola_elastic_body *body, const double *x,
                                      double stiffness_scale, int want_energy, double *forces) {
  const piola_work_split *split = body->split;
  const int32_t count = body->split_block_count;
  piola__elastic_body_sum_block_ranges(body, x, stiffness_scale, want_energy, count,
                                       update_listed, forces);
  if (split->part_count == 1) return;
  split->sum_nodes(split->context, forces);
  if (body->split_local) {
    split->share_ghosts(split->context, body, pack_rotations, unpack_rotations, ROTATION_WIDTH);
    return;
  }
  const int32_t width = want_energy ? STATE_WIDTH_MAX : STATE_WIDTH;
  for (int32_t k = 0; k < count; ++k) {
    const int32_t b = body->split_blocks[k];
    pack_state(body, b, want_energy, body->split_buffer + (size_t)b * (size_t)width);
  }
  split->share_blocks(split->context, body->split_buffer, width);
  const int32_t blocks = body->padded_tet_count / B;
  for (int32_t b = 0; b < blocks; ++b)
    if (split->block_part[b] != split->part)
      unpack_state(body, b, want_energy, body->split_buffer + (size_t)b * (size_t)width);
}
