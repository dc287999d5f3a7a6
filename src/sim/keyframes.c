/* Piecewise-linear keyframed scalars. */
#include "piola/keyframes.h"

#include <math.h>

#include "common/status_report.h"

piola_track piola_track_constant(double value) {
  piola_track track = {0};
  track.value = value;
  return track;
}

piola_status piola_track_from_keys(const double *times, const double *values, int32_t count,
                                   piola_track *out) {
  if (count < 1 || count > PIOLA_MAX_KEYS)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "keys: need 1 to %d keys, got %d",
                      PIOLA_MAX_KEYS, (int)count);
  for (int32_t i = 0; i < count; ++i) {
    if (!isfinite(times[i]) || !isfinite(values[i]))
      return PIOLA_FAIL(PIOLA_ERROR_NOT_FINITE, "keys[%d]: time and value must be finite", (int)i);
    if (i > 0 && !(times[i] > times[i - 1]))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "keys[%d]: times must increase strictly (%g after %g)", (int)i, times[i],
                        times[i - 1]);
  }
  piola_track track = {0};
  track.key_count = count;
  track.value = values[0];
  for (int32_t i = 0; i < count; ++i) {
    track.times[i] = times[i];
    track.values[i] = values[i];
  }
  *out = track;
  return PIOLA_OK;
}

double piola_track_eval(const piola_track *track, double t) {
  int32_t n = track->key_count;
  if (n == 0) return track->value;
  if (t <= track->times[0]) return track->values[0];
  if (t >= track->times[n - 1]) return track->values[n - 1];
  int32_t i = 1;
  while (track->times[i] < t) ++i;
  double t0 = track->times[i - 1], t1 = track->times[i];
  double s = (t - t0) / (t1 - t0);
  return track->values[i - 1] + s * (track->values[i] - track->values[i - 1]);
}
