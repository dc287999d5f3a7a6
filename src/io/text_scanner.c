#include "io/text_scanner.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"

void piola__scanner_init(text_scanner *s, const char *name, const char *data, size_t size, char comment) {
  memset(s, 0, sizeof *s);
  s->name = name;
  s->begin = data;
  s->p = data;
  s->end = data + size;
  /* a UTF-8 byte order mark (editors on Windows write one) is not part of the text */
  if (size >= 3 && memcmp(data, "\xEF\xBB\xBF", 3) == 0) s->p += 3;
  s->line = 1;
  s->comment = comment;
}

piola_status piola__scan_error(const text_scanner *s, piola_status status, const char *format, ...) {
  char message[512];
  va_list args;
  va_start(args, format);
  vsnprintf(message, sizeof message, format, args);
  va_end(args);
  return PIOLA_FAIL(status, "%s:%ld: %s", s->name, s->line, message);
}

static int is_blank(const text_scanner *s, char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v' || (c == ',' && s->comma_is_space);
}

int piola__scan_skip(text_scanner *s) {
  const char *p = s->p, *end = s->end;
  while (p < end) {
    char c = *p;
    if (c == '\n') {
      ++s->line;
      ++p;
    } else if (is_blank(s, c) || c == '\0') {
      ++p;
    } else if (s->comment && c == s->comment) {
      while (p < end && *p != '\n') ++p;
    } else {
      break;
    }
  }
  s->p = p;
  return p < end;
}

int piola__scan_more_on_line(text_scanner *s) {
  const char *p = s->p, *end = s->end;
  while (p < end && (is_blank(s, *p) || *p == '\0')) ++p;
  if (p < end && s->comment && *p == s->comment)
    while (p < end && *p != '\n') ++p;
  s->p = p;
  return p < end && *p != '\n';
}

void piola__scan_next_line(text_scanner *s) {
  const char *nl = s->p < s->end ? memchr(s->p, '\n', (size_t)(s->end - s->p)) : NULL;
  if (nl) {
    s->p = nl + 1;
    ++s->line;
  } else {
    s->p = s->end;
  }
}

static int is_token_char(const text_scanner *s, char c) {
  return !(c == '\n' || is_blank(s, c) || c == '\0' || (s->comment && c == s->comment));
}

piola_status piola__scan_token(text_scanner *s, const char **token, size_t *length, const char *what) {
  if (!piola__scan_skip(s)) return piola__scan_error(s, PIOLA_ERROR_PARSE, "unexpected end of file, expected %s", what);
  const char *b = s->p;
  while (s->p < s->end && is_token_char(s, *s->p)) ++s->p;
  *token = b;
  *length = (size_t)(s->p - b);
  return PIOLA_OK;
}

int piola__scan_accept(text_scanner *s, const char *word, int ignore_case) {
  if (!piola__scan_skip(s)) return 0;
  size_t n = strlen(word);
  const char *b = s->p;
  size_t len = 0;
  while (b + len < s->end && is_token_char(s, b[len])) ++len;
  if (len != n) return 0;
  for (size_t i = 0; i < n; ++i) {
    char a = b[i], c = word[i];
    if (ignore_case) {
      if (a >= 'A' && a <= 'Z') a = (char)(a - 'A' + 'a');
      if (c >= 'A' && c <= 'Z') c = (char)(c - 'A' + 'a');
    }
    if (a != c) return 0;
  }
  s->p = b + n;
  return 1;
}

/* The token at the scanner, its first TOKEN_TEXT - 1 bytes as they are: piola_fail writes
 * control bytes and bytes that are not UTF-8 as \xNN, as in every quote of file content. */
enum { TOKEN_TEXT = 41 };
static void describe_token(const text_scanner *s, char out[TOKEN_TEXT]) {
  size_t len = 0;
  while (s->p + len < s->end && len + 1 < TOKEN_TEXT && is_token_char(s, s->p[len])) ++len;
  memcpy(out, s->p, len);
  out[len] = '\0';
}

piola_status piola__scan_int64_full(text_scanner *s, int64_t *value, const char *what) {
  if (!piola__scan_skip(s)) return piola__scan_error(s, PIOLA_ERROR_PARSE, "unexpected end of file, expected %s", what);
  const char *p = s->p, *end = s->end;
  int negative = 0;
  if (*p == '-' || *p == '+') {
    negative = *p == '-';
    ++p;
  }
  uint64_t v = 0;
  const char *digits = p;
  while (p < end && *p >= '0' && *p <= '9') {
    if (v > (uint64_t)INT64_MAX / 10) goto bad;
    v = v * 10 + (uint64_t)(*p - '0');
    if (v > (uint64_t)INT64_MAX) goto bad;
    ++p;
  }
  if (p == digits || (p < end && is_token_char(s, *p))) goto bad;
  *value = negative ? -(int64_t)v : (int64_t)v;
  s->p = p;
  return PIOLA_OK;
bad:;
  char tok[TOKEN_TEXT];
  describe_token(s, tok);
  return piola__scan_error(s, PIOLA_ERROR_PARSE, "expected %s (an integer), got '%s'", what, tok);
}

