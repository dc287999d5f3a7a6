#include "output/frame_commit.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "common/fault_injection.h"
#include "common/status_report.h"

int piola__frame_pending_name(const char *final_path, char *out, size_t size) {
  const char *dot = strrchr(final_path, '.');
  const char *slash = strrchr(final_path, '/');
  if (!dot || (slash && dot < slash)) return 0;
  int n = snprintf(out, size, "%.*s.pending%s", (int)(dot - final_path), final_path, dot);
  return n > 0 && (size_t)n < size;
}

void piola__frame_commit_add(frame_commit *c, const char *from, const char *to, int is_index) {
  if (c->count >= FRAME_COMMIT_MAX_FILES) return;
  snprintf(c->from[c->count], FRAME_COMMIT_PATH, "%s", from);
  snprintf(c->to[c->count], FRAME_COMMIT_PATH, "%s", to);
  c->count++;
  if (!is_index) c->data_count = c->count;
}

piola_status piola__frame_commit_publish(frame_commit *c) {
  for (int i = 0; i < c->count; ++i) {
    piola__fault_before_rename();
    if (rename(c->from[i], c->to[i]) != 0) {
      int err = errno;
      if (i <= c->data_count)
        for (int j = 0; j < i; ++j) unlink(c->to[j]);
      for (int j = i; j < c->count; ++j) unlink(c->from[j]);
      c->count = 0;
      return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: cannot move into place: %s", c->to[i], strerror(err));
    }
  }
  c->count = 0;
  return PIOLA_OK;
}

void piola__frame_commit_discard(frame_commit *c) {
  for (int i = 0; i < c->count; ++i) unlink(c->from[i]);
  c->count = 0;
}
