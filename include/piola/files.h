/* piola: whole files in and out.
 *
 * Input files are read whole (piola_read_file). Output files are first written to a temporary file in the target's folder and renamed
 * over the target only once complete. A crash, a full disk or an error mid-way leaves the
 * previous file (or no file) in place, never a truncated one passed off as complete.
 *
 *   piola_atomic_file f;
 *   if (piola_atomic_file_open(&f, path) != PIOLA_OK) return ...;
 *   fprintf(f.stream, ...);
 *   return piola_atomic_file_commit(&f);   // or piola_atomic_file_abort(&f) on error */
#ifndef PIOLA_FILES_H
#define PIOLA_FILES_H

#include <stddef.h>
#include <stdio.h>

#include "piola/export.h"
#include "piola/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Reads the regular file at path into *data (malloc'd, NUL-terminated; free() it) and its
 * length in bytes into *size. A file larger than max_size bytes (0: no limit) is refused
 * with PIOLA_ERROR_IO, before anything is allocated. */
PIOLA_API piola_status piola_read_file(const char *path, size_t max_size, char **data,
                                       size_t *size);

typedef struct piola_atomic_file {
  FILE *stream; /* write here between open and commit */
  char target[4096];
  char temporary[4096];
} piola_atomic_file;

/* Opens a temporary file next to path (its folder must exist). */
PIOLA_API piola_status piola_atomic_file_open(piola_atomic_file *file, const char *path);
/* Flushes, checks for write errors, and renames into place. Closes the stream either way. */
PIOLA_API piola_status piola_atomic_file_commit(piola_atomic_file *file);
/* Closes and deletes the temporary file. */
PIOLA_API void piola_atomic_file_abort(piola_atomic_file *file);

#ifdef __cplusplus
}
#endif

#endif
