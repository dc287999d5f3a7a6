/* Kernels built once per instruction set, and the choice among them (piola/kernels.h).
 *
 * A kernel translation unit (CMakeLists.txt, PIOLA_KERNEL_SOURCES) is compiled once per
 * variant with PIOLA_KERNEL_ISA set to the variant's name, and defines its entry points as
 * PIOLA_ISA_NAME(f), that is f_baseline, f_avx2, f_avx512 (or f_native, f_portable in a
 * build with one variant). A wrapper with the plain name f, in ordinary code, calls
 * PIOLA_ISA_SELECT(f), the variant piola__isa_variant() chose. */
#ifndef PIOLA_COMMON_ISA_H
#define PIOLA_COMMON_ISA_H

#define PIOLA_ISA_CAT2(name, isa) name##_##isa
#define PIOLA_ISA_CAT(name, isa) PIOLA_ISA_CAT2(name, isa)
#ifdef PIOLA_KERNEL_ISA
#define PIOLA_ISA_NAME(name) PIOLA_ISA_CAT(name, PIOLA_KERNEL_ISA)
#endif

/* The variants, in increasing order of what they need from the CPU. */
typedef enum piola__isa { PIOLA__ISA_BASELINE, PIOLA__ISA_AVX2, PIOLA__ISA_AVX512 } piola__isa;

/* The variant chosen, once, on first call: the best the CPU supports, or a lower one that
 * PIOLA_ISA asks for. Always PIOLA__ISA_BASELINE in a build with one variant. */
piola__isa piola__isa_variant(void);

/* Whether this build has variant isa and this CPU runs it (tests compare the variants). In a
 * build with one variant, only PIOLA__ISA_BASELINE, which stands for it. */
int piola__isa_supported(piola__isa isa);

/* "baseline", "avx2", "avx512"; in a build with one variant, its name for
 * PIOLA__ISA_BASELINE. */
const char *piola__isa_name(piola__isa isa);

#if defined(PIOLA_KERNEL_DISPATCH)
#define PIOLA_ISA_DECLARE(ret, name, params) \
  ret name##_baseline params;                \
  ret name##_avx2 params;                    \
  ret name##_avx512 params
#define PIOLA_ISA_SELECT(name)                                     \
  (piola__isa_variant() == PIOLA__ISA_AVX512 ? name##_avx512      \
   : piola__isa_variant() == PIOLA__ISA_AVX2 ? name##_avx2        \
                                             : name##_baseline)
#else
/* one variant, named by PIOLA_KERNEL_SINGLE (native or portable) */
#define PIOLA_ISA_DECLARE(ret, name, params) ret PIOLA_ISA_CAT(name, PIOLA_KERNEL_SINGLE) params
#define PIOLA_ISA_SELECT(name) PIOLA_ISA_CAT(name, PIOLA_KERNEL_SINGLE)
#endif

#endif
