/* piola: scalars keyframed over time.
 *
 * Any scalar a scene sets may be a constant or piecewise-linear keys [[t0, v0], [t1, v1], ...]
 * over time (s); before the first key it holds the first value, after the last key the last. */
#ifndef PIOLA_KEYFRAMES_H
#define PIOLA_KEYFRAMES_H

#include <stdint.h>

#include "piola/export.h"
#include "piola/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PIOLA_MAX_KEYS 64

typedef struct piola_track {
  int32_t key_count;             /* 0 means constant `value` */
  double value;                  /* the constant when key_count == 0 */
  double times[PIOLA_MAX_KEYS];  /* s, strictly increasing */
  double values[PIOLA_MAX_KEYS];
} piola_track;

/* A constant track. */
PIOLA_API piola_track piola_track_constant(double value);

/* Keys must have finite values and strictly increasing times. */
PIOLA_API piola_status piola_track_from_keys(const double *times, const double *values,
                                             int32_t count, piola_track *out);

/* The value at time t (s). */
PIOLA_API double piola_track_eval(const piola_track *track, double t);

#ifdef __cplusplus
}
#endif

#endif
