/* The output folder policy: never write into a folder that holds anything unless forced,
 * and when forced remove only the files an earlier run of piola wrote. */
#include "output/output_internal.h"

#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/status_report.h"

piola_status piola_output_check_folder(const char *dir, bool force) {
  if (!dir || !dir[0]) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "output folder: empty path");
  struct stat st;
  if (stat(dir, &st) != 0) {
    if (errno == ENOENT) return PIOLA_OK;
    return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: %s", dir, strerror(errno));
  }
  if (!S_ISDIR(st.st_mode))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "%s exists and is not a folder", dir);
  if (force) return PIOLA_OK;
  DIR *d = opendir(dir);
  if (!d) return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: %s", dir, strerror(errno));
  int empty = 1;
  for (struct dirent *e; (e = readdir(d));)
    if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0) empty = 0;
  closedir(d);
  if (!empty)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "%s is not empty (it may hold results of an earlier run); "
                      "use --force to write into it",
                      dir);
  return PIOLA_OK;
}

static piola_status make_folder(const char *path) {
  if (mkdir(path, 0777) == 0 || errno == EEXIST) {
    struct stat st;
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) return PIOLA_OK;
    return PIOLA_FAIL(PIOLA_ERROR_IO, "%s exists and is not a folder", path);
  }
  return PIOLA_FAIL(PIOLA_ERROR_IO, "cannot create folder %s: %s", path, strerror(errno));
}

/* Creates every missing folder on the way to path (like mkdir -p). */
static piola_status make_folders(const char *path) {
  char buf[4096];
  int n = snprintf(buf, sizeof buf, "%s", path);
  if (n < 0 || n >= (int)sizeof buf) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "path too long");
  for (char *c = buf + 1; *c; ++c)
    if (*c == '/') {
      *c = '\0';
      struct stat st;
      if (stat(buf, &st) != 0) PIOLA_TRY(make_folder(buf));
      *c = '/';
    }
  return make_folder(buf);
}

static int matches(const char *name, const char *prefix, const char *suffix) {
  size_t n = strlen(name), p = strlen(prefix), s = strlen(suffix);
  if (n < p + s || strncmp(name, prefix, p) != 0 || strcmp(name + n - s, suffix) != 0) return 0;
  for (size_t i = p; i < n - s; ++i)
    if (name[i] < '0' || name[i] > '9') return 0;
  return 1;
}

static void remove_matching(const char *folder, const char *prefix, const char *suffix) {
  DIR *d = opendir(folder);
  if (!d) return;
  char path[4096];
  for (struct dirent *e; (e = readdir(d));)
    if (matches(e->d_name, prefix, suffix)) {
      snprintf(path, sizeof path, "%s/%s", folder, e->d_name);
      unlink(path);
    }
  closedir(d);
}

piola_status piola__output_prepare_folder(const char *dir, bool force) {
  PIOLA_TRY(piola_output_check_folder(dir, force));
  char path[4096];
  PIOLA_TRY(make_folders(dir));
  snprintf(path, sizeof path, "%s/frames", dir);
  PIOLA_TRY(make_folder(path));
  if (force) remove_matching(path, "frame_", ".vtu");
  snprintf(path, sizeof path, "%s/surface", dir);
  PIOLA_TRY(make_folder(path));
  if (force) {
    remove_matching(path, "frame_", ".obj");
    static const char *const files[] = {"stats.csv", "sim.pvd", "failure_report.txt"};
    for (int i = 0; i < 3; ++i) {
      snprintf(path, sizeof path, "%s/%s", dir, files[i]);
      unlink(path);
    }
  }
  return PIOLA_OK;
}
