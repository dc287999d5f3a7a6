/* piola: scene files (the piola_scene library, on top of the core).
 *
 * A scene is a JSON file (docs/scene-format.md) describing the frame rate, the number of
 * frames, gravity, integrator settings, solids, shells, obstacles and bones. Loading
 * validates every key: an unknown key, a wrong type or an out-of-range value is an error
 * whose message names the key path, e.g.
 * "scene.json: solids[0].material.poisson_ratio: must be in (-1, 0.5), got 0.7".
 * Loading also reads or generates the meshes and builds the world, so a scene that loads is
 * ready to run.
 *
 *   piola_scene *scene;
 *   if (piola_scene_load("scene.json", &scene) != PIOLA_OK) puts(piola_last_error());
 *   piola_world *world = piola_scene_world(scene);
 *   for (int f = 1; f <= piola_scene_frames(scene); ++f)
 *     piola_world_advance_to(world, f / piola_scene_fps(scene), NULL);
 *   piola_scene_destroy(scene);
 *
 * Loading is two stages, also available apart: parsing (every syntactic and range error,
 * no mesh file opened) gives a piola_scene_desc that can be inspected (a renderer reads a
 * scene's obstacles and materials this way without meshing its solids), then building reads
 * or generates the meshes and creates the world. */
#ifndef PIOLA_SCENE_H
#define PIOLA_SCENE_H

#include <stdbool.h>
#include <stdint.h>

#include "piola/export.h"
#include "piola/material.h"
#include "piola/obstacle.h"
#include "piola/status.h"
#include "piola/world.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct piola_scene piola_scene;

/* Reads, validates and builds the scene in the file at path. Mesh paths are relative to the
 * scene file's folder. */
PIOLA_API piola_status piola_scene_load(const char *path, piola_scene **out);
/* The same from JSON text; relative mesh paths are taken from base_dir (NULL: "."), and
 * error messages start with label (NULL: "scene"). */
PIOLA_API piola_status piola_scene_load_string(const char *json, const char *base_dir,
                                               const char *label, piola_scene **out);
PIOLA_API void piola_scene_destroy(piola_scene *scene);

PIOLA_API double piola_scene_fps(const piola_scene *scene);     /* frames per second of output */
PIOLA_API int32_t piola_scene_frames(const piola_scene *scene); /* frames to write after frame 0 */
PIOLA_API piola_world *piola_scene_world(piola_scene *scene);

/* ---------------------------------------------------------------- the two stages */

/* A parsed and validated scene whose meshes are not read yet. */
typedef struct piola_scene_desc piola_scene_desc;

/* Parses and validates the scene file at path (no mesh is opened); mesh paths are resolved
 * against the file's folder. */
PIOLA_API piola_status piola_scene_parse_file(const char *path, piola_scene_desc **out);
/* The same from JSON text, as piola_scene_load_string. */
PIOLA_API piola_status piola_scene_parse_string(const char *json, const char *base_dir,
                                                const char *label, piola_scene_desc **out);
PIOLA_API void piola_scene_desc_destroy(piola_scene_desc *desc);

/* Reads or generates the meshes, places them and builds the world; desc is not changed and
 * may be built again. Errors start with the label given when parsing. */
PIOLA_API piola_status piola_scene_build(const piola_scene_desc *desc, piola_scene **out);

PIOLA_API double piola_scene_desc_fps(const piola_scene_desc *desc);
PIOLA_API int32_t piola_scene_desc_frames(const piola_scene_desc *desc);
PIOLA_API int32_t piola_scene_desc_solid_count(const piola_scene_desc *desc);
/* Solid i's name and material (0 <= i < solid_count; another i gives NULL and a zeroed
 * material). */
PIOLA_API const char *piola_scene_desc_solid_name(const piola_scene_desc *desc, int32_t i);
PIOLA_API piola_material_def piola_scene_desc_solid_material(const piola_scene_desc *desc,
                                                             int32_t i);
/* Obstacles, then the shapes of the bones (whose attachments are left out). */
PIOLA_API int32_t piola_scene_desc_obstacle_count(const piola_scene_desc *desc);
/* Obstacle i's definition (0 <= i < obstacle_count); for a mesh obstacle, def.mesh is NULL
 * and *mesh_path (when not NULL) receives its resolved surface file, else "". Another i
 * gives a zeroed definition and a NULL *mesh_path. */
PIOLA_API piola_obstacle_def piola_scene_desc_obstacle(const piola_scene_desc *desc, int32_t i,
                                                       const char **mesh_path);

/* Obstacle i's `name` (default "obstacle<i>"), or for a bone (i >= the number of
 * obstacles) the bone's name; NULL for an i out of range. Valid while desc lives. */
PIOLA_API const char *piola_scene_desc_obstacle_name(const piola_scene_desc *desc, int32_t i);
/* Whether entry i of the obstacle list is a bone's shape (false out of range). */
PIOLA_API bool piola_scene_desc_obstacle_is_bone(const piola_scene_desc *desc, int32_t i);
/* The scene's gravity (m/s^2) at time t (s). */
PIOLA_API piola_vec3 piola_scene_desc_gravity(const piola_scene_desc *desc, double t);

/* Writes the scene file at scene_path to out_path (whole or not at all) with every mesh path
 * of solids, shells, obstacles, bones and plastic goals made absolute, so the copy reads the
 * same meshes from any folder. The copy is not validated beyond being JSON. */
PIOLA_API piola_status piola_scene_copy_resolved(const char *scene_path, const char *out_path);

/* A key (FNV-1a 64) of the files the scene at scene_path names: the meshes of solids,
 * shells, obstacles and bones, plastic goal meshes and fracture cut meshes, each by its
 * resolved path and its bytes, in the scene's order. `piola run` folds it into its
 * checkpoints' scene key, so that --resume refuses a run whose obstacle or goal mesh has
 * been edited since (file-formats.md, "Checkpoints"). */
PIOLA_API piola_status piola_scene_inputs_key(const char *scene_path, uint64_t *key);

#ifdef __cplusplus
}
#endif

#endif
