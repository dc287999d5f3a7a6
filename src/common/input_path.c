#include "common/input_path.h"

#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/status_report.h"

static const char *kind(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a named pipe";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a plain file";
}

piola_status piola__open_input(const char *path, FILE **out) {
  *out = NULL;
  if (!path || !path[0]) return PIOLA_FAIL(PIOLA_ERROR_IO, "empty file path");
  struct stat st;
  if (stat(path, &st) != 0)
    return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: cannot open: %s", path, strerror(errno));
  if (!S_ISREG(st.st_mode))
    return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: not a regular file (%s)", path, kind(st.st_mode));
  int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: cannot open: %s", path, strerror(errno));
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    close(fd);
    return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: not a regular file (%s)", path, kind(st.st_mode));
  }
  int flags = fcntl(fd, F_GETFL);
  if (flags != -1) fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
  FILE *f = fdopen(fd, "rb");
  if (!f) {
    int err = errno;
    close(fd);
    return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: cannot open: %s", path, strerror(err));
  }
  *out = f;
  return PIOLA_OK;
}
