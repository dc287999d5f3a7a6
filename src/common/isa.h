/* Kernels built once per instruction set, and the choice among them (piola/kernels.h).
 *
 * A kernel translation unit (CMakeLists.txt, PIOLA_KERNEL_SOURCES) is compiled once per
 * variant with PIOLA_KERNEL_ISA set to the variant's name, and defines its entry points as
 * PIOLA_ISA_NAME(f), that is f_baseline, f_avx2, f_avx512 (or f_native, f_portable in a
 * build with one variant; a sanitizer build has no f_avx2). A wrapper with the plain name f,
 * in ordinary code, calls PIOLA_ISA_SELECT(f), the variant piola__isa_variant() chose. */
#ifndef PIOLA_COMMON_ISA_H
#define PIOLA_COMMON_ISA_H

#define PIOLA_ISA_CAT2(name, isa) name##_##isa
#define PIOLA_ISA_CAT(name, isa) PIOLA_ISA_CAT2(name, isa)
#ifdef PIOLA_KERNEL_ISA
#define PIOLA_ISA_NAME(name) PIOLA_ISA_CAT(name, PIOLA_KERNEL_ISA)
#endif

/* The variants, in increasing order of what they need from the CPU. */
typedef enum piola__isa { PIOLA__ISA_BASELINE, PIOLA__ISA_AVX2, PIOLA__ISA_AVX512 } piola__isa;

/* The variant chosen, once, on first call: the best built variant the CPU supports, or, if
 * PIOLA_ISA names one, the best built one the CPU supports that is not above it. Always
 * PIOLA__ISA_BASELINE in a build with one variant. */
piola__isa piola__isa_variant(void);

/* Whether this build has variant isa and this CPU runs it (tests compare the variants). In a
 * build with one variant, only PIOLA__ISA_BASELINE, which stands for it. */
int piola__isa_supported(piola__isa isa);

/* "baseline", "avx2", "avx512"; in a build with one variant, its name for
 * PIOLA__ISA_BASELINE. */
const char *piola__isa_name(piola__isa isa);

#if defined(PIOLA_KERNEL_DISPATCH)
/* All three variants are built unless PIOLA_KERNEL_WITHOUT_AVX2 or PIOLA_KERNEL_WITHOUT_AVX512
 * says otherwise (CMakeLists.txt: a sanitizer build leaves AVX2 out); baseline always is.
 * PIOLA_ISA_AVX2_OR(f, other) is f_avx2 where that variant is built, else other. */
#if !defined(PIOLA_KERNEL_WITHOUT_AVX2)
#define PIOLA_ISA_AVX2_OR(name, other) name##_avx2
#define PIOLA_ISA_DECLARE_AVX2(ret, name, params) ; ret name##_avx2 params
#else
#define PIOLA_ISA_AVX2_OR(name, other) other
#define PIOLA_ISA_DECLARE_AVX2(ret, name, params)
#endif
#if !defined(PIOLA_KERNEL_WITHOUT_AVX512)
#define PIOLA_ISA_AVX512_OR(name, other) name##_avx512
#define PIOLA_ISA_DECLARE_AVX512(ret, name, params) ; ret name##_avx512 params
#else
#define PIOLA_ISA_AVX512_OR(name, other) other
#define PIOLA_ISA_DECLARE_AVX512(ret, name, params)
#endif
#define PIOLA_ISA_DECLARE(ret, name, params)           \
  ret name##_baseline params                           \
  PIOLA_ISA_DECLARE_AVX2(ret, name, params)            \
  PIOLA_ISA_DECLARE_AVX512(ret, name, params)
/* piola__isa_variant() never chooses a variant that is not built */
#define PIOLA_ISA_SELECT(name)                                                          \
  (piola__isa_variant() == PIOLA__ISA_AVX512 ? PIOLA_ISA_AVX512_OR(name, name##_baseline) \
   : piola__isa_variant() == PIOLA__ISA_AVX2 ? PIOLA_ISA_AVX2_OR(name, name##_baseline)   \
                                             : name##_baseline)
#else
/* one variant, named by PIOLA_KERNEL_SINGLE (native or portable) */
#define PIOLA_ISA_DECLARE(ret, name, params) ret PIOLA_ISA_CAT(name, PIOLA_KERNEL_SINGLE) params
#define PIOLA_ISA_SELECT(name) PIOLA_ISA_CAT(name, PIOLA_KERNEL_SINGLE)
#endif

#endif
