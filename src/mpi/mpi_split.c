/* A world's solids split among the processes of MPI_COMM_WORLD (piola/mpi.h, docs/mpi.md).
 *
 * Partition. Each solid's blocks of PIOLA_WORK_SPLIT_BLOCK consecutive tets (the force
 * loop's unit of work) are the vertices of a graph: the tets' dual graph (METIS_MeshToDual,
 * tets sharing a face) collapsed onto blocks, each edge weighted by the faces it stands for,
 * each block weighted by its real tets. METIS_PartGraphKway cuts it into one part per process
 * on rank 0, which broadcasts it, so every process holds the same partition. A node only one
 * process's blocks touch is that process's (process 0's if no tet touches it); the nodes
 * several processes touch are shared out between them (choose_owners).
 *
 * Exchanges (the three operations of piola/work_split.h):
 *   sum_nodes    halo: each process sends its partial forces on the nodes it shares with
 *                another owner to that owner (MPI_Isend / MPI_Irecv, one message per
 *                neighbour pair and direction); the owner adds the partials in process
 *                order, its own at its place, so the sum has one fixed order whoever owns
 *                the node. Then share_nodes.
 *   share_nodes  replication: MPI_Allgatherv of the owned nodes' values (3 per node).
 *   share_blocks replication: MPI_Allgatherv of each process's blocks' per-tet state (only
 *                for solids with plasticity, which keep the replicated mode).
 *   share_ghosts halo of blocks (the local mode): each process sends the rotations of its
 *                blocks with a tet on a node a neighbour owns to that neighbour (MPI_Isend /
 *                MPI_Irecv), which holds them as ghosts for its damping rows.
 *   reduce       MPI_Allgather of each process's values, combined in process order, so
 *                every process gets the same bits.
 *   collect_blocks  MPI_Gatherv of every process's blocks to process 0 (frames only). */
#include <math.h>
#include <metis.h>
#include <mpi.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "common/status_report.h"
#ifdef PIOLA_PETSC
#include "mpi/mpi_petsc.h"
#endif
#include "piola/mpi.h"
#include "piola/work_split.h"

typedef struct solid_plan {
  struct piola_mpi_split *owner;
  int32_t node_count, block_count;
  int32_t *block_part, *node_part;
  /* items of each process in increasing order: node_order[node_start[p] .. node_start[p+1]) */
  int32_t *node_order, *node_start, *block_order, *block_start;
  /* halo: neighbours in increasing order; per neighbour the nodes whose partial this process
   * sends (owned by the neighbour) and those whose partial it receives (owned here) */
  int32_t neighbor_count;
  int32_t *neighbors, *send_start, *send_nodes, *recv_start, *recv_nodes;
  /* nodes owned here that a lower process touches too (their sum starts with the lowest
   * process's partial, not with this one's), and per received partial whether it is the
   * lowest process's; the own partials wait in late_values */
  int32_t late_count;
  int32_t *late_nodes;
  uint8_t *recv_first;
  double *send_values, *recv_values, *late_values, *gather;
  size_t gather_capacity;
  /* ghost blocks: per neighbour (ghost_neighbors) the blocks this process sends and those it
   * receives, increasing; the message buffer */
  int32_t ghost_neighbor_count;
  int32_t *ghost_neighbors, *ghost_send_start, *ghost_send, *ghost_recv_start, *ghost_recv;
  double *ghost_buffer;
  size_t ghost_capacity;
  double *reduce_buffer; /* size * REDUCE_MAX doubles */
  int *counts, *displs;
  MPI_Request *requests;
#ifdef PIOLA_PETSC
  piola__petsc_solver *newton; /* the implicit step's systems, made on first use */
#endif
  int64_t stat_tets, stat_owned, stat_shared; /* its share of the process's statistics */
  piola_work_split split;
} solid_plan;

struct piola_mpi_split {
  int rank, size;
  int32_t solid_count;  /* entries of plans */
  solid_plan **plans;   /* per solid, or NULL where not split (yet); each plan stays where it
                           is, since the bodies hold its split */
  piola_mpi_split_stats stats;
};

