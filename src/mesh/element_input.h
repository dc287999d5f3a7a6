/* Checks shared by every element body (tetrahedral solids, triangle shells) on the input
 * they are built from, so both report bad input with the same messages:
 * at least one material and each one initialized by piola_material_init, finite rest
 * positions, corner indices in range, and per-element material indices in range.
 * body_name ("elastic body", "shell body") and element_name ("tet", "triangle") with its
 * corner count shape the messages, e.g. "tet 12 corner 3 refers to vertex 99, outside 0..40". */
#ifndef PIOLA_MESH_ELEMENT_INPUT_H
#define PIOLA_MESH_ELEMENT_INPUT_H

#include <stdint.h>

#include "piola/material.h"
#include "piola/status.h"

piola_status piola__check_element_input(const char *body_name, const char *element_name,
                                        int corners, int32_t vertex_count,
                                        const double *positions, int32_t element_count,
                                        const int32_t *elements, const piola_material *materials,
                                        int32_t material_count, const int32_t *element_materials);

#endif
