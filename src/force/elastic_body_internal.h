/* The elastic body's internal layout, shared by the rest state, the force loops and damping.
 *
 * Why it looks like this. The force loop is the hottest code in piola: every time step
 * evaluates F, its diagonalization, the stress and the nodal forces of every tet, and the
 * damping force is evaluated again inside every conjugate-gradient iteration. So the data it
 * reads per tet is kept in structure-of-arrays form (one array per matrix entry: Dm^-1 as 9
 * arrays, the rotations U and V as 9 arrays each), padded to a multiple of
 * PIOLA_TET_BLOCK tets. A block of PIOLA_TET_BLOCK consecutive tets is one set of SIMD lanes
 * (8 doubles = one AVX-512 register): entry k of the tets of a block sits in consecutive
 * memory, so loads and stores are plain vector moves and the compiler can vectorize the
 * straight-line per-tet math across the block. Bm = -V0 Dm^-T is not stored: it is the same
 * 9 numbers as Dm^-1 times -V0, and reading 8 fewer doubles per tet is worth more than the
 * 9 multiplies it costs. Cold data (rest positions, masses, the public AoS copy of the tets)
 * lives apart and the loop never touches it.
 *
 * Determinism. The force loop splits the tets into PIOLA_FORCE_CHUNKS fixed ranges of
 * blocks (whatever the thread count); each range adds its tets' forces in tet order into its
 * own per-vertex array (chunk_forces), and the arrays
 * are added in range order. Each sum has a fixed order and no two threads write the same
 * place, so forces are bit-for-bit identical for any thread count, without atomics.
 * Statistics are summed per block and then serially over blocks for the same reason.
 * Within a range, blocks go through the loop in pairs whose SVDs are interleaved (see
 * piola_svd8 in svd_kernel.h); the pairing depends only on the range, and the paired SVD
 * gives exactly the single one's bits, so it changes nothing either.
 *
 * The energy density is computed only when asked for (stats or the getter): stepping needs
 * forces, not energy, and the energy goes through the (scalar) public material function.
 *
 * Padding tets (the tail of the last block) have Dm^-1 = 0 and V0 = 0 and point at vertex 0:
 * F = 0, forces 0, and they are excluded from statistics. */
#ifndef PIOLA_FORCE_ELASTIC_BODY_INTERNAL_H
#define PIOLA_FORCE_ELASTIC_BODY_INTERNAL_H

#include <stdint.h>

#include "common/isa.h"
#include "force/damping_matrix.h"
#include "piola/elastic_body.h"
#include "piola/threads.h"
#include "piola/work_split.h"

#define PIOLA_TET_BLOCK 8

/* Below these sizes the loops run on one thread: a parallel region costs microseconds (much
 * more when the machine is oversubscribed and a thread waits for its time slice), more than
 * the work of a small body. Results do not depend on it (see Determinism above). */
#define PIOLA_PARALLEL_MIN_BLOCKS 256
#define PIOLA_PARALLEL_MIN_VERTICES 4096

struct piola_elastic_body {
  /* sizes */
  int32_t vertex_count;
  int32_t tet_count;
  int32_t padded_tet_count; /* multiple of PIOLA_TET_BLOCK */

  /* hot, per padded tet (SoA) */
  int32_t *tet_vertices[4]; /* vertex index of each corner */
  double *dm_inv[9];        /* Dm^-1, row-major entry k = 3 * row + col */
  double *rest_volume;      /* V0, m^3 */
  int32_t *tet_material;    /* material index */

  /* per padded tet state from the last update (SoA) */
  double *u[9];             /* u[k] = u[0] + k * padded_tet_count: one allocation, so the
                               SVD kernel writes all 9 entries with one stride */
  double *v[9];
  double *fhat;             /* 3 per tet, AoS (public) */
  double *det_f;
  double *energy_density;

  /* per block statistics scratch */
  double *block_energy;
  int32_t *block_inverted;
  double *block_min_det;

  /* muscle fibres (fiber_lanes.c): unit direction in rest space per padded tet (SoA, padding
   * tets 0), or all NULL when the body has none; the AoS public copy; the activation */
  double *fiber[3];
  double *fiber_aos;
  double activation;

  /* materials */
  piola_material *materials;
  int32_t material_count;
  int32_t uniform_material; /* index used by every tet, or -1 when they differ */

  /* cold */
  int32_t *tets;            /* 4 * tet_count, public AoS copy after reorientation */
  double *rest_positions;   /* 3 * vertex_count */
  double *masses;           /* vertex_count */
  double *positions;        /* 3 * vertex_count: x of the last update (damping needs it) */
  double density;
  double min_rest_altitude;
  double max_wave_speed;
  int has_state;            /* an update has run: U, V are valid */
  int energy_valid;         /* energy_density matches the last update (it is computed only
                               when stats are requested, or lazily by the getter) */
  double last_stiffness_scale;
  int signed_twist;         /* 1: the implicit assembly keeps the sign of the rotation
                               eigenvalues (PIOLA_STIFFNESS_SIGNED_TWIST, element_stiffness.h;
                               implicit_step.c sets it for Newton's tail), 0: projected */

