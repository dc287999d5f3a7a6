/* Triangle mesh core. */
#include <stdlib.h>
#include <string.h>

#include "piola/mesh.h"

void piola_tri_mesh_free(piola_tri_mesh *mesh) {
  if (!mesh) return;
  free(mesh->positions);
  free(mesh->triangles);
  memset(mesh, 0, sizeof *mesh);
}
