/* Whole-or-nothing file output.
 *
 * Output files are first written to a temporary file in the target's folder and renamed
 * over the target only once complete. A crash, a full disk or an error mid-way leaves the
 * previous file (or no file) in place, never a truncated one passed off as complete.
 *
 *   atomic_file f;
 *   if (atomic_file_open(&f, path) != PIOLA_OK) return ...;
 *   fprintf(f.stream, ...);
 *   return atomic_file_commit(&f);   // or atomic_file_abort(&f) on error */
#ifndef PIOLA_IO_ATOMIC_FILE_H
#define PIOLA_IO_ATOMIC_FILE_H

#include <stdio.h>

#include "piola/status.h"

typedef struct atomic_file {
  FILE *stream;
  char target[4096];
  char temporary[4096];
} atomic_file;

piola_status atomic_file_open(atomic_file *file, const char *path);
/* Flushes, checks for write errors, and renames into place. Closes the stream either way. */
piola_status atomic_file_commit(atomic_file *file);
/* The first half of commit: flushes, checks for write errors and closes, leaving the
 * complete temporary file for the caller to rename (output/frame_commit.c renames a whole
 * frame's files in a fixed order); on failure the temporary is removed. */
piola_status atomic_file_finish(atomic_file *file);
/* Closes and deletes the temporary file. */
void atomic_file_abort(atomic_file *file);

#endif