/* CPU time of the calling thread, s (the exchanges' own CPU share, docs/scaling.md). */
static double cpu_now(void) {
  struct timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void plan_free(solid_plan *p) {
#ifdef PIOLA_PETSC
  piola__petsc_solver_free(p->newton);
#endif
  free(p->block_part), free(p->node_part), free(p->node_order), free(p->node_start);
  free(p->block_order), free(p->block_start), free(p->neighbors), free(p->send_start);
  free(p->send_nodes), free(p->recv_start), free(p->recv_nodes), free(p->send_values);
  free(p->recv_values), free(p->late_nodes), free(p->recv_first), free(p->late_values);
  free(p->gather), free(p->counts), free(p->displs), free(p->requests);
  free(p->ghost_neighbors), free(p->ghost_send_start), free(p->ghost_send);
  free(p->ghost_recv_start), free(p->ghost_recv), free(p->ghost_buffer), free(p->reduce_buffer);
}

#define REDUCE_MAX 8

/* ---------------------------------------------------------------- the three operations */

static int ensure_gather(solid_plan *p, size_t doubles) {
  if (doubles <= p->gather_capacity) return 1;
  double *g = realloc(p->gather, doubles * sizeof(double));
  if (!g) return 0;
  p->gather = g;
  p->gather_capacity = doubles;
  return 1;
}

/* Every process's items (order/start by process) of `width` doubles each: written by their
 * process, read by all. */
static void share_items(solid_plan *p, double *values, int32_t width, const int32_t *order,
                        const int32_t *start) {
  piola_mpi_split *s = p->owner;
  double t0 = MPI_Wtime(), c0 = cpu_now();
  const int32_t total = start[s->size];
  if (!ensure_gather(p, (size_t)total * (size_t)width))
    MPI_Abort(MPI_COMM_WORLD, 1); /* the processes cannot go on apart */
  for (int q = 0; q < s->size; ++q) {
    p->counts[q] = (start[q + 1] - start[q]) * width;
    p->displs[q] = start[q] * width;
  }
  for (int32_t k = start[s->rank]; k < start[s->rank + 1]; ++k)
    memcpy(p->gather + (size_t)k * (size_t)width, values + (size_t)order[k] * (size_t)width,
           (size_t)width * sizeof(double));
  MPI_Allgatherv(MPI_IN_PLACE, 0, MPI_DATATYPE_NULL, p->gather, p->counts, p->displs, MPI_DOUBLE,
                 MPI_COMM_WORLD);
  for (int32_t k = 0; k < total; ++k)
    if (k < start[s->rank] || k >= start[s->rank + 1])
      memcpy(values + (size_t)order[k] * (size_t)width, p->gather + (size_t)k * (size_t)width,
             (size_t)width * sizeof(double));
  s->stats.gather_bytes += (int64_t)(total - (start[s->rank + 1] - start[s->rank])) * width * 8;
  s->stats.gather_seconds += MPI_Wtime() - t0;
  s->stats.exchange_cpu_seconds += cpu_now() - c0;
}

static void share_nodes(void *context, double *values) {
  solid_plan *p = context;
  share_items(p, values, 3, p->node_order, p->node_start);
}

static void share_blocks(void *context, double *values, int32_t width) {
  solid_plan *p = context;
  share_items(p, values, width, p->block_order, p->block_start);
}

static void sum_nodes(void *context, double *values) {
  solid_plan *p = context;
  piola_mpi_split *s = p->owner;
  double t0 = MPI_Wtime(), c0 = cpu_now();
  int r = 0;
  for (int32_t k = 0; k < p->neighbor_count; ++k) {
    const int32_t n0 = p->recv_start[k], n1 = p->recv_start[k + 1];
    if (n1 > n0)
      MPI_Irecv(p->recv_values + 3 * (size_t)n0, 3 * (n1 - n0), MPI_DOUBLE, p->neighbors[k], 7,
                MPI_COMM_WORLD, &p->requests[r++]);
  }
  for (int32_t k = 0; k < p->neighbor_count; ++k) {
    const int32_t n0 = p->send_start[k], n1 = p->send_start[k + 1];
    if (n1 == n0) continue;
    for (int32_t j = n0; j < n1; ++j)
      memcpy(p->send_values + 3 * (size_t)j, values + 3 * (size_t)p->send_nodes[j], 3 * sizeof(double));
    MPI_Isend(p->send_values + 3 * (size_t)n0, 3 * (n1 - n0), MPI_DOUBLE, p->neighbors[k], 7,
              MPI_COMM_WORLD, &p->requests[r++]);
    s->stats.halo_bytes += 24 * (int64_t)(n1 - n0);
  }
  MPI_Waitall(r, p->requests, MPI_STATUSES_IGNORE);
  /* the partials in process order: the lower neighbours' (the lowest one's copied, not
   * added: 0 + x is not x's bits for x = -0), this process's, the higher neighbours' */
  for (int32_t k = 0; k < p->late_count; ++k)
    memcpy(p->late_values + 3 * (size_t)k, values + 3 * (size_t)p->late_nodes[k], 3 * sizeof(double));
  int32_t k = 0;
  for (; k < p->neighbor_count && p->neighbors[k] < s->rank; ++k)
    for (int32_t j = p->recv_start[k]; j < p->recv_start[k + 1]; ++j)
      for (int c = 0; c < 3; ++c) {
        double *v = values + 3 * (size_t)p->recv_nodes[j] + c;
        *v = p->recv_first[j] ? p->recv_values[3 * (size_t)j + c] : *v + p->recv_values[3 * (size_t)j + c];
      }
  for (int32_t l = 0; l < p->late_count; ++l)
    for (int c = 0; c < 3; ++c) values[3 * (size_t)p->late_nodes[l] + c] += p->late_values[3 * (size_t)l + c];
  for (; k < p->neighbor_count; ++k)
    for (int32_t j = p->recv_start[k]; j < p->recv_start[k + 1]; ++j)
      for (int c = 0; c < 3; ++c) values[3 * (size_t)p->recv_nodes[j] + c] += p->recv_values[3 * (size_t)j + c];
  s->stats.halo_seconds += MPI_Wtime() - t0;
  s->stats.exchange_cpu_seconds += cpu_now() - c0;
  share_nodes(context, values);
}

static double *ensure(double **buffer, size_t *capacity, size_t doubles) {
  if (doubles <= *capacity) return *buffer;
  double *g = realloc(*buffer, (doubles > 0 ? doubles : 1) * sizeof(double));
  if (!g) MPI_Abort(MPI_COMM_WORLD, 1); /* the processes cannot go on apart */
  *buffer = g;
  *capacity = doubles;
  return g;
}

static void share_ghosts(void *context, void *owner, piola_work_split_pack pack,
                         piola_work_split_unpack unpack, int32_t width) {
  solid_plan *p = context;
  piola_mpi_split *s = p->owner;
  double t0 = MPI_Wtime(), c0 = cpu_now();
  const int32_t nk = p->ghost_neighbor_count;
  const size_t sends = (size_t)p->ghost_send_start[nk], recvs = (size_t)p->ghost_recv_start[nk];
  double *buf = ensure(&p->ghost_buffer, &p->ghost_capacity, (sends + recvs) * (size_t)width);
  double *in = buf + sends * (size_t)width;
  int r = 0;
  for (int32_t k = 0; k < nk; ++k) {
    const int32_t b0 = p->ghost_recv_start[k], b1 = p->ghost_recv_start[k + 1];
    if (b1 > b0)
      MPI_Irecv(in + (size_t)b0 * (size_t)width, (b1 - b0) * width, MPI_DOUBLE, p->ghost_neighbors[k],
                8, MPI_COMM_WORLD, &p->requests[r++]);
  }
  for (int32_t k = 0; k < nk; ++k) {
    const int32_t b0 = p->ghost_send_start[k], b1 = p->ghost_send_start[k + 1];
    if (b1 == b0) continue;
    for (int32_t j = b0; j < b1; ++j) pack(owner, p->ghost_send[j], buf + (size_t)j * (size_t)width);
    MPI_Isend(buf + (size_t)b0 * (size_t)width, (b1 - b0) * width, MPI_DOUBLE, p->ghost_neighbors[k],
              8, MPI_COMM_WORLD, &p->requests[r++]);
    s->stats.halo_bytes += 8 * (int64_t)(b1 - b0) * width;
  }
  MPI_Waitall(r, p->requests, MPI_STATUSES_IGNORE);
  for (size_t j = 0; j < recvs; ++j) unpack(owner, p->ghost_recv[j], in + j * (size_t)width);
  s->stats.halo_seconds += MPI_Wtime() - t0;
  s->stats.exchange_cpu_seconds += cpu_now() - c0;
}

static void reduce(void *context, double *values, int32_t count, piola_work_split_reduction op) {
  solid_plan *p = context;
  piola_mpi_split *s = p->owner;
  if (count > REDUCE_MAX) MPI_Abort(MPI_COMM_WORLD, 1); /* a programming error */
  const double c0 = cpu_now();
  MPI_Allgather(values, count, MPI_DOUBLE, p->reduce_buffer, count, MPI_DOUBLE, MPI_COMM_WORLD);
  for (int32_t i = 0; i < count; ++i) {
    double r = p->reduce_buffer[i];
    for (int q = 1; q < s->size; ++q) {
      const double x = p->reduce_buffer[(size_t)q * (size_t)count + i];
      r = op == PIOLA_WORK_SPLIT_SUM ? r + x : op == PIOLA_WORK_SPLIT_MAX ? fmax(r, x) : fmin(r, x);
    }
    values[i] = r;
  }
  s->stats.exchange_cpu_seconds += cpu_now() - c0;
}

static void collect_blocks(void *context, void *owner, piola_work_split_pack pack,
                           piola_work_split_unpack unpack, int32_t width) {
  solid_plan *p = context;
  piola_mpi_split *s = p->owner;
  double t0 = MPI_Wtime(), c0 = cpu_now();
  const int32_t *start = p->block_start, *order = p->block_order;
  const int32_t mine = start[s->rank + 1] - start[s->rank];
  /* process 0 receives every other process's blocks, the others send theirs */
  const size_t items = s->rank == 0 ? (size_t)(start[s->size] - mine) : (size_t)mine;
  double *buf = ensure(&p->gather, &p->gather_capacity, items * (size_t)width);
  if (s->rank != 0)
    for (int32_t k = 0; k < mine; ++k) pack(owner, order[start[s->rank] + k], buf + (size_t)k * (size_t)width);
  for (int q = 0; q < s->size; ++q) {
    p->counts[q] = q == 0 ? 0 : (start[q + 1] - start[q]) * width;
    p->displs[q] = q == 0 ? 0 : (start[q] - mine) * width;
  }
  if (s->rank == 0)
    MPI_Gatherv(MPI_IN_PLACE, 0, MPI_DOUBLE, buf, p->counts, p->displs, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  else
    MPI_Gatherv(buf, mine * width, MPI_DOUBLE, NULL, NULL, NULL, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  if (s->rank == 0) {
    for (int32_t k = mine; k < start[s->size]; ++k)
      unpack(owner, order[k], buf + (size_t)(k - mine) * (size_t)width);
    s->stats.gather_bytes += 8 * (int64_t)items * width;
  }
  s->stats.gather_seconds += MPI_Wtime() - t0;
  s->stats.exchange_cpu_seconds += cpu_now() - c0;
}

#ifdef PIOLA_PETSC
static int32_t solve_newton(void *context, const piola_split_newton_system *system,
                            double *solution) {
  solid_plan *p = context;
  piola_mpi_split *s = p->owner;
  if (!p->newton && piola__petsc_solver_create(s->rank, p->node_count, p->node_order,
                                               p->node_start, &p->newton) != PIOLA_OK)
    return -1;
  return piola__petsc_solve(p->newton, system, solution);
}
#endif

/* Ghost plan: the blocks this process sends to each neighbour (its blocks with a tet on a
 * node the neighbour owns) and receives (the neighbour's blocks with a tet on a node owned
 * here), the rule the core's held blocks follow (work_split.c). */
static int plan_ghosts(solid_plan *p, const int32_t *tv, int32_t tets, int parts, int me) {
  int32_t *send_count = calloc((size_t)parts, sizeof(int32_t));
  int32_t *recv_count = calloc((size_t)parts, sizeof(int32_t));
  uint8_t *seen = calloc((size_t)parts, 1);
  int ok = send_count && recv_count && seen;
  for (int pass = 0; ok && pass < 2; ++pass) {
    if (pass == 1) {
      p->ghost_neighbor_count = 0;
      for (int q = 0; q < parts; ++q)
        if (send_count[q] || recv_count[q]) p->ghost_neighbor_count++;
      const int32_t nk = p->ghost_neighbor_count;
      p->ghost_neighbors = malloc(sizeof(int32_t) * (size_t)(nk > 0 ? nk : 1));
      p->ghost_send_start = calloc((size_t)nk + 1, sizeof(int32_t));
      p->ghost_recv_start = calloc((size_t)nk + 1, sizeof(int32_t));
      if (!p->ghost_neighbors || !p->ghost_send_start || !p->ghost_recv_start) {
        ok = 0;
        break;
      }
      int32_t k = 0;
      for (int q = 0; q < parts; ++q) {
        if (!send_count[q] && !recv_count[q]) continue;
        p->ghost_neighbors[k] = q;
        p->ghost_send_start[k + 1] = p->ghost_send_start[k] + send_count[q];
        p->ghost_recv_start[k + 1] = p->ghost_recv_start[k] + recv_count[q];
        send_count[q] = p->ghost_send_start[k]; /* now the fill positions */
        recv_count[q] = p->ghost_recv_start[k];
        k++;
      }
      p->ghost_send = malloc(sizeof(int32_t) * (size_t)(p->ghost_send_start[nk] + 1));
      p->ghost_recv = malloc(sizeof(int32_t) * (size_t)(p->ghost_recv_start[nk] + 1));
      if (!p->ghost_send || !p->ghost_recv) {
        ok = 0;
        break;
      }
    }
    for (int32_t b = 0; b < p->block_count; ++b) {
      const int own = p->block_part[b] == me;
      int touches_me = 0;
      memset(seen, 0, (size_t)parts);
      for (int32_t t = b * PIOLA_WORK_SPLIT_BLOCK; t < (b + 1) * PIOLA_WORK_SPLIT_BLOCK && t < tets; ++t)
        for (int c = 0; c < 4; ++c) {
          const int32_t o = p->node_part[tv[4 * t + c]];
          touches_me |= o == me;
          if (own && o != me && !seen[o]) {
            seen[o] = 1;
            if (pass == 0) send_count[o]++;
            else p->ghost_send[send_count[o]++] = b;
          }
        }
      if (!own && touches_me) {
        if (pass == 0) recv_count[p->block_part[b]]++;
        else p->ghost_recv[recv_count[p->block_part[b]]++] = b;
      }
    }
  }
  free(send_count), free(recv_count), free(seen);
  return ok;
}

/* ---------------------------------------------------------------- partition */

static int compare_i64(const void *a, const void *b) {
  int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
  return (x > y) - (x < y);
}

/* A solid's tets as the partition sees them: 4 node indices per tet; blocks are
 * PIOLA_WORK_SPLIT_BLOCK consecutive tets. */
typedef struct plan_mesh {
  const int32_t *tets;
  int32_t tet_count, node_count;
} plan_mesh;

static int32_t block_count_of(int32_t tets) {
  return (tets + PIOLA_WORK_SPLIT_BLOCK - 1) / PIOLA_WORK_SPLIT_BLOCK;
}

/* block_part of a solid's blocks over `parts` processes (rank 0 only). */
static piola_status partition_blocks(const plan_mesh *mesh, int parts, int32_t *block_part) {
  const int32_t tets = mesh->tet_count;
  const int32_t blocks = block_count_of(tets);
  const int32_t *tv = mesh->tets;
  if (parts == 1 || blocks <= parts) { /* METIS divides by zero for one part */
    for (int32_t b = 0; b < blocks; ++b) block_part[b] = parts == 1 ? 0 : b;
    return PIOLA_OK;
  }
  idx_t ne = tets, nn = mesh->node_count, ncommon = 3, numflag = 0;
  idx_t *eptr = malloc(sizeof(idx_t) * ((size_t)tets + 1)), *eind = malloc(sizeof(idx_t) * 4 * (size_t)tets);
  idx_t *xadj = NULL, *adjncy = NULL;
  int64_t *pairs = NULL;
  idx_t *bxadj = NULL, *badj = NULL, *bw = NULL, *vw = NULL, *part = NULL;
  piola_status st = PIOLA_OK;
  if (!eptr || !eind) goto oom;
  for (int32_t t = 0; t <= tets; ++t) eptr[t] = 4 * (idx_t)t;
  for (int64_t k = 0; k < 4 * (int64_t)tets; ++k) eind[k] = tv[k];
  if (METIS_MeshToDual(&ne, &nn, eptr, eind, &ncommon, &numflag, &xadj, &adjncy) != METIS_OK)
    goto oom;
  /* the dual graph's edges between different blocks, as (block, neighbour block) keys */
  const int64_t edges = xadj[tets];
  pairs = malloc(sizeof(int64_t) * (size_t)(edges > 0 ? edges : 1));
  bxadj = calloc((size_t)blocks + 1, sizeof(idx_t));
  badj = malloc(sizeof(idx_t) * (size_t)(edges > 0 ? edges : 1));
  bw = malloc(sizeof(idx_t) * (size_t)(edges > 0 ? edges : 1));
  vw = calloc((size_t)blocks, sizeof(idx_t));
  part = malloc(sizeof(idx_t) * (size_t)blocks);
  if (!pairs || !bxadj || !badj || !bw || !vw || !part) goto oom;
  int64_t count = 0;
  for (int32_t t = 0; t < tets; ++t) {
    vw[t / PIOLA_WORK_SPLIT_BLOCK]++;
    for (idx_t k = xadj[t]; k < xadj[t + 1]; ++k) {
      int32_t b = t / PIOLA_WORK_SPLIT_BLOCK, c = (int32_t)adjncy[k] / PIOLA_WORK_SPLIT_BLOCK;
      if (b != c) pairs[count++] = (int64_t)b * blocks + c;
    }
  }
  qsort(pairs, (size_t)count, sizeof(int64_t), compare_i64);
  int64_t unique = 0;
  for (int64_t k = 0; k < count; ++k) {
    if (unique > 0 && pairs[k] == pairs[k - 1]) {
      bw[unique - 1]++;
      continue;
    }
    badj[unique] = (idx_t)(pairs[k] % blocks);
    bw[unique] = 1;
    bxadj[pairs[k] / blocks + 1]++;
    unique++;
  }
  for (int32_t b = 0; b < blocks; ++b) bxadj[b + 1] += bxadj[b];
  idx_t nv = blocks, ncon = 1, np = parts, objval = 0;
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = 1;
  int ok = METIS_PartGraphKway(&nv, &ncon, bxadj, badj, vw, NULL, bw, &np, NULL, NULL, options,
                               &objval, part);
  if (ok != METIS_OK) {
    st = PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "METIS could not partition %d blocks into %d parts",
                    (int)blocks, parts);
  } else {
    for (int32_t b = 0; b < blocks; ++b) block_part[b] = (int32_t)part[b];
  }
  goto done;
oom:
  st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "partition of %d tets: out of memory", (int)tets);
done:
  if (xadj) METIS_Free(xadj);
  if (adjncy) METIS_Free(adjncy);
  free(eptr), free(eind), free(pairs), free(bxadj), free(badj), free(bw), free(vw), free(part);
  return st;
}

/* Items 0 .. n-1 sorted by their process (stable: increasing within a process). */
static int order_by_part(const int32_t *part_of, int32_t n, int parts, int32_t **order, int32_t **start) {
  *order = malloc(sizeof(int32_t) * (size_t)(n > 0 ? n : 1));
  *start = calloc((size_t)parts + 1, sizeof(int32_t));
  if (!*order || !*start) return 0;
  for (int32_t i = 0; i < n; ++i) (*start)[part_of[i] + 1]++;
  for (int q = 0; q < parts; ++q) (*start)[q + 1] += (*start)[q];
  int32_t *fill = malloc(sizeof(int32_t) * (size_t)parts);
  if (!fill) return 0;
  memcpy(fill, *start, sizeof(int32_t) * (size_t)parts);
  for (int32_t i = 0; i < n; ++i) (*order)[fill[part_of[i]]++] = i;
  free(fill);
  return 1;
}

/* lowest and highest process touching node i (touch: node x process), -1 if none */
static void touch_range(const uint8_t *touch, int32_t i, int parts, int *lo, int *hi) {
  *lo = *hi = -1;
  for (int q = 0; q < parts; ++q)
    if (touch[(size_t)i * parts + q]) {
      if (*lo < 0) *lo = q;
      *hi = q;
    }
}

/* Owners. A node one process touches is its own (process 0's if none touches it). The nodes
 * several processes touch (the parts' interfaces) are shared out: of those with the same
 * lowest and highest process, taken in node order, the first half goes to the lowest and
 * the rest to the highest. Giving all to the lowest (until 2026-12-02) gave process 0 of 2
 * every interface row of the damping products and every block of the other process on the
 * interface as a ghost to assemble: the work that made it the busier one (docs/scaling.md).
 * Halves in node order keep each owner's interface nodes together on a spatially ordered
 * mesh, so each process holds about half of the other's interface blocks as ghosts. */
static int choose_owners(const uint8_t *touch, int32_t nodes, int parts, int32_t *owner) {
  const size_t groups = (size_t)parts * (size_t)parts; /* by (lowest, highest) process */
  int32_t *size = calloc(2 * groups, sizeof(int32_t)), *taken = size + groups;
  if (!size) return 0;
  for (int pass = 0; pass < 2; ++pass)
    for (int32_t i = 0; i < nodes; ++i) {
      int lo, hi;
      touch_range(touch, i, parts, &lo, &hi);
      if (lo == hi) { /* one process, or none */
        owner[i] = lo < 0 ? 0 : lo;
        continue;
      }
      const size_t g = (size_t)lo * (size_t)parts + (size_t)hi;
      if (pass == 0) size[g]++;
      else owner[i] = taken[g]++ < (size[g] + 1) / 2 ? lo : hi;
    }
  free(size);
  return 1;
}

/* The lists sum_nodes needs to add the partials in process order when this process owns a
 * node that a lower process touches too. */
static int plan_late_sums(solid_plan *p, const uint8_t *touch, int parts, int me) {
  const int32_t recvs = p->recv_start[p->neighbor_count];
  p->recv_first = calloc((size_t)(recvs > 0 ? recvs : 1), 1);
  if (!p->recv_first) return 0;
  p->late_count = 0;
  for (int32_t k = 0; k < p->neighbor_count; ++k)
    for (int32_t j = p->recv_start[k]; j < p->recv_start[k + 1]; ++j) {
      int lo, hi;
      touch_range(touch, p->recv_nodes[j], parts, &lo, &hi);
      p->recv_first[j] = p->neighbors[k] == lo;
      p->late_count += p->recv_first[j]; /* once per late node: its lowest process sends it */
    }
  p->late_nodes = malloc(sizeof(int32_t) * (size_t)(p->late_count > 0 ? p->late_count : 1));
  p->late_values = malloc(3 * sizeof(double) * (size_t)(p->late_count > 0 ? p->late_count : 1));
  if (!p->late_nodes || !p->late_values) return 0;
  int32_t n = 0;
  for (int32_t i = 0; i < p->node_count; ++i) {
    if (p->node_part[i] != me) continue;
    int lo, hi;
    touch_range(touch, i, parts, &lo, &hi);
    if (lo >= 0 && lo < me) p->late_nodes[n++] = i;
  }
  return n == p->late_count;
}

/* The plan and split of one solid from its tets (collective). */
static piola_status plan_solid(piola_mpi_split *s, const plan_mesh *mesh, solid_plan *p) {
  const int32_t tets = mesh->tet_count;
  const int32_t *tv = mesh->tets;
  const int parts = s->size, me = s->rank;
  p->owner = s;
  p->node_count = mesh->node_count;
  p->block_count = block_count_of(tets);
  p->block_part = malloc(sizeof(int32_t) * (size_t)(p->block_count > 0 ? p->block_count : 1));
  p->node_part = malloc(sizeof(int32_t) * (size_t)(p->node_count > 0 ? p->node_count : 1));
  p->counts = malloc(sizeof(int) * (size_t)parts);
  p->displs = malloc(sizeof(int) * (size_t)parts);
  uint8_t *touch = calloc((size_t)p->node_count * (size_t)parts, 1); /* node x process */
  if (!p->block_part || !p->node_part || !p->counts || !p->displs || !touch) {
    free(touch);
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "MPI split: out of memory");
  }
  int failed = 0;
  if (me == 0) {
    piola_status st = partition_blocks(mesh, parts, p->block_part);
    failed = st != PIOLA_OK;
  }
  MPI_Bcast(&failed, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (failed) {
    free(touch);
    return me == 0 ? PIOLA_ERROR_INVALID_ARGUMENT
                   : PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "MPI split: rank 0 could not partition");
  }
  MPI_Bcast(p->block_part, p->block_count, MPI_INT32_T, 0, MPI_COMM_WORLD);
  /* which processes touch each node, and its owner */
  for (int32_t t = 0; t < tets; ++t)
    for (int c = 0; c < 4; ++c)
      touch[(size_t)tv[4 * t + c] * parts + p->block_part[t / PIOLA_WORK_SPLIT_BLOCK]] = 1;
  if (!choose_owners(touch, p->node_count, parts, p->node_part)) goto oom;
  /* halo plan: nodes this process touches together with another, by neighbour */
  p->neighbors = malloc(sizeof(int32_t) * (size_t)parts);
  p->send_start = calloc((size_t)parts + 1, sizeof(int32_t));
  p->recv_start = calloc((size_t)parts + 1, sizeof(int32_t));
  if (!p->neighbors || !p->send_start || !p->recv_start) goto oom;
  int64_t shared = 0;
  for (int32_t i = 0; i < p->node_count; ++i) {
    if (!touch[(size_t)i * parts + me]) continue;
    int other = 0;
    for (int q = 0; q < parts; ++q) other |= q != me && touch[(size_t)i * parts + q];
    shared += other;
  }
  p->send_nodes = malloc(sizeof(int32_t) * (size_t)(shared > 0 ? shared : 1));
  p->recv_nodes = malloc(sizeof(int32_t) * (size_t)(shared * parts > 0 ? shared * parts : 1));
  if (!p->send_nodes || !p->recv_nodes) goto oom;
  int32_t sends = 0, recvs = 0;
  p->neighbor_count = 0;
  for (int q = 0; q < parts; ++q) {
    if (q == me) continue;
    int32_t s0 = sends, r0 = recvs;
    for (int32_t i = 0; i < p->node_count; ++i) {
      if (!touch[(size_t)i * parts + me] || !touch[(size_t)i * parts + q]) continue;
      if (p->node_part[i] == q) p->send_nodes[sends++] = i;    /* q owns it: send my partial */
      else if (p->node_part[i] == me) p->recv_nodes[recvs++] = i; /* mine: q's partial comes */
    }
    if (sends == s0 && recvs == r0) continue;
    p->neighbors[p->neighbor_count++] = q;
    p->send_start[p->neighbor_count] = sends;
    p->recv_start[p->neighbor_count] = recvs;
  }
  p->send_values = malloc(3 * sizeof(double) * (size_t)(sends > 0 ? sends : 1));
  p->recv_values = malloc(3 * sizeof(double) * (size_t)(recvs > 0 ? recvs : 1));
  if (!plan_late_sums(p, touch, parts, me)) goto oom;
  p->requests = malloc(sizeof(MPI_Request) * 2 * (size_t)parts);
  p->reduce_buffer = malloc(sizeof(double) * REDUCE_MAX * (size_t)parts);
  if (!p->send_values || !p->recv_values || !p->requests || !p->reduce_buffer) goto oom;
  if (!plan_ghosts(p, tv, tets, parts, me)) goto oom;
  if (!order_by_part(p->node_part, p->node_count, parts, &p->node_order, &p->node_start) ||
      !order_by_part(p->block_part, p->block_count, parts, &p->block_order, &p->block_start))
    goto oom;
  free(touch);
  for (int32_t b = 0; b < p->block_count; ++b)
    if (p->block_part[b] == me)
      p->stat_tets += (b + 1) * PIOLA_WORK_SPLIT_BLOCK <= tets ? PIOLA_WORK_SPLIT_BLOCK
                                                              : tets - b * PIOLA_WORK_SPLIT_BLOCK;
  p->stat_owned = p->node_start[me + 1] - p->node_start[me];
  p->stat_shared = shared;
  s->stats.tets += p->stat_tets;
  s->stats.owned_nodes += p->stat_owned;
  s->stats.shared_nodes += p->stat_shared;
  p->split = (piola_work_split){.part = me,
                                .part_count = parts,
                                .block_part = p->block_part,
                                .node_part = p->node_part,
                                .context = p,
                                .sum_nodes = sum_nodes,
                                .share_nodes = share_nodes,
                                .share_blocks = share_blocks,
                                .share_ghosts = share_ghosts,
                                .reduce = reduce,
                                .collect_blocks = collect_blocks};
#ifdef PIOLA_PETSC
  p->split.solve_newton = solve_newton;
#endif
  return PIOLA_OK;
oom:
  free(touch);
  return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "MPI split: out of memory");
}

