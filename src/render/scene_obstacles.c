/* The obstacles (and bones) of a scene file, for drawing. Only the parser runs
 * (piola_scene_parse_file): solids' meshes are neither read nor generated, so a large scene's
 * preview costs nothing extra; mesh obstacles read their surface file, resolved against the
 * scene's folder. */
#include "common/status_report.h"
#include "piola/mesh_io.h"
#include "piola/scene.h"
#include "render/render_internal.h"

piola_status piola_renderer_load_scene_obstacles(piola_renderer *r, const char *path) {
  if (!r || !path) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "renderer: NULL argument");
  piola_scene_desc *desc;
  PIOLA_TRY(piola_scene_parse_file(path, &desc));
  /* bones are obstacles too (their attachments do not matter for drawing) */
  piola_status st = PIOLA_OK;
  for (int32_t i = 0; st == PIOLA_OK && i < piola_scene_desc_obstacle_count(desc); ++i) {
    const char *mesh_path;
    piola_obstacle_def def = piola_scene_desc_obstacle(desc, i, &mesh_path);
    piola_tri_mesh surface = {0};
    if (def.type == PIOLA_OBSTACLE_MESH) {
      st = piola_tri_mesh_read(mesh_path, &surface);
      def.mesh = &surface;
    }
    if (st == PIOLA_OK) st = piola_renderer_add_obstacle(r, &def);
    piola_tri_mesh_free(&surface);
  }
  piola_scene_desc_destroy(desc);
  return st;
}
