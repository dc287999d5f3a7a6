/* The colour map for scalar fields and the colour bar that explains it.
 *
 * The map is viridis sampled at five stops and interpolated linearly between them: dark
 * purple (68, 1, 84), indigo blue (59, 82, 139), teal (33, 145, 140), green (94, 201, 98)
 * and yellow (253, 231, 37). Brightness grows monotonically, so it reads in grey too. It
 * never passes through red, which is reserved for inverted elements.
 *
 * A range whose width is rounding noise is drawn as one value. A field that is uniform up to
 * rounding (a cube under uniform stretch: energy densities 1e-10 apart relative, det F 3e-15)
 * would otherwise be stretched over its noise and show random patches from one end of the
 * map to the other, under colour-bar labels that all read the same number. The tolerance,
 * RENDER_UNIFORM_TOLERANCE of the range's magnitude, sits far above the noise of the values a
 * renderer is given (doubles carry 1e-16, derived fields such as energy densities a few
 * orders more, even a foreign Float32 frame only 6e-8) and far below any variation worth a
 * colour: telling 1 from 1 + 1e-6 on the bar already takes labels of eight digits. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/render_internal.h"

render_rgb piola__render_colormap(double s) {
  static const float stops[5][3] = {
      {68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
  if (!(s > 0)) s = 0; /* NaN goes to the bottom */
  if (s > 1) s = 1;
  double u = s * 4;
  int i = (int)u;
  if (i > 3) i = 3;
  float f = (float)(u - i);
  return (render_rgb){stops[i][0] + f * (stops[i + 1][0] - stops[i][0]),
                      stops[i][1] + f * (stops[i + 1][1] - stops[i][1]),
                      stops[i][2] + f * (stops[i + 1][2] - stops[i][2])};
}

bool piola__render_range_is_uniform(double lo, double hi) {
  return hi - lo <= RENDER_UNIFORM_TOLERANCE * fmax(fabs(lo), fabs(hi));
}

double piola__render_range_position(double v, double lo, double hi) {
  if (!piola__render_range_is_uniform(lo, hi)) return (v - lo) / (hi - lo);
  /* one value: the middle of the map within the tolerance of it, the ends beyond */
  double mid = lo + 0.5 * (hi - lo), band = RENDER_UNIFORM_TOLERANCE * fmax(fabs(lo), fabs(hi));
  if (!(v >= mid - band)) return 0; /* NaN goes to the bottom, as in the map */
  return v > mid + band ? 1 : 0.5;
}

/* v with `digits` significant digits: plain between 0.01 and 10^4, else in exponent form. */
static void format_value(double v, int digits, char *buf, size_t n) {
  double a = fabs(v);
  if (v == 0)
    snprintf(buf, n, "0");
  else if (a >= 1e-2 && a < 1e4)
    snprintf(buf, n, "%.*g", digits, v);
  else
    snprintf(buf, n, "%.*e", digits - 1, v);
}

void piola__render_color_bar(piola_image *image, double lo, double hi, const char *label) {
  int scale = image->height >= 600 ? 2 : 1;
  int bar_h = image->height / 2, bar_w = 10 * scale;
  /* The labels, top to bottom: hi, the middle and lo with the fewest digits (3 to 8) that
   * tell them apart, or the single value of a uniform range. */
  bool uniform = piola__render_range_is_uniform(lo, hi);
  int count = uniform ? 1 : 3;
  char text[3][40];
  for (int digits = 3; digits <= 8; ++digits) {
    for (int k = 0; k < count; ++k)
      format_value(uniform ? lo + 0.5 * (hi - lo) : hi + (lo - hi) * k / 2.0, digits, text[k],
                   sizeof text[k]);
    if (uniform || (strcmp(text[0], text[1]) != 0 && strcmp(text[1], text[2]) != 0)) break;
  }
  int text_w = 0;
  for (int k = 0; k < count; ++k) {
    int w = piola__render_text_width(text[k], scale);
    if (w > text_w) text_w = w;
  }
  int room = text_w + 6 * scale > 70 * scale ? text_w + 6 * scale : 70 * scale;
  int x0 = image->width - bar_w - room, y0 = (image->height - bar_h) / 2;
  if (x0 < 0 || bar_h < 8) return;
  /* a dark frame, then the ramp with the top at hi (one colour for a uniform range) */
  piola__render_fill_rect(image, x0 - scale, y0 - scale, bar_w + 2 * scale, bar_h + 2 * scale, 20,
                          20, 20);
  for (int y = 0; y < bar_h; ++y) {
    render_rgb c = piola__render_colormap(uniform ? 0.5 : 1.0 - (y + 0.5) / bar_h);
    piola__render_fill_rect(image, x0, y0 + y, bar_w, 1, (uint8_t)lrintf(c.r), (uint8_t)lrintf(c.g),
                            (uint8_t)lrintf(c.b));
  }
  int tx = x0 + bar_w + 4 * scale;
  for (int k = 0; k < count; ++k) {
    int ty = y0 + (uniform ? 1 : k) * (bar_h - 1) / 2 - 3 * scale;
    piola__render_fill_rect(image, tx - scale, ty - scale,
                            piola__render_text_width(text[k], scale) + 2 * scale, 9 * scale, 245,
                            245, 245);
    piola__render_text(image, tx, ty, scale, text[k], 20, 20, 20);
  }
  if (label && label[0]) {
    int w = piola__render_text_width(label, scale);
    int lx = x0 + bar_w / 2 - w / 2;
    if (lx + w > image->width - 2) lx = image->width - 2 - w;
    if (lx < 0) lx = 0;
    piola__render_text(image, lx, y0 - 14 * scale, scale, label, 20, 20, 20);
  }
}
