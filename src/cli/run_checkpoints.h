/* Checkpoints of `piola run` (run_checkpoints.c): DIR/checkpoint_NNNN.bin next to the
 * frames, the newest two kept. */
#ifndef PIOLA_CLI_RUN_CHECKPOINTS_H
#define PIOLA_CLI_RUN_CHECKPOINTS_H

#include <stdint.h>

#include "piola/world.h"

/* The scene key of the world built from scene_path (piola_world_scene_key over the file's
 * bytes and the bodies' rest state). Returns 0 and prints a message when the file cannot
 * be read again. */
int run_scene_key(const char *scene_path, const piola_world *world, uint64_t *key);

/* Loads the newest intact checkpoint of dir into world. Returns 0 with *frame set; 1 when
 * dir holds no checkpoint at all; 2 (message printed) when one is refused: another scene,
 * another format version, or none intact. Damaged newer ones are skipped with a warning. */
int run_checkpoint_resume(const char *dir, piola_world *world, uint64_t key, int32_t *frame);

/* The frame numbers of dir's checkpoint_NNNN<suffix> files (suffix ".bin": a single
 * process's checkpoints), newest first (*count of them; malloc'ed, may be NULL). */
int32_t *run_checkpoint_list(const char *dir, const char *suffix, int *count);

/* The number of frame rows in dir/stats.csv (0 when it is missing). */
int run_listed_frames(const char *dir);

/* Writes dir/checkpoint_<frame>.bin and removes older checkpoints but the previous one. */
int run_checkpoint_save(const char *dir, const piola_world *world, uint64_t key, int32_t frame);

#endif
