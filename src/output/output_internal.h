/* Shared between the output folder policy and the frame writer. */
#ifndef PIOLA_OUTPUT_OUTPUT_INTERNAL_H
#define PIOLA_OUTPUT_OUTPUT_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "piola/output.h"

/* Checks the folder policy, creates DIR, DIR/frames and DIR/surface, and when forced
 * removes an earlier run's results. */
piola_status piola__output_prepare_folder(const char *dir, bool force);

/* output_reconcile.c: removes stray temporaries from dir, dir/frames and dir/surface and,
 * with drop_after >= 0, the frames numbered above it. */
void piola__output_remove_strays(const char *dir, long drop_after);
/* For a resume from frame last_frame: checks that frames 0..last_frame are in place and
 * stats.csv lists them, removes strays and later frames, and returns stats.csv's rows for
 * frames 0..last_frame (no header; malloc'ed, *rows owned by the caller). */
piola_status piola__output_reconcile(const char *dir, int32_t last_frame, char **rows, size_t *length);

#endif
