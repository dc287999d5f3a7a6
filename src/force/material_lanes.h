/* Stress and energy density for the B tets of one block, from their diagonal Fhat.
 *
 * The models live in the materials module (one source of truth); this adapter only decides
 * how to call them for a block: when every lane uses the same material, one model for all
 * lanes; otherwise lane by lane. */
#ifndef PIOLA_FORCE_MATERIAL_LANES_H
#define PIOLA_FORCE_MATERIAL_LANES_H

#include "force/elastic_body_internal.h"
#include "piola/material.h"

static inline void piola__material_lanes(const piola_elastic_body *body, int32_t base,
                                         double fhat[3][PIOLA_TET_BLOCK],
                                         double phat[3][PIOLA_TET_BLOCK],
                                         double psi[PIOLA_TET_BLOCK]) {
  for (int l = 0; l < PIOLA_TET_BLOCK; ++l) {
    const piola_material *material = &body->materials[body->tet_material[base + l]];
    double fh[3] = {fhat[0][l], fhat[1][l], fhat[2][l]}, ph[3];
    piola_material_stress(material, fh, ph);
    psi[l] = piola_material_energy_density(material, fh);
    phat[0][l] = ph[0];
    phat[1][l] = ph[1];
    phat[2][l] = ph[2];
  }
}

#endif
