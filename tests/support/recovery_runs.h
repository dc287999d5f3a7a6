/* Recovery runs shared by bench/bench_scramble_recovery, bench/bench_collapse_recovery and
 * tests/test_default_inversion.c: a body started scrambled or collapsed, left to its elastic
 * and damping forces, judged against its rest shape. No cmocka here: the benchmarks link it.
 *
 * Two protocols:
 *   - the scramble grid (docs/materials.md, "Tangled equilibria"): the 3 x 3 x 3 grid of unit
 *     size (162 tets), every node at a uniformly random point of the unit cube (seed s), 12 s
 *     with beta = 300, alpha = 100 Pa s and a fixed step (a fraction of the rest CFL step;
 *     for HGO, whose fibres stiffen exponentially, capped by half the state-aware bound);
 *   - collapse of a real mesh scaled to a 1 m bounding box (as tests/test_recovery_real_meshes.c):
 *     every vertex to one point, onto a line or onto a plane, 12 s with beta = 1000,
 *     alpha = 300 Pa s and a step shortened with the body's largest stretch. */
#ifndef PIOLA_TESTS_RECOVERY_RUNS_H
#define PIOLA_TESTS_RECOVERY_RUNS_H

#include <stdint.h>

#include "piola/material.h"
#include "piola/mesh.h"

typedef enum recovery_result {
  RECOVERY_RECOVERED,       /* at rest shape (criteria in recovery_runs.c) */
  RECOVERY_SLOW,            /* not yet, but the elastic energy is below 1e-3 J */
  RECOVERY_STUCK_MODEL,     /* stuck with every Fhat entry at or above the threshold */
  RECOVERY_STUCK_EXTENSION, /* stuck with some entry below the threshold */
  RECOVERY_DIVERGED,        /* a position or force stopped being finite */
  RECOVERY_RESULT_COUNT
} recovery_result;

extern const char *const recovery_result_names[RECOVERY_RESULT_COUNT];

/* The material of both protocols for `model`: E = 10 kPa, nu = 0.3; the models with their own
 * moduli (mooney_rivlin, ogden, hgo) get their default parameters scaled to the same rest
 * shear modulus (3846 Pa), hgo's k1 with it; the muscle's fibre moduli are scaled by 0.1 (its
 * defaults suit E = 100 kPa). Inversion mode and threshold are left at the model's default. */
piola_material_def recovery_material_def(piola_material_model model);

/* The grid of the scramble protocol (caller frees with piola_tet_mesh_free). */
int recovery_grid(piola_tet_mesh *mesh);

/* Simulated time of a scramble run (s): 12, the tables' protocol; bench_scramble_recovery
 * takes a longer one to tell a slow recovery from a stuck one. */
extern double recovery_scramble_seconds;

/* An experiment of docs/materials.md ("Defaults that recover"), off unless levels >= 2: a
 * threshold that rises as an element loses volume. Each tet takes, for each update, the
 * material's threshold raised towards high: by the J of the previous update, from the
 * material's own threshold at J >= j_high to `high` at J <= j_low, in `levels` steps (the
 * body holds one material per step). A piecewise-constant, one-step-lagged stand-in for a
 * threshold that depends on J, to measure whether one would recover more scrambles. */
typedef struct recovery_volume_threshold {
  int levels;
  double high, j_low, j_high;
} recovery_volume_threshold;
extern recovery_volume_threshold recovery_threshold_by_volume;

/* Runs seed `seed` of the scramble protocol on `mesh` (the grid) with `material`. */
recovery_result recovery_scramble_run(const piola_tet_mesh *mesh, const piola_material *material,
                                      int seed);

typedef enum recovery_collapse_kind { COLLAPSE_TO_POINT, COLLAPSE_TO_LINE, COLLAPSE_TO_PLANE } recovery_collapse_kind;
extern const char *const recovery_collapse_names[3];

/* Reads a file of ../shared/data (path relative to it), centred with largest side 1 m.
 * Returns 0 on success (else the message is piola_last_error()). */
int recovery_read_unit_mesh(const char *data_dir, const char *relative, piola_tet_mesh *mesh);

typedef struct recovery_collapse_outcome {
  recovery_result result;
  double position_error; /* m, after the best rigid alignment onto the rest positions */
  double fhat_error;     /* max |fhat - 1| */
  int32_t inverted;      /* inverted tets at the end */
  int steps;
  double start_energy, end_energy; /* J: elastic energy of the collapsed start and at the end */
} recovery_collapse_outcome;

/* Simulated time of a collapse run (s): 12, the protocol's; a test may take a shorter one. */
extern double recovery_collapse_seconds;

/* Collapses `mesh` (a unit mesh) and runs the collapse protocol with `material`. Recovered:
 * position error <= 1e-3 m, max |fhat - 1| <= 1e-3, nothing inverted. */
recovery_collapse_outcome recovery_collapse_run(const piola_tet_mesh *mesh,
                                                const piola_material *material,
                                                recovery_collapse_kind kind);

/* Largest distance (m) between x, optimally rotated and translated, and rest: mass-weighted
 * centroids, and the rotation R maximizing sum m (x - cx) . R^T (rest - cr) from the
 * invertible diagonalization of the cross-covariance H = sum m (rest - cr)(x - cx)^T =
 * U S V^T, R = U V^T, which is proper (det +1) as a rigid motion is (a mirror image is not).
 * INFINITY if H cannot be diagonalized. */
double recovery_procrustes_error(const double *x, const double *rest, const double *mass,
                                 int32_t nv);

#endif
