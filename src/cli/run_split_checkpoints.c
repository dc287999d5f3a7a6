/* Checkpoints of a split run (run_split_checkpoints.h, docs/mpi.md "Checkpoints").
 *
 * Each process writes its own file, DIR/checkpoint_NNNN_pK.bin: the checkpoint format of
 * piola/checkpoint.h with the per-tet state of the blocks that process holds (header word
 * 44 names the process and the process count). When every process's file is in place,
 * process 0 writes DIR/checkpoint_NNNN.manifest, the commit point of the set: the frame,
 * the process count, the scene key and each solid's partition (the process of each block
 * of PIOLA_WORK_SPLIT_BLOCK tets, as runs "process*blocks"). A resume takes the newest
 * manifest whose process count, scene and partition are this run's and whose files every
 * process reads intact; in a scene with fracture the partition is the cut mesh's, made
 * again and compared once every process has read its file. */
#include "cli/run_split_checkpoints.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/run_checkpoints.h"
#include "piola/checkpoint.h"
#include "piola/files.h"
#include "piola/work_split.h"
#include "piola/world_fracture.h"

static void manifest_path(char *out, size_t size, const char *dir, int32_t frame) {
  snprintf(out, size, "%s/checkpoint_%04d.manifest", dir, (int)frame);
}

static void part_path(char *out, size_t size, const char *dir, int32_t frame, int process) {
  snprintf(out, size, "%s/checkpoint_%04d_p%d.bin", dir, (int)frame, process);
}

/* The manifest of this run's checkpoint at frame (malloc'ed text, NULL when out of memory). */
static char *manifest_text(const piola_world *world, uint64_t key, int32_t frame, int processes) {
  char *text = NULL;
  size_t length = 0;
  FILE *f = open_memstream(&text, &length);
  if (!f) return NULL;
  const int32_t solids = piola_world_solid_count(world);
  fprintf(f, "piola split checkpoint 1\nframe %d\nprocesses %d\nscene_key %016llx\nsolids %d\n",
          (int)frame, processes, (unsigned long long)key, (int)solids);
  for (int32_t s = 0; s < solids; ++s) {
    const piola_elastic_body *b = piola_world_solid_body(world, s);
    const piola_work_split *split = piola_elastic_body_work_split(b);
    const int32_t blocks = piola_elastic_body_block_count(b);
    fprintf(f, "solid %d blocks %d partition", (int)s, (int)blocks);
    for (int32_t k = 0; k < blocks;) {
      const int32_t part = split ? split->block_part[k] : 0;
      int32_t run = 1;
      while (k + run < blocks && (split ? split->block_part[k + run] : 0) == part) run++;
      fprintf(f, " %d*%d", (int)part, (int)run);
      k += run;
    }
    fputc('\n', f);
  }
  return fclose(f) == 0 ? text : (free(text), NULL);
}

/* The whole text of path (malloc'ed), or NULL. */
static char *read_text(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  char *text = NULL;
  size_t length = 0;
  FILE *out = open_memstream(&text, &length);
  char buf[1 << 14];
  size_t n;
  while (out && (n = fread(buf, 1, sizeof buf, f)) > 0) fwrite(buf, 1, n, out);
  fclose(f);
  if (!out) return NULL;
  return fclose(out) == 0 ? text : (free(text), NULL);
}

/* The text after "name " on a line of text, or NULL. */
static const char *line_of(const char *text, const char *name) {
  size_t n = strlen(name);
  for (const char *p = text; p && *p;) {
    if (strncmp(p, name, n) == 0 && p[n] == ' ') return p + n + 1;
    p = strchr(p, '\n');
    p = p ? p + 1 : NULL;
  }
  return NULL;
}

/* The decimal number after "name " on a line of text, or -1. */
static long long line_value(const char *text, const char *name) {
  const char *v = line_of(text, name);
  return v ? strtoll(v, NULL, 10) : -1;
}

int run_split_checkpoint_processes(const char *dir) {
  int count;
  int32_t *frames = run_checkpoint_list(dir, ".manifest", &count);
  int processes = 0;
  if (count > 0) {
    char path[4200];
    manifest_path(path, sizeof path, dir, frames[0]);
    char *text = read_text(path);
    long long p = text ? line_value(text, "processes") : -1;
    processes = p > 0 && p < 1 << 20 ? (int)p : 0;
    free(text);
  }
  free(frames);
  return count > 0 ? (processes > 0 ? processes : -1) : 0;
}

