/* One commit point per frame (frame_commit.c).
 *
 * Every file of a frame is first written whole under a temporary name; then the data files
 * (VTU, OBJ) are renamed into place, and only then the two indexes (stats.csv, then
 * sim.pvd). So an index never lists a frame whose files are not all in place, whatever
 * moment a kill -9 or a power cut hits. What a kill can leave is a frame's data files
 * without an index entry, stats.csv one frame ahead of sim.pvd, and temporaries: the next
 * --resume or --force run cleans these (output_reconcile.c). */
#ifndef PIOLA_OUTPUT_FRAME_COMMIT_H
#define PIOLA_OUTPUT_FRAME_COMMIT_H

#include <stddef.h>

#include "piola/status.h"

enum { FRAME_COMMIT_MAX_FILES = 4, FRAME_COMMIT_PATH = 4200 };

typedef struct frame_commit {
  int count;
  int data_count; /* the first data_count files are data files, the rest indexes */
  char from[FRAME_COMMIT_MAX_FILES][FRAME_COMMIT_PATH];
  char to[FRAME_COMMIT_MAX_FILES][FRAME_COMMIT_PATH];
} frame_commit;

/* The name a data file waits under before its commit: "frame_0007.vtu" becomes
 * "frame_0007.pending.vtu" (the extension stays last, since writers choose the format by
 * it). False when it does not fit. */
int piola__frame_pending_name(const char *final_path, char *out, size_t size);

/* Queues the rename of the complete file from to its place to (in the order given). */
void piola__frame_commit_add(frame_commit *c, const char *from, const char *to, int is_index);
/* Renames every queued file in order. On a failure before any index was renamed, the data
 * files already moved are removed again (the frame stays invisible); the rest of the
 * temporaries are removed either way. */
piola_status piola__frame_commit_publish(frame_commit *c);
/* Removes every queued temporary (the frame is abandoned). */
void piola__frame_commit_discard(frame_commit *c);

#endif
