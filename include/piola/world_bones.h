/* piola: bones: key-framed rigid bodies that carry regions of solids and push the rest away.
 *
 * A bone is the composition of two things the world already has (docs/bones.md):
 *  - an obstacle (piola/obstacle.h) with the bone's shape, friction and rigid motion, so
 *    every node of every solid that is not attached to the bone is kept out of it by the
 *    collision processing of paper section 9;
 *  - driven constraints (piola/world.h) with the same motion on the attached nodes: an
 *    attached node with rest position X is at x(t) = R(t) X + c(t), the bone's own pose at
 *    time t, exactly. Attached nodes are not free, so the bone never projects them.
 * The validated motion of the obstacle (its axis normalized) is the one the attached nodes
 * use, so nodes and bone surface cannot drift apart by rounding.
 *
 * Attachments are chosen over a solid's rest positions: by a selector (box, sphere or
 * indices, as for constraints), or by distance to the bone's shape before its motion
 * ("every node within 5 mm of the bone, or inside it"). A node attached by a later
 * attachment or bone is driven by that one. Attach bones at time 0: a node attached later
 * jumps to where the bone carries its rest position.
 *
 *   piola_bone_def bone = piola_default_bone_def();
 *   bone.shape.type = PIOLA_OBSTACLE_CAPSULE;      // shape in the rest frame, m
 *   bone.shape.center = (piola_vec3){0.15, 0, 0};
 *   bone.shape.axis = (piola_vec3){1, 0, 0};
 *   bone.shape.radius = 0.02, bone.shape.half_length = 0.1;
 *   bone.shape.motion.kind = PIOLA_MOTION_POSE;    // elbow: angle keys about a pivot
 *   bone.shape.motion.pivot = (piola_vec3){0, 0, 0};
 *   bone.shape.motion.axis = (piola_vec3){0, 1, 0};
 *   piola_track_from_keys(times, angles, 3, &bone.shape.motion.angle);
 *   piola_attachment_def at = piola_default_attachment_def();
 *   at.solid = 0, at.near_surface = true, at.distance = 0.005;
 *   bone.attachments = &at, bone.attachment_count = 1;
 *   piola_world_add_bone(world, &bone, NULL); */
#ifndef PIOLA_WORLD_BONES_H
#define PIOLA_WORLD_BONES_H

#include <stdbool.h>
#include <stdint.h>

#include "piola/export.h"
#include "piola/obstacle.h"
#include "piola/status.h"
#include "piola/world.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Which nodes of one solid a bone carries. */
typedef struct piola_attachment_def {
  int32_t solid;           /* index of a solid already in the world. Default 0 */
  bool near_surface;       /* true: nodes whose rest position is inside the bone's shape (before
                              its motion) or within `distance` of its surface; false: the
                              nodes `selector` picks. Default false */
  double distance;         /* m, >= 0, used with near_surface. Default 0 */
  piola_selector selector; /* box, sphere or indices over rest positions (m). Default: an
                              empty index list */
} piola_attachment_def;

typedef struct piola_bone_def {
  /* The bone's shape at rest (world space, m), its Coulomb friction and its rigid motion,
   * exactly as for an obstacle. Default: piola_default_obstacle_def() */
  piola_obstacle_def shape;
  const piola_attachment_def *attachments; /* attachment_count attachments, read by add_bone */
  int32_t attachment_count;                /* >= 0; 0: a pure moving obstacle */
} piola_bone_def;

PIOLA_API piola_attachment_def piola_default_attachment_def(void);
PIOLA_API piola_bone_def piola_default_bone_def(void);

/* Adds the bone's obstacle (its obstacle index goes to *obstacle_index, may be NULL) and
 * drives the attached nodes with its motion, moving them to the bone's pose at the world's
 * current time. Every attachment must select at least one node; the world is left as it
 * was on any error, which names the attachment ("attachments[1]: selects no node of solid
 * 'arm'"). attached_counts (attachment_count entries, may be NULL) receives how many nodes
 * each attachment selected. */
PIOLA_API piola_status piola_world_add_bone(piola_world *world, const piola_bone_def *def,
                                            int32_t *obstacle_index, int32_t *attached_counts);

#ifdef __cplusplus
}
#endif

#endif
