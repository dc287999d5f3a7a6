/* Scalar referees of the force and damping loops: the straightforward per-tet formulations
 * that the fast, blocked loops of src/force are checked against (tests) and timed against
 * (bench_forces). Test code, not part of the library. */
#ifndef PIOLA_TESTS_ELASTIC_REFEREES_H
#define PIOLA_TESTS_ELASTIC_REFEREES_H

#include "force/elastic_body_internal.h"

/* Scalar reference force loop for the tests: per tet F = Ds Dm^-1, the public
 * piola_diagonalize3, piola_material_stress and piola_material_energy_density, forces summed
 * serially. Writes forces and stats only; does not touch the stored per-tet state. */
piola_status piola__elastic_body_update_reference(const piola_elastic_body *body,
                                                  const double *x, double stiffness_scale,
                                                  double *forces, piola_elastic_stats *stats);

/* Scalar reference of the damping forces for the tests: the original per-tet
 * formulation (U, V and the projections recomputed per tet), summed serially. Reads the
 * state of the last update like piola_elastic_body_damping_forces. */
void piola__elastic_body_damping_reference(const piola_elastic_body *body, const double *v,
                                           double shear_viscosity, double bulk_viscosity,
                                           double *forces);

#endif
