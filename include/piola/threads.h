/* piola: how many threads the library uses.
 *
 * One setting for every parallel loop of the library (forces, damping, collisions, the
 * mesher, the renderer). Results never depend on it, only speed does: every parallel loop
 * writes disjoint outputs and sums in a fixed order.
 *
 * On a machine busy with other work, OpenMP's default of spinning idle threads makes many
 * threads slower than one: a host program should run with OMP_WAIT_POLICY=passive in its
 * environment (the runtime reads it at start-up only; the `piola` program sets it itself,
 * docs/cli.md). */
#ifndef PIOLA_THREADS_H
#define PIOLA_THREADS_H

#include "piola/export.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Number of OpenMP threads piola's parallel loops use (0 = OpenMP's default,
 * omp_get_max_threads()). Process-wide; set it before starting work, not during. */
PIOLA_API void piola_set_thread_count(int threads);

/* The number of threads a parallel loop uses: the piola_set_thread_count value, or
 * omp_get_max_threads() when none was set. Every `#pragma omp parallel` in piola (and in
 * its scene and render layers) says num_threads(piola_thread_count()), so one setting
 * governs them all without touching the OpenMP default the host program may rely on; loops
 * keep their own size thresholds, below which they run on one thread. */
PIOLA_API int piola_thread_count(void);

#ifdef __cplusplus
}
#endif

#endif
