/* The scene parser's sections: one reader per concept of the format, each in its own file
 * (scene_parse_<section>.c) and built from the JSON walker in scene_json.h. The top level
 * (scene_parse.c) calls them in the format's order: world keys, shells, solids, obstacles,
 * bones. Each reads the value at the current key path (or obj.key where it takes a key) and
 * names the key path in every error. */
#ifndef PIOLA_SCENE_SCENE_PARSE_SECTIONS_H
#define PIOLA_SCENE_SCENE_PARSE_SECTIONS_H

#include "scene/scene_desc.h"
#include "scene/scene_json.h"

/* fps, frames, gravity and integrator at the top level (scene_parse_world.c). */
piola_status piola__scene_parse_world(scene_parser *p, const cJSON *obj, scene_desc *out);

/* The `solids` array; v may be NULL when the scene has shells (scene_parse_solid.c). */
piola_status piola__scene_parse_solids(scene_parser *p, const cJSON *v, scene_desc *out);

/* The `shells` array (scene_parse_shell.c). */
piola_status piola__scene_parse_shells(scene_parser *p, const cJSON *v, scene_desc *out);

/* The `obstacles` array (scene_parse_obstacle.c), and one obstacle or the obstacle part of a
 * bone: extra_keys (NULL-terminated, or NULL) are also allowed and left to the caller. */
piola_status piola__scene_parse_obstacles(scene_parser *p, const cJSON *v, scene_desc *out);
piola_status piola__scene_parse_obstacle(scene_parser *p, const cJSON *obj,
                                         const char *const *extra_keys, scene_obstacle_desc *d);

/* The `bones` array; solids must be parsed first (scene_parse_bone.c). */
piola_status piola__scene_parse_bones(scene_parser *p, const cJSON *v, scene_desc *out);

/* Keys solids and shells share (scene_parse_body_keys.c): name (also of bones: into a buffer
 * of capacity bytes), transform (v is its value), damping and self_collision (read from
 * obj). */
piola_status piola__scene_parse_name(scene_parser *p, const cJSON *obj, char *name,
                                     size_t capacity);
piola_status piola__scene_parse_transform(scene_parser *p, const cJSON *v, scene_solid_desc *d);
piola_status piola__scene_parse_damping(scene_parser *p, const cJSON *obj, scene_solid_desc *d);
piola_status piola__scene_parse_self_collision(scene_parser *p, const cJSON *obj,
                                               piola_self_collision_def *out);

/* A `material` object (scene_parse_material.c). */
piola_status piola__scene_parse_material(scene_parser *p, const cJSON *obj, scene_solid_desc *d);

/* A solid's `plasticity` object (scene_parse_plasticity.c). */
piola_status piola__scene_parse_plasticity(scene_parser *p, const cJSON *obj, scene_solid_desc *d);

/* A solid's `fracture` object (scene_parse_fracture.c); after self_collision is read. */
piola_status piola__scene_parse_fracture(scene_parser *p, const cJSON *obj, scene_solid_desc *d);

/* A solid's `fibers` object (scene_parse_fibers.c). */
piola_status piola__scene_parse_fibers(scene_parser *p, const cJSON *obj, scene_fibers *f);

/* A `motion` object; default_pivot and default_axis: where and about what the rotation turns
 * unless the scene says otherwise (scene_parse_motion.c). */
piola_status piola__scene_parse_motion(scene_parser *p, const cJSON *obj, piola_vec3 default_pivot,
                                       piola_vec3 default_axis, piola_rigid_motion_def *out);

/* Node selectors (scene_parse_constraints.c): one of box, sphere or indices, plus motion when
 * driven; the `fixed` or `driven` list of a solid or shell (key), appended to d->constraints. */
piola_status piola__scene_parse_selector(scene_parser *p, const cJSON *obj, int driven,
                                         piola_constraint_def *out, int32_t **indices_out);
piola_status piola__scene_parse_constraints(scene_parser *p, const cJSON *solid, const char *key,
                                            int driven, scene_solid_desc *d);

#endif
