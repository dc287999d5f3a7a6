/* Shared helpers for the cmocka unit tests. */
#ifndef PIOLA_TEST_SUPPORT_H
#define PIOLA_TEST_SUPPORT_H

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
/* cmocka.h needs the headers above first. */
#include <cmocka.h>

/* Multiplier for the sample counts of heavy property tests: 1 normally, smaller under
 * the sanitizers (PIOLA_TEST_SCALE in the environment). Never returns less than 1e-3. */
double test_scale(void);

/* Sample count n scaled by test_scale(), at least `minimum`. */
long test_samples(long n, long minimum);

/* Deterministic xorshift random numbers, so failures reproduce. */
typedef struct test_rng {
  uint64_t state;
} test_rng;
test_rng test_rng_seeded(uint64_t seed);
uint64_t test_rng_next(test_rng *rng);
double test_rng_uniform(test_rng *rng, double lo, double hi); /* in [lo, hi) */
double test_rng_normal(test_rng *rng);                         /* standard normal */

/* Eigenvalues of the symmetric n x n matrix a (row-major) by cyclic Jacobi, unsorted: the
 * dense reference the projected stiffnesses are checked against. a is destroyed. */
void test_symmetric_eigenvalues(double *a, int n, double *lambda);

/* Asserts |a - b| <= tol with a message that prints both values. */
#define assert_close(a, b, tol)                                                            \
  do {                                                                                     \
    double assert_close_a_ = (a), assert_close_b_ = (b), assert_close_t_ = (tol);          \
    if (!(fabs(assert_close_a_ - assert_close_b_) <= assert_close_t_))                     \
      fail_msg("%s = %.17g and %s = %.17g differ by more than %g", #a, assert_close_a_, #b, \
               assert_close_b_, assert_close_t_);                                          \
  } while (0)

/* Path of a file in ../shared/data (static buffer, valid until the next call). */
const char *test_data_path(const char *relative);

/* A group setup's scratch folder: makes a fresh /tmp/<prefix>_XXXXXX (its name in dir, of
 * `size` bytes). Returns 0, or -1 if it cannot (a cmocka group setup's convention). */
int test_make_scratch_folder(char *dir, size_t size, const char *prefix);

/* Removes folder dir and everything in it (rm -rf). Returns 0, or -1 (a group teardown's
 * convention). */
int test_remove_scratch_folder(const char *dir);

/* The whole text file at path, NUL-terminated (free it); fails the test if it cannot be read. */
char *test_read_text(const char *path);

/* Replaces the first occurrence of from in text by to (no longer than from), in place: tests
 * edit an example scene's text before loading it. Fails the test if from is absent. */
void test_replace_first(char *text, const char *from, const char *to);

#endif
