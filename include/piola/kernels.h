/* piola: which instruction set the numerical kernels run on.
 *
 * The hot kernels (the 3x3 diagonalization and force lanes, muscle fibres, the damping
 * matrix assembly, the step bound, the plastic return map) are built once per instruction
 * set in a portable x86-64 build (baseline x86-64, AVX2 with FMA, AVX-512) and the best one the CPU supports
 * is chosen on first use; the rest of the library is plain x86-64 (docs/architecture.md,
 * "Instruction sets"). The environment variable PIOLA_ISA (baseline, avx2 or avx512), read
 * once on first use, asks for a lower one, for tests and comparisons. A build configured with
 * PIOLA_NATIVE=ON, or for another architecture, has one variant only. */
#ifndef PIOLA_KERNELS_H
#define PIOLA_KERNELS_H

#include "piola/export.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The name of the kernel variant in use: "baseline", "avx2" or "avx512" in a dispatching
 * build, "native" (PIOLA_NATIVE=ON) or "portable" (a build without dispatch) otherwise. */
PIOLA_API const char *piola_kernel_isa(void);

#ifdef __cplusplus
}
#endif

#endif
