/* piola: small fixed-size vector and matrix types of the public API.
 *
 * Plain structs of doubles, row-major: m[row][col]. Units are whatever the quantity
 * carries (positions in m, deformation gradients dimensionless, stresses in Pa). */
#ifndef PIOLA_MATH_TYPES_H
#define PIOLA_MATH_TYPES_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct piola_vec3 {
  double x, y, z;
} piola_vec3;

typedef struct piola_mat3 {
  double m[3][3];
} piola_mat3;

/* A 3x2 matrix: the deformation gradient of a triangle embedded in 3D. */
typedef struct piola_mat3x2 {
  double m[3][2];
} piola_mat3x2;

typedef struct piola_mat2 {
  double m[2][2];
} piola_mat2;

#ifdef __cplusplus
}
#endif

#endif
