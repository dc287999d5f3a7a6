/* Internal entry of the muscle model (muscle.c) used by piola_material_init. */
#ifndef PIOLA_MATERIAL_MUSCLE_H
#define PIOLA_MATERIAL_MUSCLE_H

#include "piola/material.h"
#include "piola/status.h"

/* The default fibre parameters (piola_default_material_def fills them in). */
piola_muscle_def piola__default_muscle_def(void);

/* Validates def->muscle (errors name the key, e.g. "muscle.active_width") and stores it and
 * the fibre modulus in out. Called for PIOLA_MODEL_MUSCLE only. */
piola_status piola__muscle_init(const piola_material_def *def, piola_material *out);

#endif
