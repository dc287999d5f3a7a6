/* The deformed state the force-loop benchmarks time (bench_forces, bench_material_models), so
 * that their numbers compare. */
#ifndef PIOLA_BENCH_DEFORM_H
#define PIOLA_BENCH_DEFORM_H

#include "piola/elastic_body.h"

/* Positions (malloc'd, 3 per vertex): rest + noise (1% of the mean edge), then ~1% of tets
 * get corner 0 mirrored through the plane of corners 1..3, so a few percent of tets are
 * inverted, as in a simulation recovering from collisions. Uses bench_uniform's sequence. */
double *bench_deformed_positions(const piola_elastic_body *body);

#endif