/* Removes all but the newest two of dir's checkpoint_NNNN<suffix> files. */
static void keep_newest_two(const char *dir, const char *suffix) {
  int count;
  int32_t *frames = run_checkpoint_list(dir, suffix, &count);
  char path[4200];
  for (int i = 2; i < count; ++i) {
    snprintf(path, sizeof path, "%s/checkpoint_%04d%s", dir, (int)frames[i], suffix);
    remove(path);
  }
  free(frames);
}

int run_split_checkpoint_save(run_mpi *m, const char *dir, const piola_world *world, uint64_t key,
                              int32_t frame) {
  char path[4200];
  part_path(path, sizeof path, dir, frame, m->rank);
  bool ok = piola_world_checkpoint_write(world, path, key, frame) == PIOLA_OK;
  if (!ok) fprintf(stderr, "piola run: MPI process %d: checkpoint: %s\n", m->rank, piola_last_error());
  if (!run_mpi_all(m, ok)) return 0;
  if (m->rank == 0) { /* every process's file is in place: the manifest commits the set */
    char *text = manifest_text(world, key, frame, m->size);
    piola_atomic_file f;
    manifest_path(path, sizeof path, dir, frame);
    ok = text && piola_atomic_file_open(&f, path) == PIOLA_OK;
    if (ok) {
      fputs(text, f.stream);
      ok = piola_atomic_file_commit(&f) == PIOLA_OK;
    }
    if (!ok) fprintf(stderr, "piola run: checkpoint: %s\n", text ? piola_last_error() : "out of memory");
    free(text);
  }
  if (!run_mpi_all(m, ok)) return 0;
  /* the newest two sets, as a single process keeps its newest two files */
  char suffix[32];
  snprintf(suffix, sizeof suffix, "_p%d.bin", m->rank);
  if (m->rank == 0) keep_newest_two(dir, ".manifest");
  keep_newest_two(dir, suffix);
  return 1;
}

/* Whether a solid of world can be cut (its mesh and partition then change). */
static bool cut_world(const piola_world *world) {
  for (int32_t s = 0; s < piola_world_solid_count(world); ++s)
    if (piola_world_solid_has_fracture(world, s)) return true;
  return false;
}

/* Process 0: whether the manifest of frame fits this run: 0 yes, 1 damaged (skip it),
 * 2 refused (printed). Without partition, the solids' partitions are not compared: a cut
 * world's are known only once its state is read (run_split_checkpoint_resume). */
static int check_manifest(run_mpi *m, const char *dir, const piola_world *world, uint64_t key,
                          int32_t frame, bool partition) {
  char path[4200];
  manifest_path(path, sizeof path, dir, frame);
  char *text = read_text(path), *expected = manifest_text(world, key, frame, m->size);
  int verdict = 0;
  if (!text || !expected || line_value(text, "frame") != frame) {
    fprintf(stderr, "piola run: skipping a damaged checkpoint: %s cannot be read\n", path);
    verdict = 1;
  } else if (line_value(text, "processes") != m->size) {
    fprintf(stderr,
            "piola run: cannot resume: %s was written by a run on %lld MPI processes, this run has "
            "%d; resume with mpirun -np %lld, or use --force to start over (docs/mpi.md)\n",
            path, line_value(text, "processes"), m->size, line_value(text, "processes"));
    verdict = 2;
  } else if (!line_of(text, "scene_key") || strtoull(line_of(text, "scene_key"), NULL, 16) != key) {
    fprintf(stderr, "piola run: cannot resume: %s was written for another scene (its scene file "
                    "or meshes differ); use --force to start over\n", path);
    verdict = 2;
  } else if (partition ? strcmp(text, expected) != 0
                       : line_value(text, "solids") != line_value(expected, "solids")) {
    fprintf(stderr, "piola run: cannot resume: %s holds another partition of the solids than "
                    "this run's (docs/mpi.md); use --force to start over\n", path);
    verdict = 2;
  }
  free(text), free(expected);
  return verdict;
}

/* Every process reads its file of frame: 0 when all read it intact, 1 when one found it
 * damaged, 2 when one refused it (printed where it happened). Collective. */
