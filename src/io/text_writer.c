#include "io/text_writer.h"

#include <string.h>

#include "io/mesh_writers.h"

void piola__tw_init(text_writer *w, FILE *stream) {
  w->stream = stream;
  w->used = 0;
}

void piola__tw_flush(text_writer *w) {
  if (w->used) fwrite(w->buffer, 1, w->used, w->stream);
  w->used = 0;
}

static void reserve(text_writer *w, size_t n) {
  if (w->used + n > sizeof w->buffer) piola__tw_flush(w);
}

void piola__tw_str(text_writer *w, const char *s) {
  size_t n = strlen(s);
  if (n > sizeof w->buffer / 2) {
    piola__tw_flush(w);
    fwrite(s, 1, n, w->stream);
    return;
  }
  reserve(w, n);
  memcpy(w->buffer + w->used, s, n);
  w->used += n;
}

void piola__tw_char(text_writer *w, char c) {
  reserve(w, 1);
  w->buffer[w->used++] = c;
}

void piola__tw_int(text_writer *w, int64_t v) {
  reserve(w, 24);
  char digits[24];
  int n = 0;
  uint64_t u = v < 0 ? (uint64_t)0 - (uint64_t)v : (uint64_t)v;
  do {
    digits[n++] = (char)('0' + u % 10);
    u /= 10;
  } while (u);
  if (v < 0) w->buffer[w->used++] = '-';
  while (n) w->buffer[w->used++] = digits[--n];
}

void piola__tw_double(text_writer *w, double v) {
  reserve(w, 32);
  w->used += (size_t)piola__format_double(w->buffer + w->used, v);
}
