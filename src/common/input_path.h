/* Opening an input file (input_path.c): only a regular file is ever opened for reading.
 * A named pipe would block the open (or the read) forever, a device could be endless or
 * have side effects, a folder reads as an error deep in a parser; each is refused first,
 * with a message that says what the path is. */
#ifndef PIOLA_COMMON_INPUT_PATH_H
#define PIOLA_COMMON_INPUT_PATH_H

#include <stdio.h>

#include "piola/status.h"

/* Opens path ("rb") after checking that it names a regular file: stat first (nothing but a
 * regular file is opened at all), then an open that cannot block (O_NONBLOCK, cleared
 * afterwards) and fstat of what was opened (the path may have been swapped in between).
 * PIOLA_ERROR_IO with "PATH: cannot open: ..." or "PATH: not a regular file (a named
 * pipe)" otherwise. */
piola_status piola__open_input(const char *path, FILE **out);

#endif
