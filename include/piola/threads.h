/* piola: how many threads the library uses.
 *
 * One setting for every parallel loop of the library (forces, damping, collisions, the
 * mesher, the renderer). Results never depend on it, only speed does: every parallel loop
 * writes disjoint outputs and sums in a fixed order. */
#ifndef PIOLA_THREADS_H
#define PIOLA_THREADS_H

#include "piola/export.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Number of OpenMP threads piola's parallel loops use (0 = OpenMP's default,
 * omp_get_max_threads()). Process-wide; set it before starting work, not during. */
PIOLA_API void piola_set_thread_count(int threads);

#ifdef __cplusplus
}
#endif

#endif
