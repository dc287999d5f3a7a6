/* `piola run` on several MPI processes (run_mpi.h, docs/mpi.md). */
#include "cli/run_mpi.h"

#include <stdio.h>
#include <stdlib.h>

#ifdef PIOLA_MPI
#include <mpi.h>

#include "common/status_report.h"
#include "piola/mpi.h"
#include "piola/work_split.h"

/* mpirun (OpenMPI) and other launchers set these in the processes they start. */
static bool launched_by_mpirun(void) {
  return getenv("OMPI_COMM_WORLD_SIZE") || getenv("PMI_SIZE") || getenv("PMIX_RANK");
}

bool run_mpi_start(run_mpi *m) {
  *m = (run_mpi){0, 1, false, NULL};
  if (!launched_by_mpirun()) return true;
  if (MPI_Init(NULL, NULL) != MPI_SUCCESS) {
    fprintf(stderr, "piola run: MPI_Init failed\n");
    return false;
  }
  m->started = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &m->rank);
  MPI_Comm_size(MPI_COMM_WORLD, &m->size);
  return true;
}

piola_status run_mpi_load(run_mpi *m, const char *path, piola_scene **out) {
  *out = NULL;
  if (m->size <= 1) return piola_scene_load(path, out);
  piola_scene_desc *desc = NULL;
  PIOLA_TRY(piola_scene_parse_file(path, &desc));
  piola_mpi_split *split = NULL;
  piola_status st = piola_mpi_split_create(&split);
  m->split = split;
  if (st == PIOLA_OK) {
    piola_work_split_planner planner = piola_mpi_split_planner(split);
    st = piola_scene_build_split(desc, &planner, out);
  }
  piola_scene_desc_destroy(desc);
  return st;
}

bool run_mpi_split(run_mpi *m, piola_world *world) {
  if (m->size <= 1) return true;
  piola_status st;
  if (m->split) {
    st = piola_mpi_split_finish(m->split, world);
  } else {
    piola_mpi_split *split = NULL;
    st = piola_mpi_split_world(world, &split);
    m->split = split;
  }
  if (st != PIOLA_OK) {
    if (m->rank == 0)
      fprintf(stderr, "piola run: cannot run on %d MPI processes: %s (run it without mpirun, "
                      "or with -np 1; docs/mpi.md)\n", m->size, piola_last_error());
    return false;
  }
  return true;
}

bool run_mpi_all(run_mpi *m, bool ok) {
  if (!m->started) return ok;
  int mine = ok, all = 0;
  MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  return all != 0;
}

void run_mpi_collect(run_mpi *m, piola_world *world) {
  if (m->split) (void)piola_world_split_collect(world);
}

void run_mpi_report(run_mpi *m) {
  if (!m->split) return;
  piola_mpi_split_stats st = piola_mpi_split_stats_of(m->split);
  double mine[9] = {(double)st.tets, (double)st.owned_nodes, (double)st.shared_nodes,
                    (double)st.halo_bytes, st.halo_seconds, (double)st.gather_bytes,
                    st.gather_seconds, (double)st.replans, st.replan_seconds};
  double *all = m->rank == 0 ? malloc(sizeof mine * (size_t)m->size) : NULL;
  MPI_Gather(mine, 9, MPI_DOUBLE, all, 9, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  if (m->rank != 0 || !all) return;
  for (int r = 0; r < m->size; ++r) {
    const double *a = all + 9 * r;
    fprintf(stderr,
            "piola run: MPI rank %d/%d: %.0f tets, %.0f owned nodes, %.0f shared nodes; halo "
            "sent %.3f MB in %.3f s, gathers received %.3f MB in %.3f s",
            r, m->size, a[0], a[1], a[2], a[3] / 1e6, a[4], a[5] / 1e6, a[6]);
    if (a[7] > 0) /* cuts changed a solid's mesh */
      fprintf(stderr, "; %.0f partitions made again after cuts in %.3f s", a[7], a[8]);
    fputc('\n', stderr);
  }
  free(all);
}

int run_mpi_max(run_mpi *m, int value) {
  if (!m->started) return value;
  int all = value;
  MPI_Allreduce(&value, &all, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return all;
}

int run_mpi_from_lead(run_mpi *m, int value) {
  if (m->started) MPI_Bcast(&value, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return value;
}

void run_mpi_finish(run_mpi *m, piola_world *world) {
  piola_mpi_split_destroy(m->split, world);
  m->split = NULL;
  if (m->started) MPI_Finalize();
  m->started = false;
}

#else /* a build without MPI: always the single process */

bool run_mpi_start(run_mpi *m) {
  *m = (run_mpi){0, 1, false, NULL};
  return true;
}
piola_status run_mpi_load(run_mpi *m, const char *path, piola_scene **out) {
  (void)m;
  return piola_scene_load(path, out);
}
bool run_mpi_split(run_mpi *m, piola_world *world) {
  (void)m, (void)world;
  return true;
}
bool run_mpi_all(run_mpi *m, bool ok) {
  (void)m;
  return ok;
}
void run_mpi_collect(run_mpi *m, piola_world *world) { (void)m, (void)world; }
void run_mpi_report(run_mpi *m) { (void)m; }
int run_mpi_max(run_mpi *m, int value) {
  (void)m;
  return value;
}
int run_mpi_from_lead(run_mpi *m, int value) {
  (void)m;
  return value;
}
void run_mpi_finish(run_mpi *m, piola_world *world) { (void)m, (void)world; }

#endif
