/* The output folder policy: never write into a folder that holds anything unless forced,
 * and when forced remove only the files an earlier run of piola wrote. */
#include "output/output_internal.h"

#include <dirent.h>
#include <stdlib.h>
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/status_report.h"

/* Whether files can be created in folder: creates and removes a probe (permission bits
 * alone do not say, e.g. for root or on a read-only or special file system). */
static piola_status probe_writable(const char *folder, const char *dir) {
  char probe[4200];
  snprintf(probe, sizeof probe, "%s/.piola-probe-XXXXXX", folder);
  int fd = mkstemp(probe);
  if (fd < 0)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "output folder %s: cannot write in %s: %s", dir,
                      folder, strerror(errno));
  close(fd);
  unlink(probe);
  return PIOLA_OK;
}

/* A missing dir must be creatable: its nearest existing ancestor is a writable folder. */
static piola_status check_creatable(const char *dir) {
  char parent[4096];
  int n = snprintf(parent, sizeof parent, "%s", dir);
  if (n < 0 || n >= (int)sizeof parent)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "output folder: path too long");
  for (;;) {
    char *slash = strrchr(parent, '/');
    while (slash && slash > parent && slash[1] == '\0') { /* trailing slashes */
      *slash = '\0';
      slash = strrchr(parent, '/');
    }
    if (!slash) snprintf(parent, sizeof parent, ".");
    else if (slash == parent) parent[1] = '\0';
    else *slash = '\0';
    struct stat st;
    if (stat(parent, &st) == 0) {
      if (!S_ISDIR(st.st_mode))
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "output folder %s: %s is not a folder", dir, parent);
      return probe_writable(parent, dir);
    }
    if (errno != ENOENT)
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "output folder %s: %s: %s", dir, parent, strerror(errno));
    if (strcmp(parent, ".") == 0 || strcmp(parent, "/") == 0)
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "output folder %s: no existing parent", dir);
  }
}

piola_status piola_output_check_folder(const char *dir, bool force) {
  if (!dir || !dir[0]) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "output folder: empty path");
  struct stat st;
  if (stat(dir, &st) != 0) {
    if (errno == ENOENT) return check_creatable(dir);
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "%s: %s", dir, strerror(errno));
  }
  if (!S_ISDIR(st.st_mode))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "%s exists and is not a folder", dir);
  PIOLA_TRY(probe_writable(dir, dir));
  if (force) return PIOLA_OK;
  DIR *d = opendir(dir);
  if (!d) return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: %s", dir, strerror(errno));
  int empty = 1;
  for (struct dirent *e; (e = readdir(d));)
    if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0) empty = 0;
  closedir(d);
  if (!empty)
    return PIOLA_FAIL(
        PIOLA_ERROR_INVALID_ARGUMENT,
        "%s is not empty (it may hold results of an earlier run); "
        "use --force (Python: force=True; C: piola_output_check_folder's force) to write "
        "into it",
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

/* A split run's per-process checkpoints, checkpoint_NNNN_pK.bin. */
static void remove_split_checkpoints(const char *dir) {
  DIR *d = opendir(dir);
  if (!d) return;
  char path[8192];
  for (struct dirent *e; (e = readdir(d));) {
    const char *name = e->d_name;
    if (strncmp(name, "checkpoint_", 11) != 0) continue;
    char *end;
    (void)strtol(name + 11, &end, 10);
    if (end == name + 11 || name[11] < '0' || name[11] > '9' || strncmp(end, "_p", 2) != 0) continue;
    const char *digits = end + 2;
    (void)strtol(digits, &end, 10);
    if (end == digits || *digits < '0' || *digits > '9' || strcmp(end, ".bin") != 0) continue;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    unlink(path);
  }
  closedir(d);
}

/* Every frame file of a frames folder: VTUs, and a split run's .pvtu files and pieces. */
static void remove_frames(const char *folder) {
  DIR *d = opendir(folder);
  if (!d) return;
  char path[8192];
  for (struct dirent *e; (e = readdir(d));)
    if (piola__frame_file_number(e->d_name) >= 0) {
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
  if (force) remove_frames(path);
  snprintf(path, sizeof path, "%s/surface", dir);
  PIOLA_TRY(make_folder(path));
  if (force) {
    remove_matching(path, "frame_", ".obj");
    remove_matching(dir, "checkpoint_", ".bin");
    remove_matching(dir, "checkpoint_", ".manifest"); /* a split run's (docs/mpi.md) */
    remove_split_checkpoints(dir);
    piola__output_remove_strays(dir, -1);
    static const char *const files[] = {"stats.csv", "sim.pvd", "failure_report.txt", "warnings.txt"};
    for (int i = 0; i < 4; ++i) {
      snprintf(path, sizeof path, "%s/%s", dir, files[i]);
      unlink(path);
    }
  }
  return PIOLA_OK;
}
