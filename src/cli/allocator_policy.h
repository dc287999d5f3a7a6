/* How `piola run` asks the C library's allocator to treat freed memory. Header only, so that
 * the benchmarks (bench_fracture*) time cuts as the program runs them. */
#ifndef PIOLA_CLI_ALLOCATOR_POLICY_H
#define PIOLA_CLI_ALLOCATOR_POLICY_H

#if defined(__GLIBC__)
#include <malloc.h>
#endif

/* A body that changes its mesh (a cut, docs/fracture.md) is rebuilt into new arrays of about
 * its old size, then the old ones are freed. With glibc's defaults, arrays above its mmap
 * threshold (128 KiB at first) are mapped and unmapped one by one and the heap top is given
 * back beyond the trim threshold, so every rebuild touched fresh pages: on the project's
 * virtual machine the page faults cost more than the rebuild's arithmetic (an 18,000-tet
 * body's creation, first force update and first damping assembly: 24 ms instead of 7 ms,
 * bench_fresh_body; BENCHMARKS.md "Fracture"). Arrays up to 32 MiB (glibc's largest mmap threshold) come from the heap
 * instead and up to 1 GiB of freed heap is kept, so a rebuild reuses the pages its
 * predecessor freed. No effect with other C libraries. */
static inline void piola_cli_keep_freed_memory(void) {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);
  mallopt(M_TRIM_THRESHOLD, 1024 * 1024 * 1024);
#endif
}

#endif
