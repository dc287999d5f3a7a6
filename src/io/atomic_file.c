#include "piola/files.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/fault_injection.h"
#include "common/status_report.h"
#include "io/atomic_file_internal.h"

piola_status piola_atomic_file_open(piola_atomic_file *file, const char *path) {
  memset(file, 0, sizeof *file);
  size_t n = strlen(path);
  if (n == 0 || n + 16 >= sizeof file->target)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "output path is empty or too long: '%s'", path);
  memcpy(file->target, path, n + 1);
  snprintf(file->temporary, sizeof file->temporary, "%s.tmpXXXXXX", path);
  int fd = mkstemp(file->temporary);
  if (fd < 0)
    return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: cannot create a temporary file: %s", path, strerror(errno));
  /* mkstemp creates the file 0600; give the result the usual permissions (0666 less the
   * umask) as a plain fopen would. Reading the umask means setting it; restore at once. */
  mode_t mask = umask(0);
  umask(mask);
  fchmod(fd, 0666 & ~mask);
  file->stream = fdopen(fd, "wb");
  if (!file->stream) {
    close(fd);
    unlink(file->temporary);
    return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: cannot open for writing: %s", path, strerror(errno));
  }
  return PIOLA_OK;
}

piola_status piola__atomic_file_finish(piola_atomic_file *file) {
  piola__fault_during_write(file->stream);
  int failed = ferror(file->stream) || fflush(file->stream) != 0;
  int err = errno;
  if (!failed && piola__fault_write_fails()) failed = 1, err = ENOSPC;
  if (fclose(file->stream) != 0 && !failed) {
    failed = 1;
    err = errno;
  }
  file->stream = NULL;
  if (failed) {
    unlink(file->temporary);
    return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: write failed: %s", file->target, strerror(err));
  }
  return PIOLA_OK;
}

piola_status piola_atomic_file_commit(piola_atomic_file *file) {
  PIOLA_TRY(piola__atomic_file_finish(file));
  piola__fault_before_rename();
  if (rename(file->temporary, file->target) != 0) {
    int err = errno;
    unlink(file->temporary);
    return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: cannot move into place: %s", file->target, strerror(err));
  }
  return PIOLA_OK;
}

void piola_atomic_file_abort(piola_atomic_file *file) {
  if (file->stream) fclose(file->stream);
  file->stream = NULL;
  if (file->temporary[0]) unlink(file->temporary);
}
