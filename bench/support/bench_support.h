/* Helpers every benchmark program shares: clocks, medians and a fixed random sequence.
 * Linked into each benchmark program by CMakeLists.txt (every .c file in bench/support). */
#ifndef PIOLA_BENCH_SUPPORT_H
#define PIOLA_BENCH_SUPPORT_H

#include <stdint.h>

#include "piola/material.h"

/* With the argument "--default-allocator" (taken out of argv, *argc updated) the C library's
 * allocator keeps its defaults; otherwise freed memory is treated as `piola run` treats it
 * (src/cli/allocator_policy.h), so a benchmark times what the program does. Prints which. */
void bench_allocator(int *argc, char **argv);

/* Monotonic wall-clock time, s. */
double bench_wall_seconds(void);

/* CPU time of the whole process (all threads), s: steadier than wall time on a busy machine. */
double bench_cpu_seconds(void);

/* CPU time of the calling thread, s: excludes time other processes hold the core. */
double bench_thread_cpu_seconds(void);

/* qsort comparator for doubles, ascending. */
int bench_compare_doubles(const void *a, const void *b);

/* Median of n values (sorts v in place; the mean of the middle two when n is even). */
double bench_median(double *v, int n);

/* Uniform in [lo, hi) from one xorshift sequence with a fixed seed, so runs are repeatable. */
double bench_uniform(double lo, double hi);

/* Restarts bench_uniform's sequence; seed 0 is the sequence a process starts with. */
void bench_seed(uint64_t seed);

/* The default material definition of `model` at the setting of BENCHMARKS.md's rows: LINEAR
 * inversion at threshold 0.3 (the default before issue 19 item 4). */
piola_material_def bench_rows_material_def(piola_material_model model);

#endif
