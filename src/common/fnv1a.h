/* FNV-1a 64, the hash of checkpoint checksums and scene keys (file-formats.md,
 * "Checkpoints"): start from PIOLA_FNV_OFFSET and fold in bytes. */
#ifndef PIOLA_COMMON_FNV1A_H
#define PIOLA_COMMON_FNV1A_H

#include <stddef.h>
#include <stdint.h>

#define PIOLA_FNV_OFFSET 0xcbf29ce484222325ull

/* h with the n bytes at data folded in. */
static inline uint64_t piola__fnv1a(uint64_t h, const void *data, size_t n) {
  const unsigned char *p = data;
  for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 0x100000001b3ull;
  return h;
}

#endif
