/* Checkpoint files taken apart and put back together by tests that rewrite one as an older
 * format wrote it (docs/file-formats.md: a 48-byte header, the payload as arrays of a u64
 * count and its elements, an FNV-1a 64 checksum of everything before it), and the check that
 * a world read from one runs on like its writer. */
#ifndef PIOLA_TEST_CHECKPOINT_FILES_H
#define PIOLA_TEST_CHECKPOINT_FILES_H

#include <stddef.h>
#include <stdint.h>

enum { CHECKPOINT_HEADER_BYTES = 48 };

/* The whole file at path (malloc'ed; *length its size, checksum included). Fails the test
 * when it cannot be read. */
unsigned char *checkpoint_file_read(const char *path, size_t *length);

/* Skips one array of the payload at *pos (u64 count, count elements of size bytes); returns
 * the count. */
uint64_t checkpoint_skip_array(const unsigned char *data, size_t *pos, size_t size);

/* Writes data (length bytes, header and payload, no checksum; at least 8 more bytes of room
 * for it) to path as format `version`: the header's version and payload length set, the
 * checksum appended. Fails the test when it cannot be written. */
void checkpoint_file_write(const char *path, unsigned char *data, size_t length, uint32_t version);

/* Makes a fresh empty file of the caller's own in the temporary folder ($TMPDIR, else /tmp),
 * its name STEM followed by a unique suffix, and writes its path to PATH (SIZE bytes); the
 * caller unlinks it. Fails the test when it cannot. */
void checkpoint_temp_file(char *path, size_t size, const char *stem);

struct piola_world;
/* Solid 0 of a and b has the same positions and velocities, bit for bit, at the same time. */
void checkpoint_same_solid_state(const struct piola_world *a, const struct piola_world *b);

#endif
