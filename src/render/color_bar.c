/* The colour map for scalar fields and the colour bar that explains it.
 *
 * The map runs dark blue -> teal -> green -> yellow (a viridis-like ramp: brightness grows
 * monotonically, so it reads in grey too). It never passes through red, which is reserved
 * for inverted elements. */
#include <math.h>
#include <stdio.h>

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

static void format_value(double v, char *buf, size_t n) {
  double a = fabs(v);
  if (v == 0)
    snprintf(buf, n, "0");
  else if (a >= 1e-2 && a < 1e4)
    snprintf(buf, n, "%.3g", v);
  else
    snprintf(buf, n, "%.2e", v);
}

void piola__render_color_bar(piola_image *image, double lo, double hi, const char *label) {
  int scale = image->height >= 600 ? 2 : 1;
  int bar_h = image->height / 2, bar_w = 10 * scale;
  int x0 = image->width - bar_w - 70 * scale, y0 = (image->height - bar_h) / 2;
  if (x0 < 0 || bar_h < 8) return;
  /* a dark frame, then the ramp with the top at hi */
  piola__render_fill_rect(image, x0 - scale, y0 - scale, bar_w + 2 * scale, bar_h + 2 * scale, 20,
                          20, 20);
  for (int y = 0; y < bar_h; ++y) {
    render_rgb c = piola__render_colormap(1.0 - (y + 0.5) / bar_h);
    piola__render_fill_rect(image, x0, y0 + y, bar_w, 1, (uint8_t)lrintf(c.r), (uint8_t)lrintf(c.g),
                            (uint8_t)lrintf(c.b));
  }
  char text[64];
  int tx = x0 + bar_w + 4 * scale;
  for (int k = 0; k <= 2; ++k) {
    double v = hi + (lo - hi) * k / 2.0;
    format_value(v, text, sizeof text);
    int ty = y0 + k * (bar_h - 1) / 2 - 3 * scale;
    piola__render_fill_rect(image, tx - scale, ty - scale,
                            piola__render_text_width(text, scale) + 2 * scale, 9 * scale, 245, 245,
                            245);
    piola__render_text(image, tx, ty, scale, text, 20, 20, 20);
  }
  if (label && label[0]) {
    int w = piola__render_text_width(label, scale);
    int lx = x0 + bar_w / 2 - w / 2;
    if (lx + w > image->width - 2) lx = image->width - 2 - w;
    if (lx < 0) lx = 0;
    piola__render_text(image, lx, y0 - 14 * scale, scale, label, 20, 20, 20);
  }
}