  double *step_weight;      /* per tet 1 / (rho h_e^2), m/kg: the step bound's geometric factor
                               (stable_step.c), built on first use */
  double *step_gram;        /* 6 * tet_count: per tet the rest sum_c g_c g_c^T (m^-2) the bound's
                               direction weights read (stable_step_anisotropy.h), built with it */
  double *ogden_cache;      /* Ogden and Mooney-Rivlin bodies of one material: the step bound's
                               slots, OGDEN_CACHE_SLOTS * padded_tet_count (material_kernels.h),
                               written by the force loop for the blocks step_cache does not
                               hold (material_lanes.h); NULL for the other bodies */
  double *step_cache;       /* bodies of one material whose model forms the step bound's k in
                               the force loop (STEP_CACHE_MODEL, not the energy extension):
                               STEP_CACHE_SLOTS per block (stable_step_modulus.h), written by
                               the force loop; NULL for the other bodies */
  uint64_t step_generation; /* raised by each update and refill of a body with step_cache: the
                               key of the blocks that update formed */
  double *hgo_cache;        /* HGO bodies of one material with fibres: the step bound's fibre
                               term, HGO_CACHE_SLOTS * padded_tet_count (hgo_kernels.h), written
                               by the force loop; NULL for the other bodies */

  double *chunk_forces; /* PIOLA_FORCE_CHUNKS * 3 * vertex_count partial sums of the force loop */

  /* damping (damping.c): the operator as a sparse matrix, assembled from the last update by
   * the first damping call after it (the update clears damping.ready) */
  piola__damping_matrix damping;

  /* work split among processes (piola/work_split.h, work_split.c), or NULL: this process's
   * blocks in increasing order; in the replicated mode the exchange buffer of the per-tet
   * state, in the local mode the blocks whose state this process holds (own and ghost) */
  const piola_work_split *split;
  int32_t *split_blocks;
  int32_t split_block_count;
  double *split_buffer; /* replicated: block count * SPLIT_STATE_WIDTH_MAX doubles */
  int split_local;      /* the local mode */
  uint8_t *split_held;  /* local: per block, 1 for own and ghost blocks */
  int split_partial;    /* a local split dropped the other blocks' rest data (for good) */
  int state_unwritten;  /* built for a split: U, V, Fhat, det F not written yet */
  int rest_localized;   /* the other blocks' Dm^-1 and damping slots are dropped */
};

/* The split of a body in the local mode with more than one process, or NULL. */
static inline const piola_work_split *piola__local_split(const piola_elastic_body *body) {
  return body->split && body->split_local && body->split->part_count > 1 ? body->split : NULL;
}

/* The body's elastic energy at its last update, sum of V0 psi (J) (elastic_body.c).
 * Collective on a split in the local mode. */
double piola__elastic_body_total_energy(const piola_elastic_body *body);

/* piola_elastic_body_set_work_split, with the local mode allowed or not (the world forbids
 * it for solids with plasticity). */
piola_status piola__elastic_body_set_work_split(piola_elastic_body *body,
                                                const piola_work_split *split, int allow_local);

/* A range [k0, k1) of the force loop's blocks (block indices, or positions in a block list),
 * forces added into out in tet order. */
typedef void piola__block_range_update(piola_elastic_body *body, const double *x,
                                       double stiffness_scale, int want_energy, int32_t k0,
                                       int32_t k1, double *out);
/* forces = the sum of update over blocks [0, count) (elastic_body.c): in parallel as
 * PIOLA_FORCE_CHUNKS fixed ranges, each summed into its own array, the arrays added in
 * range order, so which thread runs a range changes nothing. */
void piola__elastic_body_sum_block_ranges(piola_elastic_body *body, const double *x,
                                          double stiffness_scale, int want_energy,
                                          int32_t count, piola__block_range_update *update,
                                          double *forces);
/* The split force loop and damping product (work_split.c). */
void piola__elastic_body_split_update(piola_elastic_body *body, const double *x,
                                      double stiffness_scale, int want_energy, double *forces);
void piola__elastic_body_split_free(piola_elastic_body *body);
/* Local mode: every block's Fhat, det F and energy density onto process 0 (collective). */
void piola__elastic_body_split_collect(piola_elastic_body *body);
/* Local mode: the ghost blocks' Fhat from their owners (collective), which the stiffness
 * assembly reads with the U and V the update shares; nothing otherwise. */
void piola__elastic_body_split_share_fhat(piola_elastic_body *body);
/* One or two consecutive blocks of the force loop from first, forces added into out in tet
 * order (force_lanes.c, a kernel built once per instruction set, common/isa.h; the plain
 * name runs the chosen variant). */