piola_status piola__scan_int32(text_scanner *s, int32_t *value, const char *what) {
  int64_t v;
  PIOLA_TRY(piola__scan_int64(s, &v, what));
  if (v < INT32_MIN || v > INT32_MAX) return piola__scan_error(s, PIOLA_ERROR_PARSE, "%s %lld is out of range", what, (long long)v);
  *value = (int32_t)v;
  return PIOLA_OK;
}

static const double exact_powers[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                        1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

static size_t parse_slow(const char *p, const char *end, double *value) {
  char buf[128];
  size_t n = 0;
  while (p + n < end && n + 1 < sizeof buf) {
    char c = p[n];
    if (!((c >= '0' && c <= '9') || c == '.' || c == '-' || c == '+' || c == 'e' || c == 'E' ||
          (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z')))
      break;
    buf[n] = c;
    ++n;
  }
  buf[n] = '\0';
  char *stop = NULL;
  double v = strtod(buf, &stop);
  if (stop == buf) return 0;
  *value = v;
  return (size_t)(stop - buf);
}

size_t piola__parse_double(const char *p, const char *end, double *value) {
  return piola__parse_double_checked(p, end, value, NULL);
}

size_t piola__parse_double_checked(const char *p, const char *end, double *value, int *exact) {
  const char *b = p;
  if (exact) *exact = 0;
  int negative = 0;
  if (p < end && (*p == '-' || *p == '+')) {
    negative = *p == '-';
    ++p;
  }
  uint64_t mantissa = 0;
  int digits = 0, exponent = 0, any = 0;
  while (p < end && *p == '0') { /* leading zeros are not significant */
    ++p;
    any = 1;
  }
  while (p < end && *p >= '0' && *p <= '9') {
    if (digits < 19) {
      mantissa = mantissa * 10 + (uint64_t)(*p - '0');
      ++digits;
    } else {
      return parse_slow(b, end, value);
    }
    ++p;
    any = 1;
  }
  if (p < end && *p == '.') {
    ++p;
    if (mantissa == 0)
      while (p < end && *p == '0') {
        ++p;
        --exponent;
        any = 1;
      }
    while (p < end && *p >= '0' && *p <= '9') {
      if (digits < 19) {
        mantissa = mantissa * 10 + (uint64_t)(*p - '0');
        ++digits;
        --exponent;
      } else {
        return parse_slow(b, end, value);
      }
      ++p;
      any = 1;
    }
  }
  if (!any) return parse_slow(b, end, value); /* inf, nan, or not a number */
  if (p < end && (*p == 'e' || *p == 'E')) {
    const char *q = p + 1;
    int eneg = 0;
    if (q < end && (*q == '-' || *q == '+')) {
      eneg = *q == '-';
      ++q;
    }
    if (q < end && *q >= '0' && *q <= '9') {
      int e = 0;
      while (q < end && *q >= '0' && *q <= '9') {
        if (e < 100000) e = e * 10 + (*q - '0');
        ++q;
      }
      exponent += eneg ? -e : e;
      p = q;
    }
  }
  double v;
  if (mantissa == 0) {
    v = 0.0;
    if (exact) *exact = 1;
  } else if (mantissa <= (UINT64_C(1) << 53) && exponent >= -22 && exponent <= 22) {
    /* Both operands exact: one correctly rounded operation. */
    v = (double)mantissa;
    v = exponent < 0 ? v / exact_powers[-exponent] : v * exact_powers[exponent];
    if (exact) *exact = 1;
  } else if (exponent >= -27 && exponent <= 27 && sizeof(long double) > sizeof(double)) {
    /* 64-bit mantissas and 10^27 are exact in x87 extended precision; one extended
     * rounding then one to double: within one ulp. */
    static const long double long_powers[28] = {
        1e0L,  1e1L,  1e2L,  1e3L,  1e4L,  1e5L,  1e6L,  1e7L,  1e8L,  1e9L,  1e10L, 1e11L, 1e12L, 1e13L,
        1e14L, 1e15L, 1e16L, 1e17L, 1e18L, 1e19L, 1e20L, 1e21L, 1e22L, 1e23L, 1e24L, 1e25L, 1e26L, 1e27L};
    long double m = (long double)mantissa;
    v = (double)(exponent < 0 ? m / long_powers[-exponent] : m * long_powers[exponent]);
  } else {
    return parse_slow(b, end, value);
  }
  *value = negative ? -v : v;
  return (size_t)(p - b);
}

piola_status piola__scan_double_full(text_scanner *s, double *value, const char *what) {
  if (!piola__scan_skip(s)) return piola__scan_error(s, PIOLA_ERROR_PARSE, "unexpected end of file, expected %s", what);
  size_t n = piola__parse_double(s->p, s->end, value);
  if (n == 0 || (s->p + n < s->end && is_token_char(s, s->p[n]))) {
    char tok[TOKEN_TEXT];
    describe_token(s, tok);
    return piola__scan_error(s, PIOLA_ERROR_PARSE, "expected %s (a number), got '%s'", what, tok);
  }
  if (!isfinite(*value)) return piola__scan_error(s, PIOLA_ERROR_PARSE, "%s is not finite", what);
  s->p += n;
  return PIOLA_OK;
}
