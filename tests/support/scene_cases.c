/* The refusal check of bad scene texts (scene_cases.h). */
#include "scene_cases.h"

#include <string.h>

#include "scene/scene_desc.h"
#include "test_support.h"

void assert_bad_scenes_refused(const bad_scene_case *cases, size_t count) {
  for (size_t i = 0; i < count; ++i) {
    scene_desc d;
    piola_clear_error();
    if (piola__scene_parse(cases[i].json, ".", "bad.json", &d) == PIOLA_OK) {
      piola__scene_desc_free(&d);
      fail_msg("case %zu was accepted: %s", i, cases[i].json);
    }
    if (!strstr(piola_last_error(), cases[i].expected))
      fail_msg("case %zu: message '%s' does not contain '%s'", i, piola_last_error(),
               cases[i].expected);
  }
}
