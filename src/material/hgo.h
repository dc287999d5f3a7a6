/* Internal entry of the Holzapfel-Gasser-Ogden model (hgo.c) used by piola_material_init. */
#ifndef PIOLA_MATERIAL_HGO_H
#define PIOLA_MATERIAL_HGO_H

#include "piola/material.h"
#include "piola/status.h"

/* The default parameters (piola_default_material_def fills them in). */
piola_hgo_def piola__default_hgo_def(void);

/* Validates def->hgo (errors name the key, e.g. "hgo.kappa"), stores it (axis normalised),
 * the matrix's mu and lambda (from poisson_ratio) and the fibres' rest stiffness bound in
 * out. Called for PIOLA_MODEL_HGO only. */
piola_status piola__hgo_init(const piola_material_def *def, piola_material *out);

#endif
