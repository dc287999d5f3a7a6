/* A scanner over a whole text file held in memory, used by every text mesh reader.
 *
 * Mesh files are big and simple: whitespace-separated integers and decimal numbers. Reading
 * the whole file into memory and scanning it by hand is several times faster than stdio and
 * strtod, and lets every reader work on a memory buffer (so fuzzers can call them directly).
 * The buffer need not be NUL-terminated; the scanner never reads past `end`.
 *
 * Numbers: integers are scanned exactly with overflow checks. Decimals take a fast path
 * (at most 19 significant digits and a small exponent: exact for mantissas below 2^53 and
 * powers of ten up to 1e22, otherwise one extended-precision operation, within one ulp of
 * the correctly rounded value) and fall back to strtod for everything else. Non-finite
 * values are refused. Errors name the file and the line. */
#ifndef PIOLA_IO_TEXT_SCANNER_H
#define PIOLA_IO_TEXT_SCANNER_H

#include <stddef.h>
#include <stdint.h>

#include "piola/status.h"

typedef struct text_scanner {
  const char *name;  /* file name for messages */
  const char *begin; /* start of the buffer */
  const char *p;     /* current position */
  const char *end;   /* one past the last byte */
  long line;         /* 1-based line of p */
  char comment;      /* comment character ('#'), or 0 */
  int comma_is_space; /* treat ',' as whitespace (Vega) */
} text_scanner;

void piola__scanner_init(text_scanner *s, const char *name, const char *data, size_t size, char comment);

/* Skips whitespace, newlines and comments. Returns 1 if a token follows, 0 at end of data. */
int piola__scan_skip(text_scanner *s);
/* Skips blanks (not newlines) and a trailing comment. Returns 1 if a token follows on the
 * same line, 0 at end of line or data. */
int piola__scan_more_on_line(text_scanner *s);
/* Moves to the start of the next line. */
void piola__scan_next_line(text_scanner *s);

/* The next token (after piola__scan_skip): pointer and length, up to whitespace. */
piola_status piola__scan_token(text_scanner *s, const char **token, size_t *length, const char *what);
/* 1 if the next token equals `word` (case-insensitive when ignore_case); consumes it then. */
int piola__scan_accept(text_scanner *s, const char *word, int ignore_case);

/* Out-of-line versions: comments, errors, unusual number forms. */
piola_status piola__scan_int64_full(text_scanner *s, int64_t *value, const char *what);
piola_status piola__scan_double_full(text_scanner *s, double *value, const char *what);
piola_status piola__scan_int32(text_scanner *s, int32_t *value, const char *what);

/* Inline fast paths for the common case (plain separators, plain numbers); anything else
 * goes to the _full versions, which handle it and report errors. */
static inline int piola__scan_fast_blank(const char *p, const text_scanner *s) {
  return p < s->end && (*p == ' ' || *p == '\n' || *p == '\t' || *p == '\r');
}

static inline piola_status piola__scan_int64(text_scanner *s, int64_t *value, const char *what) {
  const char *p = s->p, *end = s->end;
  long lines = 0;
  while (p < end && (*p == ' ' || *p == '\n' || *p == '\t')) lines += *p++ == '\n';
  const char *b = p;
  uint64_t v = 0;
  while (p < end && (unsigned)(*p - '0') < 10u && p - b < 18) v = v * 10 + (uint64_t)(*p++ - '0');
  if (p > b && (p == end || *p == ' ' || *p == '\n' || *p == '\t' || *p == '\r')) {
    s->p = p;
    s->line += lines;
    *value = (int64_t)v;
    return PIOLA_OK;
  }
  return piola__scan_int64_full(s, value, what);
}

size_t piola__parse_double(const char *p, const char *end, double *value);
/* The same, and *exact = 1 when the result is known to be correctly rounded (Clinger's
 * fast path or zero); 0 when it may be one ulp off or came from strtod. */
size_t piola__parse_double_checked(const char *p, const char *end, double *value, int *exact);

static inline piola_status piola__scan_double(text_scanner *s, double *value, const char *what) {
  const char *p = s->p, *end = s->end;
  long lines = 0;
  while (p < end && (*p == ' ' || *p == '\n' || *p == '\t')) lines += *p++ == '\n';
  if (p < end && ((unsigned)(*p - '0') < 10u || *p == '-' || *p == '.')) {
    double v;
    size_t n = piola__parse_double(p, end, &v);
    const char *q = p + n;
    if (n > 0 && (q == end || *q == ' ' || *q == '\n' || *q == '\t' || *q == '\r') && v - v == 0) {
      s->p = q;
      s->line += lines;
      *value = v;
      return PIOLA_OK;
    }
  }
  return piola__scan_double_full(s, value, what);
}

/* piola__parse_double (declared above): parses a decimal number from [p, end); returns the
 * number of bytes used, 0 if none. Non-finite results are returned as they are. */

/* Reports "file:line: message". */
piola_status piola__scan_error(const text_scanner *s, piola_status status, const char *format, ...)
#if defined(__GNUC__) || defined(__clang__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

#endif
