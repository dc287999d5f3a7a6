/* The first half of piola_atomic_file_commit (piola/files.h), for writers in the core that
 * publish several files at one commit point (output/frame_commit.c). */
#ifndef PIOLA_IO_ATOMIC_FILE_INTERNAL_H
#define PIOLA_IO_ATOMIC_FILE_INTERNAL_H

#include "piola/files.h"

/* Flushes, checks for write errors and closes, leaving the complete temporary file for the
 * caller to rename; on failure the temporary is removed. */
piola_status piola__atomic_file_finish(piola_atomic_file *file);

#endif
