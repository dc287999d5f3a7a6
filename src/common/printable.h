/* Printable text for messages (printable.c): error messages quote file content (a token, a
 * name, a path from a scene), and a crafted file must not reach the user's terminal with
 * escape sequences. */
#ifndef PIOLA_COMMON_PRINTABLE_H
#define PIOLA_COMMON_PRINTABLE_H

#include <stddef.h>

/* Copies src to dst (size bytes, always terminated, truncated to fit) with every control
 * byte (below 0x20, 0x7f), every C1 control (U+0080..U+009F) and every byte that is not
 * part of valid UTF-8 written as \xNN; other UTF-8 is kept. */
void piola__printable(char *dst, size_t size, const char *src);

#endif
