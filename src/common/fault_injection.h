/* Fault injection for the tests: environment variables that make a run die or fail at a
 * chosen point, so the tests can check what a kill -9 or a full disk leaves behind.
 *
 *   PIOLA_FAULT_KILL_AT_RENAME=K  the K-th rename of an output commit (frames, indexes,
 *                                 checkpoints; counted from 1 in the process) is preceded
 *                                 by SIGKILL, exactly what `kill -9` at that point does
 *   PIOLA_FAULT_FAIL_WRITE_AT=K   the K-th output file finished through io/atomic_file
 *                                 fails as a full disk does (ENOSPC)
 *   PIOLA_FAULT_KILL_IN_WRITE=K   the K-th output file finished through io/atomic_file is
 *                                 cut to the first half of its bytes and the process gets
 *                                 SIGKILL: what a kill -9 in the middle of the write leaves
 *
 * Unset (the normal case) each hook costs one cached getenv. */
#ifndef PIOLA_COMMON_FAULT_INJECTION_H
#define PIOLA_COMMON_FAULT_INJECTION_H

#include <stdio.h>

/* Called right before an output rename: kills the process when its turn has come. */
void piola__fault_before_rename(void);
/* True when this output write is to fail (counts the calls). */
int piola__fault_write_fails(void);
/* Called when the temporary file of an output write is complete (stream still open): kills
 * the process, with half the file written, when its turn has come. */
void piola__fault_during_write(FILE *stream);

#endif
