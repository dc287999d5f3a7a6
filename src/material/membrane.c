/* Membrane (in-plane) models for shells: the public evaluation functions. The definition
 * (the solid model at unit thickness stretch with the plane-stress lambda) and why it was
 * chosen are in membrane_kernels.h and docs/shells.md. */
#include "material/membrane_kernels.h"
#include "piola/material.h"

void piola_membrane_stress(const piola_material *material, const double fhat[2], double phat[2]) {
  const piola_material membrane = membrane_material_from(material);
  membrane_stress_kernel(&membrane, fhat[0], fhat[1], &phat[0], &phat[1]);
}

double piola_membrane_energy_density(const piola_material *material, const double fhat[2]) {
  const piola_material membrane = membrane_material_from(material);
  double p0, p1, psi;
  membrane_stress_energy_kernel(&membrane, fhat[0], fhat[1], &p0, &p1, &psi);
  return psi;
}