/* Plans solid `solid` (collective): a failure on any process is one on every process. */
static piola_status plan_agreed(piola_mpi_split *s, int32_t solid, const plan_mesh *mesh,
                                solid_plan **out) {
  *out = NULL;
  piola_status st = PIOLA_OK;
  if (solid >= s->solid_count) {
    solid_plan **grown = realloc(s->plans, sizeof *grown * (size_t)(solid + 1));
    if (grown) {
      for (int32_t i = s->solid_count; i <= solid; ++i) grown[i] = NULL;
      s->plans = grown;
      s->solid_count = solid + 1;
    } else {
      st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "MPI split: out of memory");
    }
  }
  solid_plan *p = NULL;
  if (st == PIOLA_OK && s->plans[solid])
    st = PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "MPI split: solid %d is split already", (int)solid);
  if (st == PIOLA_OK && !(p = calloc(1, sizeof *p)))
    st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "MPI split: out of memory");
  /* plan_solid's broadcasts run on every process, whatever failed here before */
  int skip = st != PIOLA_OK, any_skip = 0;
  MPI_Allreduce(&skip, &any_skip, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (!any_skip) st = plan_solid(s, mesh, p);
  int bad = st != PIOLA_OK || any_skip, any = 0;
  MPI_Allreduce(&bad, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (any) {
    if (p) plan_free(p), free(p);
    return st != PIOLA_OK ? st : PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "MPI split: another process failed");
  }
  s->plans[solid] = p;
  *out = p;
  return PIOLA_OK;
}

