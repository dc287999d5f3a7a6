/* See checkpoint_files.h. */
#include "checkpoint_files.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "piola/elastic_body.h"
#include "piola/world.h"
#include "test_support.h"

unsigned char *checkpoint_file_read(const char *path, size_t *length) {
  FILE *f = fopen(path, "rb");
  assert_non_null(f);
  fseek(f, 0, SEEK_END);
  *length = (size_t)ftell(f);
  fseek(f, 0, SEEK_SET);
  unsigned char *data = malloc(*length);
  assert_non_null(data);
  assert_int_equal(fread(data, 1, *length, f), *length);
  fclose(f);
  return data;
}

uint64_t checkpoint_skip_array(const unsigned char *data, size_t *pos, size_t size) {
  uint64_t count;
  memcpy(&count, data + *pos, sizeof count);
  *pos += sizeof count + (size_t)count * size;
  return count;
}

void checkpoint_file_write(const char *path, unsigned char *data, size_t length, uint32_t version) {
  const uint64_t payload = length - CHECKPOINT_HEADER_BYTES;
  memcpy(data + 8, &version, 4);
  memcpy(data + 32, &payload, 8);
  uint64_t sum = 0xcbf29ce484222325ull;
  for (size_t i = 0; i < length; ++i) sum = (sum ^ data[i]) * 0x100000001b3ull;
  memcpy(data + length, &sum, 8);
  FILE *f = fopen(path, "wb");
  assert_non_null(f);
  assert_int_equal(fwrite(data, 1, length + 8, f), length + 8);
  fclose(f);
}

void checkpoint_same_solid_state(const piola_world *a, const piola_world *b) {
  const int32_t n = piola_elastic_body_vertex_count(piola_world_solid_body(a, 0));
  assert_int_equal(piola_elastic_body_vertex_count(piola_world_solid_body(b, 0)), n);
  assert_memory_equal(piola_world_solid_positions(a, 0), piola_world_solid_positions(b, 0),
                      3 * (size_t)n * sizeof(double));
  assert_memory_equal(piola_world_solid_velocities(a, 0), piola_world_solid_velocities(b, 0),
                      3 * (size_t)n * sizeof(double));
  assert_true(piola_world_time(a) == piola_world_time(b));
}

void checkpoint_temp_file(char *path, size_t size, const char *stem) {
  const char *tmp = getenv("TMPDIR");
  const int n = snprintf(path, size, "%s/%s_XXXXXX", tmp && *tmp ? tmp : "/tmp", stem);
  assert_true(n > 0 && (size_t)n < size);
  const int fd = mkstemp(path); /* the X's become the file's unique name */
  assert_true(fd >= 0);
  close(fd);
}
