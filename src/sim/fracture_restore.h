/* Putting a cut solid back into a saved cut state (checkpoints, world_checkpoint.c). */
#ifndef PIOLA_SIM_FRACTURE_RESTORE_H
#define PIOLA_SIM_FRACTURE_RESTORE_H

#include <stdint.h>

#include "piola/status.h"
#include "sim/world_internal.h"

/* A solid's cut state as a checkpoint holds it: per copy (element of the cut mesh) its
 * original tet, the cut that made it (-1: whole), its corner distances (4, m), side (+1 or
 * -1), material fraction, fragment and nodes (4), its further cuts (FRACTURE_MAX_CUTS - 1
 * slots of event, side and 4 distances; event -1: none), and per original tet its copies
 * (FRACTURE_MAX_COPIES, -1 after the last); node_count nodes. */
typedef struct fracture_saved {
  int32_t copy_count, node_count, events, fragment_count;
  const int32_t *parent, *event, *fragment, *tets, *copies, *more_event;
  const int8_t *side, *more_side;
  const double *dist, *fraction, *more_dist;
} fracture_saved;

/* Checks saved against solid b's original mesh (ranges; every node used, and by copies of
 * one original node only) and gives b that cut state: when its mesh differs, b is rebuilt
 * (piola__body_rebuild) with the saved copies and nodes, each copy taking the material and
 * fibre of its original tet and each node the constraint and rest position of its original
 * node; positions and velocities are then the rest positions and 0, for the caller to
 * replace. Returns PIOLA_ERROR_PARSE with a message (*what) when saved does not fit, and
 * leaves b unchanged then. */
piola_status piola__fracture_restore(piola_world *w, world_body *b, const fracture_saved *saved);

#endif
