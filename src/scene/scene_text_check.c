/* A check of the scene text before JSON parsing: no string may hold the escape \u0000.
 *
 * cJSON decodes "\u0000" into a NUL byte inside its C string, so "cube.msh\u0000.bad" would
 * silently read as "cube.msh": every string of a scene is a path, a name or a keyword, none
 * of which may hold NUL, so the scene is refused with the place of the escape. */
#include <stdint.h>

#include "common/status_report.h"
#include "scene/scene_desc.h"

piola_status piola__scene_check_text(const char *json, const char *label) {
  int in_string = 0;
  int32_t line = 1;
  const char *line_start = json;
  for (const char *c = json; *c; ++c) {
    if (*c == '\n') {
      line++;
      line_start = c + 1;
    }
    if (!in_string) {
      in_string = *c == '"';
      continue;
    }
    if (*c == '"') {
      in_string = 0;
    } else if (*c == '\\') {
      if (c[1] == 'u' && c[2] == '0' && c[3] == '0' && c[4] == '0' && c[5] == '0')
        return PIOLA_FAIL(PIOLA_ERROR_PARSE,
                          "%s:%d:%d: a string holds \\u0000 (NUL), which no path, name or "
                          "keyword may contain",
                          label, (int)line, (int)(c - line_start) + 1);
      if (c[1]) ++c; /* the escaped character, so \" and \\ do not end or start anything */
    }
  }
  return PIOLA_OK;
}
