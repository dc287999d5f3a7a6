/* Cleaning an output folder after a kill (see output/frame_commit.h for what one can leave).
 *
 * --force and --resume first remove stray temporaries: files piola names
 * "X.tmpXXXXXX" (io/atomic_file.c) and the pending data files of an uncommitted frame
 * ("frame_NNNN.pending.vtu"). --resume from frame C then drops every frame after C (its
 * data files and index rows, listed or not: the resumed run writes them again, identically)
 * and keeps stats.csv's rows up to C, which also give sim.pvd's entries (frame, time). */
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/status_report.h"
#include "output/output_internal.h"

static const char *const piola_names[] = {
    "frame_",      "stats.csv",  "sim.pvd",    "failure_report.txt", "warnings.txt",
    "checkpoint_", "scene.json", "preview.png"};

/* A temporary of a file piola writes: NAME.tmpXXXXXX (mkstemp's six characters), or a
 * frame's pending data file frame_NNNN.pending.EXT. */
static int is_stray(const char *name) {
  size_t n = strlen(name);
  int ours = 0;
  for (size_t i = 0; i < sizeof piola_names / sizeof *piola_names; ++i)
    if (strncmp(name, piola_names[i], strlen(piola_names[i])) == 0) ours = 1;
  if (!ours) return 0;
  if (n > 10 && strncmp(name + n - 10, ".tmp", 4) == 0) return 1;
  return strncmp(name, "frame_", 6) == 0 && strstr(name, ".pending.") != NULL;
}

/* The frame number of "frame_NNNN.EXT", or -1. */
static long frame_number(const char *name, const char *ext) {
  if (strncmp(name, "frame_", 6) != 0) return -1;
  char *end;
  long k = strtol(name + 6, &end, 10);
  if (end == name + 6 || strcmp(end, ext) != 0 || k < 0) return -1;
  return k;
}

long piola__frame_file_number(const char *name) {
  long k = frame_number(name, ".vtu");
  if (k < 0) k = frame_number(name, ".pvtu");
  if (k >= 0 || strncmp(name, "frame_", 6) != 0) return k;
  /* a split run's piece, frame_NNNN_pK.vtu */
  char *end;
  k = strtol(name + 6, &end, 10);
  if (end == name + 6 || k < 0 || strncmp(end, "_p", 2) != 0) return -1;
  const char *digits = end + 2;
  (void)strtol(digits, &end, 10);
  return end != digits && *digits >= '0' && *digits <= '9' && strcmp(end, ".vtu") == 0 ? k : -1;
}

/* Removes strays in folder, and with drop_after >= 0 the frames numbered above it. */
static void clean_folder(const char *folder, long drop_after, const char *ext) {
  DIR *d = opendir(folder);
  if (!d) return;
  char path[4200];
  for (struct dirent *e; (e = readdir(d));) {
    long k = !ext ? -1 : strcmp(ext, ".vtu") == 0 ? piola__frame_file_number(e->d_name)
                                                   : frame_number(e->d_name, ext);
    if (is_stray(e->d_name) || (drop_after >= 0 && k > drop_after)) {
      snprintf(path, sizeof path, "%s/%s", folder, e->d_name);
      unlink(path);
    }
  }
  closedir(d);
}

void piola__output_remove_strays(const char *dir, long drop_after) {
  char path[4200];
  clean_folder(dir, -1, NULL);
  snprintf(path, sizeof path, "%s/frames", dir);
  clean_folder(path, drop_after, ".vtu");
  snprintf(path, sizeof path, "%s/surface", dir);
  clean_folder(path, drop_after, ".obj");
}

piola_status piola__output_reconcile(const char *dir, int32_t last_frame, int32_t piece_count,
                                     char **rows, size_t *length) {
  *rows = NULL;
  *length = 0;
  char path[4200];
  struct stat st;
  for (int32_t k = 0; k <= last_frame; ++k) {
    snprintf(path, sizeof path, "%s/frames/frame_%04d.%s", dir, (int)k, piece_count > 0 ? "pvtu" : "vtu");
    int vtu = stat(path, &st) == 0 && S_ISREG(st.st_mode);
    for (int32_t p = 0; vtu && p < piece_count; ++p) {
      piola__piece_name(path, sizeof path, dir, k, p);
      vtu = stat(path, &st) == 0 && S_ISREG(st.st_mode);
    }
    snprintf(path, sizeof path, "%s/surface/frame_%04d.obj", dir, (int)k);
    if (!vtu || stat(path, &st) != 0 || !S_ISREG(st.st_mode))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "%s: frame %d of the checkpoint's run is missing (frames/ or surface/); "
                        "cannot resume, start over with --force (Python and C: force)",
                        dir, (int)k);
  }
  snprintf(path, sizeof path, "%s/stats.csv", dir);
  FILE *f = fopen(path, "rb");
  if (!f)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "%s: %s; cannot resume, start over with --force (Python and C: force)", path,
                      strerror(errno));
  size_t cap = 4096, len = 0;
  char *kept = malloc(cap), line[1024];
  if (!kept) {
    fclose(f);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
  }
  kept[0] = '\0';
  int32_t expect = 0;
  while (fgets(line, sizeof line, f)) {
    char *end;
    long k = strtol(line, &end, 10);
    if (end == line || *end != ',') continue; /* the header */
    if (k != expect) break;                   /* only an unbroken run of rows from frame 0 */
    if (k > last_frame) break;
    size_t n = strlen(line);
    if (n == 0 || line[n - 1] != '\n') break; /* a row too long to be ours */
    if (len + n + 1 > cap) {
      char *grown = realloc(kept, 2 * cap + n);
      if (!grown) {
        free(kept);
        fclose(f);
        return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", path);
      }
      kept = grown;
      cap = 2 * cap + n;
    }
    memcpy(kept + len, line, n + 1);
    len += n;
    expect++;
  }
  fclose(f);
  if (expect != last_frame + 1) {
    free(kept);
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "%s lists frames 0..%d, the checkpoint is at frame %d; cannot resume, start "
                      "over with --force (Python and C: force)",
                      path, (int)expect - 1, (int)last_frame);
  }
  piola__output_remove_strays(dir, last_frame);
  *rows = kept;
  *length = len;
  return PIOLA_OK;
}
