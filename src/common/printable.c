#include "common/printable.h"

#include <stdio.h>

/* Length of the valid UTF-8 sequence at s that encodes a printable code point (2 to 4
 * bytes), or 0. Overlong forms, surrogates and C1 controls are not printable. */
static int printable_utf8(const unsigned char *s) {
  unsigned c = s[0];
  int n = c >= 0xc2 && c <= 0xdf ? 2 : c >= 0xe0 && c <= 0xef ? 3 : c >= 0xf0 && c <= 0xf4 ? 4 : 0;
  if (!n) return 0;
  unsigned cp = c & (0x7f >> n);
  for (int i = 1; i < n; ++i) {
    if ((s[i] & 0xc0) != 0x80) return 0;
    cp = (cp << 6) | (s[i] & 0x3f);
  }
  if ((n == 3 && cp < 0x800) || (n == 4 && (cp < 0x10000 || cp > 0x10ffff))) return 0;
  if ((cp >= 0xd800 && cp <= 0xdfff) || (cp >= 0x80 && cp <= 0x9f)) return 0;
  return n;
}

void piola__printable(char *dst, size_t size, const char *src) {
  if (!size) return;
  size_t o = 0;
  const unsigned char *s = (const unsigned char *)src;
  while (*s) {
    int n = *s >= 0x80 ? printable_utf8(s) : (*s >= 0x20 && *s != 0x7f);
    if (n > 0) {
      if (o + (size_t)n >= size) break;
      for (int i = 0; i < n; ++i) dst[o++] = (char)s[i];
      s += n;
    } else {
      if (o + 4 >= size) break;
      snprintf(dst + o, 5, "\\x%02x", *s);
      o += 4;
      s++;
    }
  }
  dst[o] = '\0';
}
