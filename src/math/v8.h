/* 8-lane double vectors: the one vocabulary of piola's hand-vectorized kernels (the SVD and
 * force lanes in svd_kernel.h, the plastic lanes, log and exp in v8_logexp.h).
 *
 * One piola_v8d holds one value of 8 elements: one AVX-512 register, or two or four narrower
 * ones on other targets (GCC and clang vector extensions). */
#ifndef PIOLA_MATH_V8_H
#define PIOLA_MATH_V8_H

#include <stdint.h>
#include <string.h>

/* The kernels must be inlined into the caller's `omp simd` loop, or that loop cannot be
 * vectorized. */
#if defined(__GNUC__) || defined(__clang__)
#define PIOLA_KERNEL_INLINE static inline __attribute__((always_inline))
#else
#define PIOLA_KERNEL_INLINE static inline
#endif
/* Functions holding a lane loop ask for full AVX-512 vectors where the build targets them
 * (GCC otherwise prefers 256-bit vectors on these CPUs; the kernel is ~30% faster at 512). */
#if defined(__GNUC__) && !defined(__clang__) && defined(__AVX512F__)
#define PIOLA_WIDE_VECTORS __attribute__((target("prefer-vector-width=512")))
#else
#define PIOLA_WIDE_VECTORS
#endif

/* The kernel is always inlined, so the ABI of passing these vectors by value (which GCC
 * and clang warn about where the target has no 512-bit registers) never applies. GCC reports it at
 * the end of the translation unit, so the note stays off for the rest of the includer
 * (which passes no vectors by value itself). */
#if defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
typedef double piola_v8d __attribute__((vector_size(64)));
typedef int64_t piola_v8l __attribute__((vector_size(64)));
typedef uint64_t piola_v8u __attribute__((vector_size(64)));

#define PIOLA_V8_SELECT(mask, a, b) \
  ((piola_v8d)(((mask) & (piola_v8l)(a)) | (~(mask) & (piola_v8l)(b))))
PIOLA_KERNEL_INLINE piola_v8d piola__v8_abs(piola_v8d x) {
  return (piola_v8d)((piola_v8l)x & INT64_C(0x7fffffffffffffff));
}
PIOLA_KERNEL_INLINE piola_v8d piola__v8_splat(double x) {
  piola_v8d r = {x, x, x, x, x, x, x, x};
  return r;
}
PIOLA_KERNEL_INLINE piola_v8d piola__v8_load(const double *p) {
  piola_v8d r;
  memcpy(&r, p, sizeof r);
  return r;
}
PIOLA_KERNEL_INLINE void piola__v8_store(double *p, piola_v8d x) { memcpy(p, &x, sizeof x); }

#endif
