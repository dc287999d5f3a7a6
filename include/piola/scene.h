/* piola: scene files.
 *
 * A scene is a JSON file (docs/scene-format.md) describing the frame rate, the number of
 * frames, gravity, integrator settings, solids and obstacles. Loading validates every key:
 * an unknown key, a wrong type or an out-of-range value is an error whose message names the
 * key path, e.g. "scene.json: solids[0].material.poisson_ratio: must be in (-1, 0.5), got 0.7".
 * Loading also reads or generates the meshes and builds the world, so a scene that loads is
 * ready to run.
 *
 *   piola_scene *scene;
 *   if (piola_scene_load("scene.json", &scene) != PIOLA_OK) puts(piola_last_error());
 *   piola_world *world = piola_scene_world(scene);
 *   for (int f = 1; f <= piola_scene_frames(scene); ++f)
 *     piola_world_advance_to(world, f / piola_scene_fps(scene), NULL);
 *   piola_scene_destroy(scene); */
#ifndef PIOLA_SCENE_H
#define PIOLA_SCENE_H

#include <stdint.h>

#include "piola/export.h"
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

#ifdef __cplusplus
}
#endif

#endif
