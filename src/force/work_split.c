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

#define B PIOLA_TET_BLOCK
#define STATE_WIDTH (B * (9 + 9 + 3 + 1))
#define STATE_WIDTH_MAX (STATE_WIDTH + B + 3)

_Static_assert(PIOLA_WORK_SPLIT_BLOCK == PIOLA_TET_BLOCK, "a split block is a force-loop block");

int32_t piola_elastic_body_block_count(const piola_elastic_body *body) {
  return body ? body->padded_tet_count / B : 0;
}

void piola__elastic_body_split_free(piola_elastic_body *body) {
  free(body->split_blocks);
  free(body->split_buffer);
  body->split_blocks = NULL;
  body->split_buffer = NULL;
  body->split = NULL;
  body->split_block_count = 0;
}

piola_status piola_elastic_body_set_work_split(piola_elastic_body *body,
                                               const piola_work_split *split) {
  if (!body) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "work split: body is NULL");
  piola__elastic_body_split_free(body);
  if (!split) return PIOLA_OK;
  if (split->part_count < 1 || split->part < 0 || split->part >= split->part_count ||
      !split->block_part || !split->node_part || !split->sum_nodes || !split->share_nodes ||
      !split->share_blocks)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "work split: part %d of %d, or a NULL array or operation", (int)split->part,
                      (int)split->part_count);
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
  body->split_blocks = malloc(sizeof(int32_t) * (size_t)(mine > 0 ? mine : 1));
  body->split_buffer = malloc(sizeof(double) * STATE_WIDTH_MAX * (size_t)(blocks > 0 ? blocks : 1));
  if (!body->split_blocks || !body->split_buffer) {
    piola__elastic_body_split_free(body);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "work split: out of memory");
  }
  for (int32_t b = 0; b < blocks; ++b)
    if (split->block_part[b] == split->part) body->split_blocks[body->split_block_count++] = b;
  body->split = split;
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

void piola__elastic_body_split_update(piola_elastic_body *body, const double *x,
                                      double stiffness_scale, int want_energy, double *forces) {
  const piola_work_split *split = body->split;
  const int32_t count = body->split_block_count;
  piola__elastic_body_sum_block_ranges(body, x, stiffness_scale, want_energy, count,
                                       update_listed, forces);
  if (split->part_count == 1) return;
  split->sum_nodes(split->context, forces);
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