static piola_status plan_added_solid(void *context, int32_t solid, const piola_tet_mesh *mesh,
                                     const piola_work_split **out) {
  piola_mpi_split *s = context;
  *out = NULL;
  if (s->size == 1) return PIOLA_OK; /* one process: the solid stays whole */
  plan_mesh m = {mesh->tets, mesh->tet_count, mesh->vertex_count};
  solid_plan *p;
  PIOLA_TRY(plan_agreed(s, solid, &m, &p));
  *out = &p->split;
  return PIOLA_OK;
}

/* A split solid whose mesh a cut changed (piola_world_set_work_split_replanner): its old
 * plan, which no body refers to any more, gives way to one for the new mesh, partitioned
 * afresh (METIS on process 0, broadcast), as when the solid was added. */
static piola_status replan_solid(void *context, int32_t solid, const piola_tet_mesh *mesh,
                                 const piola_work_split **out) {
  piola_mpi_split *s = context;
  *out = NULL;
  if (s->size == 1) return PIOLA_OK;
  if (solid < s->solid_count && s->plans[solid]) {
    solid_plan *old = s->plans[solid];
    s->stats.tets -= old->stat_tets;
    s->stats.owned_nodes -= old->stat_owned;
    s->stats.shared_nodes -= old->stat_shared;
    plan_free(old);
    free(old);
    s->plans[solid] = NULL;
  }
  const double t0 = MPI_Wtime();
  plan_mesh m = {mesh->tets, mesh->tet_count, mesh->vertex_count};
  solid_plan *p;
  PIOLA_TRY(plan_agreed(s, solid, &m, &p));
  s->stats.replans++;
  s->stats.replan_seconds += MPI_Wtime() - t0;
  *out = &p->split;
  return PIOLA_OK;
}

