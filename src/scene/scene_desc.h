/* A parsed scene, before any mesh is read: the definition structs of the world, its solids
 * and obstacles, plus where each mesh comes from and how it is placed.
 *
 * Parsing (scene_parse*.c) and building (scene_build.c) are split so that every syntactic
 * and range error is found, with its key path, before any file is opened, and so the
 * parser can be tested alone. */
#ifndef PIOLA_SCENE_SCENE_DESC_H
#define PIOLA_SCENE_SCENE_DESC_H

#include <stdint.h>

#include "piola/mesher.h"
#include "piola/obstacle.h"
#include "piola/work_split.h"
#include "piola/world.h"
#include "piola/world_bones.h"
#include "piola/world_fracture.h"
#include "piola/world_shells.h"

#define SCENE_PATH_MAX 4096

/* A solid's `fibers` key: a direction field in scene (world) coordinates. */
typedef enum scene_fiber_kind {
  SCENE_FIBERS_NONE = 0,
  SCENE_FIBERS_AXIS,      /* one direction for every tet */
  SCENE_FIBERS_CURVE,     /* polyline: the tangent of the segment nearest each tet's centroid */
  SCENE_FIBERS_FROM_MESH, /* per-tet data read with the mesh */
  SCENE_FIBERS_AROUND,    /* circumferential about a line: axis x (centroid - point) */
} scene_fiber_kind;

typedef struct scene_fibers {
  scene_fiber_kind kind;
  piola_vec3 axis;        /* SCENE_FIBERS_AXIS, SCENE_FIBERS_AROUND: unit */
  piola_vec3 point;       /* SCENE_FIBERS_AROUND: a point of the line (m) */
  double *curve;          /* SCENE_FIBERS_CURVE: 3 per point, owned */
  int32_t curve_points;   /* >= 2 */
} scene_fibers;

typedef struct scene_solid_desc {
  piola_solid_def def;            /* mesh, name and constraints are filled in by the builder */
  char name[128];
  int mesh_generated;             /* 1: mesher, 0: file */
  char mesh_path[SCENE_PATH_MAX]; /* resolved against the scene's folder */
  piola_mesher_def mesher;
  piola_vec3 translate;           /* m */
  piola_vec3 rotate_degrees;      /* XYZ Euler angles, degrees */
  piola_vec3 scale;               /* per axis */
  piola_constraint_def *constraints;
  int32_t constraint_count;
  int32_t fixed_count;            /* constraints[0, fixed_count) come from `fixed`, the rest
                                     from `driven` */
  int32_t **index_lists;          /* owned index arrays, one per constraint (or NULL) */
  int plastic;                    /* 1: "plasticity" given */
  piola_plasticity_def plasticity;
  char goal_mesh_path[SCENE_PATH_MAX]; /* plasticity.control.goal.mesh, resolved */
  scene_fibers fibers;            /* `fibers` (muscle), turned into per-tet directions by the
                                     builder (scene_fibers.c) */
  int fractures;                  /* 1: "fracture" given */
  piola_fracture_def fracture;    /* its cuts point at fracture_cuts */
  piola_fracture_cut *fracture_cuts; /* owned */
  char (*fracture_blade_paths)[SCENE_PATH_MAX]; /* owned, per cut: its "mesh" resolved, "" for
                                     a plane */
} scene_solid_desc;

/* A shell: the solid fields it shares (name, transform, density, material, damping,
 * velocity, fixed, driven; base.def is not used for the mesh) plus its own. */
typedef struct scene_shell_desc {
  scene_solid_desc base;
  piola_shell_def def;            /* thickness, bending, plasticity, reference normals */
  int generator;                  /* 0 file (base.mesh_path), 1 rectangle, 2 disk, 3 torus */
  double size[2];                 /* rectangle: m */
  int32_t resolution[2];          /* rectangle: cells; disk: rings in [0]; torus: segments */
  double radius;                  /* disk, torus: m */
  double minor_radius;            /* torus: m */
  double sweep_degrees;           /* torus */
} scene_shell_desc;

typedef struct scene_obstacle_desc {
  piola_obstacle_def def;
  char name[128];                 /* `name` of an obstacle (default obstacle<i>); bones keep
                                     theirs in scene_bone_desc */
  char mesh_path[SCENE_PATH_MAX]; /* mesh obstacles */
} scene_obstacle_desc;

/* A bone (docs/bones.md): an obstacle's shape, friction and motion plus attachments; the
 * attachments' solid indices are resolved from their names while parsing. */
typedef struct scene_bone_desc {
  scene_obstacle_desc obstacle;
  char name[128];
  piola_attachment_def *attachments;
  int32_t attachment_count;
  int32_t **index_lists;          /* owned index arrays, one per attachment (or NULL) */
} scene_bone_desc;

typedef struct scene_desc {
  double fps;
  int32_t frames;
  piola_world_def world;
  scene_solid_desc *solids;
  int32_t solid_count;
  scene_obstacle_desc *obstacles;
  int32_t obstacle_count;
  scene_shell_desc *shells;       /* the `shells` key (scene_parse_shell.c) */
  int32_t shell_count;
  scene_bone_desc *bones;         /* the `bones` key (scene_parse_bone.c) */
  int32_t bone_count;
  /* the integrator keys the scene sets that its integrator does not use, as
   * "integrator.dt, integrator.newton_tolerance" ("" for none; scene_parse_world.c): the
   * build raises PIOLA_WARNING_IGNORED_KEYS with them */
  char ignored_integrator_keys[320];
} scene_desc;

/* The folder of a file path: "." for a bare name, "/" for a file in the root (scene.c). */
void piola__scene_folder(const char *path, char dir[SCENE_PATH_MAX]);

/* Parses and validates JSON text; label prefixes error messages. */
piola_status piola__scene_parse(const char *json, const char *base_dir, const char *label,
                                scene_desc *out);
void piola__scene_desc_free(scene_desc *desc);

/* Reads the goal mesh of a controlled plastic solid and places it like the solid; it must
 * have the rest mesh's vertices and tets (scene_build.c). */
piola_status piola__scene_read_goal_mesh(const scene_solid_desc *d, const piola_tet_mesh *rest,
                                         piola_tet_mesh *goal);

/* Per-tet fibre directions (3 per tet, malloc'd into *out; NULL when the solid has no
 * `fibers`) for the placed rest mesh (scene_fibers.c). Errors name the key. */
piola_status piola__scene_fiber_directions(const scene_fibers *fibers, const piola_tet_mesh *mesh,
                                           double **out);

/* Reads or generates the meshes, places them and builds the world. */
piola_status piola__scene_build(const scene_desc *desc, const char *label,
                                const piola_work_split_planner *planner, piola_world **out);

/* Refuses a scene text whose strings hold the escape \u0000 (scene_text_check.c): it would
 * cut a path short. */
piola_status piola__scene_check_text(const char *json, const char *label);

#endif
