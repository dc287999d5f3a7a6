/* Scene texts the parser must refuse, and the check that it does (test_scene.c,
 * test_shell_scene.c, test_material_scene.c, test_muscle_scene.c). */
#ifndef PIOLA_TEST_SCENE_CASES_H
#define PIOLA_TEST_SCENE_CASES_H

#include <stddef.h>

typedef struct bad_scene_case {
  const char *json;
  const char *expected; /* substring of the message */
} bad_scene_case;

/* Each case, parsed as "bad.json" in ".", is refused with a message that holds its
 * expected text (its key path, usually). */
void assert_bad_scenes_refused(const bad_scene_case *cases, size_t count);

#endif
