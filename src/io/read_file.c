/* Whole input files (piola/files.h): one reader for every format and layer. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "common/input_path.h"
#include "common/status_report.h"
#include "piola/files.h"

piola_status piola_read_file(const char *path, size_t max_size, char **data, size_t *size) {
  *data = NULL;
  *size = 0;
  FILE *f;
  PIOLA_TRY(piola__open_input(path, &f)); /* a regular file, or refused before opening */
  struct stat st;
  if (fstat(fileno(f), &st) != 0) {
    fclose(f);
    return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: cannot read: %s", path, strerror(errno));
  }
  size_t n = (size_t)st.st_size;
  if (max_size > 0 && n > max_size) {
    fclose(f);
    return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: larger than %zu bytes (%zu), the limit for this file",
                      path, max_size, n);
  }
  char *buf = malloc(n + 1);
  if (!buf) {
    fclose(f);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: cannot allocate %zu bytes", path, n);
  }
  size_t got = n ? fread(buf, 1, n, f) : 0;
  int err = ferror(f);
  fclose(f);
  if (got != n || err) {
    free(buf);
    return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: read error", path);
  }
  buf[n] = '\0';
  *data = buf;
  *size = n;
  return PIOLA_OK;
}