static int read_set(run_mpi *m, const char *dir, piola_world *world, uint64_t key, int32_t frame) {
  char path[4200];
  part_path(path, sizeof path, dir, frame, m->rank);
  int32_t read_frame = -1;
  const piola_status st = piola_world_checkpoint_read(world, path, key, &read_frame);
  const int mine = st == PIOLA_OK && read_frame == frame ? 0 : st == PIOLA_ERROR_UNSUPPORTED ? 2 : 1;
  if (mine == 2)
    fprintf(stderr, "piola run: MPI process %d: cannot resume: %s; use --force to start over\n",
            m->rank, piola_last_error());
  else if (mine == 1)
    fprintf(stderr, "piola run: MPI process %d: skipping a damaged checkpoint: %s\n", m->rank,
            st == PIOLA_OK ? "another frame than its manifest's" : piola_last_error());
  return run_mpi_max(m, mine);
}

/* After every process has read the set of frame of a world that can be cut: the solids a
 * cut rebuilt on any process (left whole by the deferred read) are partitioned again
 * together, the files read once more into the split solids (the split's own state, the
 * damping operator and the next solve's start, as the run that wrote them had it), and
 * the manifest's partitions compared with the world's. 0, or 2 (printed). Collective. */
static int split_cut_solids(run_mpi *m, const char *dir, piola_world *world, uint64_t key,
                            int32_t frame) {
  bool replanned = false, ok = true;
  for (int32_t s = 0; s < piola_world_solid_count(world) && ok; ++s) {
    if (!run_mpi_max(m, piola_world_solid_split_pending(world, s))) continue;
    const piola_status st = piola_world_solid_replan_work_split(world, s);
    if (st != PIOLA_OK)
      fprintf(stderr, "piola run: MPI process %d: cannot resume: %s\n", m->rank, piola_last_error());
    ok = run_mpi_all(m, st == PIOLA_OK);
    replanned = true;
  }
  if (ok && replanned && read_set(m, dir, world, key, frame) != 0) {
    if (m->rank == 0)
      fprintf(stderr, "piola run: cannot resume: the checkpoint of frame %d could not be read again "
                      "after its cut solids were partitioned; use --force to start over\n", (int)frame);
    ok = false;
  }
  if (!ok) return 2;
  const int verdict = m->rank == 0 ? check_manifest(m, dir, world, key, frame, true) : 0;
  return run_mpi_from_lead(m, verdict) == 0 ? 0 : 2;
}

int run_split_checkpoint_resume(run_mpi *m, const char *dir, piola_world *world, uint64_t key,
                                int32_t *frame) {
  const bool lead = m->rank == 0;
  int count = 0, single = 0;
  int32_t *frames = lead ? run_checkpoint_list(dir, ".manifest", &count) : NULL;
  if (lead && count == 0) {
    int32_t *bins = run_checkpoint_list(dir, ".bin", &single);
    free(bins);
  }
  const int found = run_mpi_from_lead(m, count > 0 ? 0 : single > 0 ? 2 : 1);
  if (found != 0) {
    if (found == 2 && lead)
      fprintf(stderr, "piola run: cannot resume: %s holds the checkpoints of a single-process run "
                      "(checkpoint_NNNN.bin); resume it without mpirun, or use --force to start "
                      "over (docs/mpi.md)\n", dir);
    free(frames);
    return found;
  }
  /* a cut state's read rebuilds the solid; its partition, a collective step, waits until
   * every process has read its file, so that a set one of them cannot read is skipped by
   * all without anyone left waiting */
  const bool cut = cut_world(world);
  piola_world_defer_work_split_replans(world, cut);
  int rc = 2, next = 0;
  for (;;) {
    int candidate = -1; /* -1: none left, -2: refused */
    while (lead && next < count) {
      const int verdict = check_manifest(m, dir, world, key, frames[next++], !cut);
      if (verdict == 0) candidate = frames[next - 1];
      if (verdict == 2) candidate = -2;
      if (verdict != 1) break;
    }
    candidate = run_mpi_from_lead(m, candidate);
    if (candidate == -2) break;
    if (candidate == -1) {
      if (lead)
        fprintf(stderr, "piola run: cannot resume: no intact checkpoint in %s; use --force to "
                        "start over\n", dir);
      break;
    }
    const int worst = read_set(m, dir, world, key, candidate);
    if (worst == 0) {
      *frame = candidate;
      rc = 0;
      break;
    }
    if (worst == 2) break;
  }
  piola_world_defer_work_split_replans(world, 0);
  if (rc == 0 && cut) rc = split_cut_solids(m, dir, world, key, *frame);
  free(frames);
  return rc;
}
