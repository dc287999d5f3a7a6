/* The thread count of piola's parallel loops.
 *
 * Every `#pragma omp parallel` in the library says num_threads(piola__thread_count()), so
 * piola_set_thread_count (include/piola/threads.h) is the one setting that governs them all,
 * without touching the process-wide OpenMP default that the host program may rely on. Loops
 * keep their own `if (size)` thresholds: below them they run on one thread whatever the
 * setting, since a parallel region costs more than the work. */
#ifndef PIOLA_COMMON_THREADS_H
#define PIOLA_COMMON_THREADS_H

#include "piola/threads.h"

/* The number of threads a parallel loop should use: the piola_set_thread_count value, or
 * omp_get_max_threads() when none was set. */
int piola__thread_count(void);

#endif
