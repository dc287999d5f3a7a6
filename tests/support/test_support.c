#include "test_support.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

double test_scale(void) {
  const char *s = getenv("PIOLA_TEST_SCALE");
  if (!s) return 1.0;
  double v = atof(s);
  return v < 1e-3 ? 1e-3 : v;
}

long test_samples(long n, long minimum) {
  long scaled = (long)((double)n * test_scale());
  return scaled < minimum ? minimum : scaled;
}

test_rng test_rng_seeded(uint64_t seed) {
  test_rng rng = {seed * 0x9E3779B97F4A7C15ull + 0x2545F4914F6CDD1Dull};
  if (rng.state == 0) rng.state = 1;
  return rng;
}

uint64_t test_rng_next(test_rng *rng) {
  uint64_t x = rng->state;
  x ^= x << 13;
  x ^= x >> 7;
  x ^= x << 17;
  rng->state = x;
  return x * 0x2545F4914F6CDD1Dull;
}

double test_rng_uniform(test_rng *rng, double lo, double hi) {
  double u = (double)(test_rng_next(rng) >> 11) * 0x1.0p-53;
  return lo + (hi - lo) * u;
}

double test_rng_normal(test_rng *rng) {
  double u1 = test_rng_uniform(rng, 1e-300, 1.0), u2 = test_rng_uniform(rng, 0.0, 1.0);
  return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

int test_make_scratch_folder(char *dir, size_t size, const char *prefix) {
  snprintf(dir, size, "/tmp/%s_XXXXXX", prefix);
  return mkdtemp(dir) ? 0 : -1;
}

int test_remove_scratch_folder(const char *dir) {
  char cmd[512];
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
  return system(cmd) == 0 ? 0 : -1;
}

const char *test_data_path(const char *relative) {
  static char path[4096];
  snprintf(path, sizeof path, "%s/%s", PIOLA_DATA_DIR, relative);
  return path;
}

char *test_read_text(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) fail_msg("cannot open %s", path);
  fseek(f, 0, SEEK_END);
  long size = ftell(f);
  fseek(f, 0, SEEK_SET);
  char *text = malloc((size_t)size + 1);
  assert_non_null(text);
  assert_int_equal(fread(text, 1, (size_t)size, f), (size_t)size);
  text[size] = 0;
  fclose(f);
  return text;
}

void test_replace_first(char *text, const char *from, const char *to) {
  char *at = strstr(text, from);
  if (!at) fail_msg("'%s' not found in the text", from);
  size_t a = strlen(from), b = strlen(to);
  assert_true(b <= a);
  memcpy(at, to, b);
  memmove(at + b, at + a, strlen(at + a) + 1);
}

void test_symmetric_eigenvalues(double *a, int n, double *lambda) {
  for (int sweep = 0; sweep < 100; ++sweep) {
    double off = 0, diag = 0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        if (i == j)
          diag += a[n * i + j] * a[n * i + j];
        else
          off += a[n * i + j] * a[n * i + j];
      }
    if (!(off > 1e-30 * diag)) break;
    for (int p = 0; p < n; ++p)
      for (int q = p + 1; q < n; ++q) {
        if (a[n * p + q] == 0) continue;
        const double theta = (a[n * q + q] - a[n * p + p]) / (2 * a[n * p + q]);
        const double t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1));
        const double c = 1 / sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < n; ++k) { /* columns p and q */
          const double kp = a[n * k + p], kq = a[n * k + q];
          a[n * k + p] = c * kp - s * kq;
          a[n * k + q] = s * kp + c * kq;
        }
        for (int k = 0; k < n; ++k) { /* rows p and q */
          const double pk = a[n * p + k], qk = a[n * q + k];
          a[n * p + k] = c * pk - s * qk;
          a[n * q + k] = s * pk + c * qk;
        }
      }
  }
  for (int i = 0; i < n; ++i) lambda[i] = a[n * i + i];
}