#define PIOLA_UPDATE_BLOCK_PAIR_PARAMS                                                        \
  (piola_elastic_body * body, const double *x, double stiffness_scale, int want_energy,      \
   int32_t first, int count, double *out)
PIOLA_ISA_DECLARE(void, piola__elastic_body_update_block_pair, PIOLA_UPDATE_BLOCK_PAIR_PARAMS);
void piola__elastic_body_update_block_pair PIOLA_UPDATE_BLOCK_PAIR_PARAMS;

/* Frees the caches only the explicit step bound reads (step_cache, ogden_cache, hgo_cache):
 * a world with an implicit integrator never computes that bound (piola_world_stable_dt), so
 * its force evaluations need not form them. The stress is the same without them. */
void piola__elastic_body_drop_step_caches(piola_elastic_body *body);

/* Refills the step bound's k cache (stable_step_modulus.h) from the stored Fhat with the
 * force loop's own kernels, blocks in the force loop's pairs: after a checkpoint restores Fhat
 * without an update, the bound then reads the bits the uninterrupted run's force loop stored
 * (force_lanes.c; the plain name runs the chosen variant). It raises step_generation first,
 * so that no block of an earlier state is read, and without a state refills nothing. Call it
 * after the step weights are restored. No-op without the cache. */
#define PIOLA_REFILL_STEP_CACHE_PARAMS (piola_elastic_body * body)
PIOLA_ISA_DECLARE(void, piola__elastic_body_refill_step_cache, PIOLA_REFILL_STEP_CACHE_PARAMS);
void piola__elastic_body_refill_step_cache PIOLA_REFILL_STEP_CACHE_PARAMS;

/* Bodies of at least PIOLA_PARALLEL_MIN_BLOCKS blocks sum their elastic forces in this many
 * fixed tet ranges (each its own partial sum), whatever the thread count. */
#define PIOLA_FORCE_CHUNKS 4

/* Builds the rest state of body from def (rest_state.c): validates def, reorients, fills
 * the SoA arrays, masses, incidence, altitude and wave speed. body must be zeroed. Without
 * write_state the per-tet state (U, V, Fhat, det F) is left unwritten (zero, its pages not
 * mapped) for piola__elastic_body_rest_rotations to fill. */
piola_status piola__elastic_body_build_rest_state(piola_elastic_body *body,
                                                  const piola_elastic_body_def *def,
                                                  int write_state);
/* The rest state's U = V = I, Fhat = (1, 1, 1), det F = 1, on the blocks with held[b] set
 * (every block for NULL). */
void piola__elastic_body_rest_rotations(piola_elastic_body *body, const uint8_t *held);
/* A body built for a split known before its first update: its per-tet state is written for
 * its own and ghost blocks only, never for the others (docs/mpi.md), then the split is set
 * (piola__elastic_body_set_work_split). */
piola_status piola__elastic_body_create_split(const piola_elastic_body_def *def,
                                              const piola_work_split *split,
                                              piola_elastic_body **out);
/* Local mode: drops the rest data of the blocks this process does not hold (Dm^-1, the
 * damping matrix's tet slots), once whatever reads every tet's Dm^-1 at setup (the step
 * bound's weights, the sliver check) has run. Nothing to do for other bodies. */
piola_status piola__elastic_body_split_localize_rest(piola_elastic_body *body);

/* Frees everything body owns (not body itself). */
void piola__elastic_body_free_arrays(piola_elastic_body *body);

/* Assembles the damping matrix from the last update with these viscosities (Pa s), unless
 * that has been done already (damping.c). The damping calls do it themselves; the step loop
 * calls it apart so its cost can be timed. */
void piola__elastic_body_damping_prepare(piola_elastic_body *body, double shear_viscosity,
                                         double bulk_viscosity);

/* The implicit step's operator out = M v - h D v (3 * vertex_count), D the damping of
 * piola_elastic_body_damping_forces, mass the lumped masses (vertex_count, kg), h in s: the
 * same numbers as forming it from the damping forces, without a separate pass (damping.c). */
void piola__elastic_body_damping_operator(const piola_elastic_body *body, const double *v,
                                          double shear_viscosity, double bulk_viscosity,
                                          const double *mass, double h, double *out);

/* forces += scale D v for a v that is zero on all but a few vertices: only the edges
 * touching a vertex with nonzero v are visited, serially, in vertex order (damping.c). For
 * correcting a product already taken at a nearby v (the step's second right-hand side). */
void piola__elastic_body_damping_forces_add_sparse(const piola_elastic_body *body, const double *v,
                                                   double shear_viscosity, double bulk_viscosity,
                                                   double scale, double *forces);

/* piola_thread_count, the number of threads a parallel loop should use, is in
 * piola/threads.h (included above). */

#endif
