#include "cli/run_checkpoints.h"

#include <dirent.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli/run_split_checkpoints.h"
#include "piola/checkpoint.h"
#include "piola/scene.h"

int run_scene_key(const char *scene_path, const piola_world *world, uint64_t *key) {
  /* the scene was just loaded from this path, so it is a regular file of a sane size */
  int fd = open(scene_path, O_RDONLY | O_NONBLOCK);
  struct stat st;
  if (fd < 0 || fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size > (1 << 28)) {
    if (fd >= 0) close(fd);
    fprintf(stderr, "piola run: %s: cannot read the scene again for its checkpoint key\n",
            scene_path);
    return 0;
  }
  size_t n = (size_t)st.st_size, got = 0;
  char *bytes = malloc(n ? n : 1);
  while (bytes && got < n) {
    ssize_t r = read(fd, bytes + got, n - got);
    if (r <= 0) break;
    got += (size_t)r;
  }
  close(fd);
  if (!bytes || got != n) {
    free(bytes);
    fprintf(stderr, "piola run: %s: cannot read the scene again for its checkpoint key\n",
            scene_path);
    return 0;
  }
  /* the files the scene names, appended to its bytes: a mesh obstacle or a plastic goal
   * edited between a kill and --resume would otherwise go on from the old frames */
  uint64_t inputs = 0;
  char *all = bytes ? realloc(bytes, n + sizeof inputs) : NULL;
  if (!all || piola_scene_inputs_key(scene_path, &inputs) != PIOLA_OK) {
    free(all ? all : bytes);
    fprintf(stderr, "piola run: %s: cannot read the files the scene names for its checkpoint key\n",
            scene_path);
    return 0;
  }
  memcpy(all + n, &inputs, sizeof inputs);
  *key = piola_world_scene_key(world, all, n + sizeof inputs);
  free(all);
  return 1;
}

static int32_t *list_checkpoints(const char *dir, int *count) {
  return run_checkpoint_list(dir, ".bin", count);
}

int32_t *run_checkpoint_list(const char *dir, const char *suffix, int *count) {
  *count = 0;
  DIR *d = opendir(dir);
  if (!d) return NULL;
  int cap = 16;
  int32_t *frames = malloc((size_t)cap * sizeof *frames);
  for (struct dirent *e; frames && (e = readdir(d));) {
    char *end;
    if (strncmp(e->d_name, "checkpoint_", 11) != 0) continue;
    long k = strtol(e->d_name + 11, &end, 10);
    if (end == e->d_name + 11 || strcmp(end, suffix) != 0 || k < 0 || k > 100000000) continue;
    if (*count == cap) {
      int32_t *grown = realloc(frames, 2 * (size_t)cap * sizeof *frames);
      if (!grown) break;
      frames = grown;
      cap *= 2;
    }
    frames[(*count)++] = (int32_t)k;
  }
  closedir(d);
  for (int i = 1; i < *count; ++i) /* insertion sort, descending: a handful of files */
    for (int j = i; j > 0 && frames[j] > frames[j - 1]; --j) {
      int32_t t = frames[j];
      frames[j] = frames[j - 1];
      frames[j - 1] = t;
    }
  return frames;
}

int run_checkpoint_resume(const char *dir, piola_world *world, uint64_t key, int32_t *frame) {
  int count;
  int32_t *frames = list_checkpoints(dir, &count);
  if (count == 0) {
    free(frames);
    const int processes = run_split_checkpoint_processes(dir);
    if (processes == 0) return 1;
    char n[32];
    snprintf(n, sizeof n, processes > 0 ? "%d" : "N", processes);
    fprintf(stderr, "piola run: cannot resume: %s holds the checkpoints of a run on %s MPI "
                    "processes (checkpoint_NNNN.manifest); resume it with mpirun -np %s, or use "
                    "--force to start over (docs/mpi.md)\n", dir, n, n);
    return 2;
  }
  int rc = 2;
  for (int i = 0; i < count; ++i) {
    char path[4200];
    snprintf(path, sizeof path, "%s/checkpoint_%04d.bin", dir, (int)frames[i]);
    piola_status st = piola_world_checkpoint_read(world, path, key, frame);
    /* one holding another frame than its name says is damaged: resuming from it would
     * rewrite the frames after the one it holds */
    if (st == PIOLA_OK && *frame != frames[i])
      st = piola_fail(PIOLA_ERROR_PARSE, "%s holds frame %d, not the frame %d its name says", path,
                      (int)*frame, (int)frames[i]);
    if (st == PIOLA_OK) {
      rc = 0;
      break;
    }
    if (st == PIOLA_ERROR_UNSUPPORTED) { /* another scene or version: never silently older */
      fprintf(stderr, "piola run: cannot resume: %s; use --force to start over\n",
              piola_last_error());
      break;
    }
    fprintf(stderr, "piola run: skipping a damaged checkpoint: %s\n", piola_last_error());
    if (i == count - 1)
      fprintf(stderr,
              "piola run: cannot resume: no intact checkpoint in %s; use --force to start over\n",
              dir);
  }
  free(frames);
  return rc;
}

int run_checkpoint_save(const char *dir, const piola_world *world, uint64_t key, int32_t frame) {
  char path[4200];
  snprintf(path, sizeof path, "%s/checkpoint_%04d.bin", dir, (int)frame);
  if (piola_world_checkpoint_write(world, path, key, frame) != PIOLA_OK) {
    fprintf(stderr, "piola run: checkpoint: %s\n", piola_last_error());
    return 0;
  }
  int count;
  int32_t *frames = list_checkpoints(dir, &count);
  for (int i = 2; i < count; ++i) { /* keep the newest two: one may be the damaged one */
    snprintf(path, sizeof path, "%s/checkpoint_%04d.bin", dir, (int)frames[i]);
    unlink(path);
  }
  free(frames);
  return 1;
}

int run_listed_frames(const char *dir) {
  char path[4200], line[1024];
  snprintf(path, sizeof path, "%s/stats.csv", dir);
  FILE *f = fopen(path, "rb");
  if (!f) return 0;
  int rows = 0;
  while (fgets(line, sizeof line, f))
    if (line[0] >= '0' && line[0] <= '9') rows++;
  fclose(f);
  return rows;
}