piola_status piola_mpi_split_create(piola_mpi_split **out) {
  if (!out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "MPI split: NULL argument");
  piola_mpi_split *s = calloc(1, sizeof *s);
  *out = s;
  if (!s) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "MPI split: out of memory");
  MPI_Comm_rank(MPI_COMM_WORLD, &s->rank);
  MPI_Comm_size(MPI_COMM_WORLD, &s->size);
  s->stats.rank = s->rank;
  s->stats.size = s->size;
  return PIOLA_OK;
}

piola_work_split_planner piola_mpi_split_planner(piola_mpi_split *split) {
  return (piola_work_split_planner){split ? plan_added_solid : NULL, split};
}

piola_status piola_mpi_split_finish(piola_mpi_split *s, piola_world *world) {
  if (!s || !world) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "MPI split: NULL argument");
  piola_world_set_work_split_planner(world, NULL);
#ifdef PIOLA_PETSC
  const char *why = piola_world_split_unsupported_solving(world);
#else
  const char *why = piola_world_split_unsupported(world);
#endif
  if (why) return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED, "%s", why);
  const int32_t solids = piola_world_solid_count(world);
  for (int32_t i = 0; i < solids; ++i) {
    if (i < s->solid_count && s->plans[i]) continue; /* planned when it was added */
    const piola_elastic_body *body = piola_world_solid_body(world, i);
    plan_mesh m = {piola_elastic_body_tets(body), piola_elastic_body_tet_count(body),
                   piola_elastic_body_vertex_count(body)};
    solid_plan *p;
    PIOLA_TRY(plan_agreed(s, i, &m, &p));
    piola_status st = piola_world_solid_set_work_split(world, i, &p->split);
    int bad = st != PIOLA_OK, any = 0;
    MPI_Allreduce(&bad, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (any) return bad ? st : PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "MPI split: another process failed");
  }
  const piola_work_split_planner replanner = {replan_solid, s};
  piola_world_set_work_split_replanner(world, &replanner);
  return PIOLA_OK;
}

piola_status piola_mpi_split_world(piola_world *world, piola_mpi_split **out) {
  if (!world || !out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "MPI split: NULL argument");
  *out = NULL;
  piola_mpi_split *s;
  PIOLA_TRY(piola_mpi_split_create(&s));
  piola_status st = piola_mpi_split_finish(s, world);
  if (st != PIOLA_OK) {
    piola_mpi_split_destroy(s, world);
    return st;
  }
  *out = s;
  return PIOLA_OK;
}

piola_mpi_split_stats piola_mpi_split_stats_of(const piola_mpi_split *split) {
  piola_mpi_split_stats none = {0};
  return split ? split->stats : none;
}

void piola_mpi_split_destroy(piola_mpi_split *split, piola_world *world) {
  if (!split) return;
  if (world) piola_world_set_work_split_replanner(world, NULL);
  for (int32_t i = 0; i < split->solid_count; ++i) {
    if (!split->plans[i]) continue;
    if (world) (void)piola_world_solid_set_work_split(world, i, NULL);
    plan_free(split->plans[i]);
    free(split->plans[i]);
  }
  free(split->plans);
  free(split);
#ifdef PIOLA_PETSC
  piola__petsc_finish();
#endif
}
