/* Buffered text output for the ASCII mesh writers.
 *
 * Mesh files are millions of small integers; printf parses its format string for each one,
 * which made writing several times slower than reading. This writer formats integers by hand
 * into a 64 KiB buffer and hands full buffers to the (piola_atomic_file) stream. Doubles go through
 * piola__format_double, which guarantees an exact round trip. */
#ifndef PIOLA_IO_TEXT_WRITER_H
#define PIOLA_IO_TEXT_WRITER_H

#include <stdint.h>
#include <stdio.h>

typedef struct text_writer {
  FILE *stream;
  size_t used;
  char buffer[1 << 16];
} text_writer;

void piola__tw_init(text_writer *w, FILE *stream);
void piola__tw_flush(text_writer *w);
void piola__tw_str(text_writer *w, const char *s);
void piola__tw_char(text_writer *w, char c);
void piola__tw_int(text_writer *w, int64_t v);
void piola__tw_double(text_writer *w, double v);

#endif
