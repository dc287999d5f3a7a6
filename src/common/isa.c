/* The choice of kernel variant (common/isa.h, piola/kernels.h): made once, on first use,
 * from what the CPU supports and the PIOLA_ISA environment variable. */
#include "common/isa.h"

#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "piola/kernels.h"

#define PIOLA_ISA_STRING2(x) #x
#define PIOLA_ISA_STRING(x) PIOLA_ISA_STRING2(x)

#if defined(PIOLA_KERNEL_DISPATCH)

static const char *const ISA_NAMES[] = {"baseline", "avx2", "avx512"};

/* Whether this build has the variant (CMakeLists.txt, PIOLA_KERNEL_VARIANTS). */
static int built(piola__isa isa) {
#if defined(PIOLA_KERNEL_WITHOUT_AVX2)
  if (isa == PIOLA__ISA_AVX2) return 0;
#endif
#if defined(PIOLA_KERNEL_WITHOUT_AVX512)
  if (isa == PIOLA__ISA_AVX512) return 0;
#endif
  (void)isa;
  return 1;
}

/* What each variant is compiled for (CMakeLists.txt, PIOLA_KERNEL_FLAGS_*): AVX2 with FMA,
 * and AVX-512 F, CD, BW, DQ and VL on top. __builtin_cpu_supports also asks whether the
 * operating system saves the wide registers. */
static int cpu_runs(piola__isa isa) {
  __builtin_cpu_init();
  int avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  int avx512 = avx2 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512cd") &&
               __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
               __builtin_cpu_supports("avx512vl");
  return isa == PIOLA__ISA_AVX512 ? avx512 : isa == PIOLA__ISA_AVX2 ? avx2 : 1;
}

int piola__isa_supported(piola__isa isa) { return built(isa) && cpu_runs(isa); }

/* the best variant this build has and the CPU runs, not above `ceiling` */
static piola__isa best_up_to(piola__isa ceiling) {
  for (int i = ceiling; i > PIOLA__ISA_BASELINE; --i)
    if (piola__isa_supported((piola__isa)i)) return (piola__isa)i;
  return PIOLA__ISA_BASELINE;
}

const char *piola__isa_name(piola__isa isa) { return ISA_NAMES[isa]; }

static piola__isa choose(void) {
  piola__isa best = best_up_to(PIOLA__ISA_AVX512);
  const char *asked = getenv("PIOLA_ISA");
  if (!asked || !*asked) return best;
  for (int i = 0; i <= PIOLA__ISA_AVX512; ++i)
    if (strcmp(asked, ISA_NAMES[i]) == 0) {
      piola__isa got = best_up_to((piola__isa)i);
      if (got != (piola__isa)i)
        fprintf(stderr, "piola: PIOLA_ISA=%s: %s, using %s\n", asked,
                built((piola__isa)i) ? "this CPU does not support it" : "not built in this build",
                ISA_NAMES[got]);
      return got;
    }
  fprintf(stderr, "piola: PIOLA_ISA=%s is not one of baseline, avx2, avx512; using %s\n", asked,
          ISA_NAMES[best]);
  return best;
}

/* -1 until chosen; two threads choosing at once choose the same */
static atomic_int chosen = -1;

piola__isa piola__isa_variant(void) {
  int isa = atomic_load_explicit(&chosen, memory_order_relaxed);
  if (isa < 0) {
    int expected = -1;
    isa = (int)choose();
    if (!atomic_compare_exchange_strong(&chosen, &expected, isa)) isa = expected;
  }
  return (piola__isa)isa;
}

const char *piola_kernel_isa(void) { return ISA_NAMES[piola__isa_variant()]; }

#else

piola__isa piola__isa_variant(void) { return PIOLA__ISA_BASELINE; }

int piola__isa_supported(piola__isa isa) { return isa == PIOLA__ISA_BASELINE; }

const char *piola__isa_name(piola__isa isa) {
  return isa == PIOLA__ISA_BASELINE ? PIOLA_ISA_STRING(PIOLA_KERNEL_SINGLE) : "none";
}

const char *piola_kernel_isa(void) { return PIOLA_ISA_STRING(PIOLA_KERNEL_SINGLE); }

#endif
