/* RGB images: storage, PNG files through libpng, and contact sheets. */
#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "piola/files.h"
#include "render/render_internal.h"

void piola_image_free(piola_image *image) {
  if (!image) return;
  free(image->rgb);
  image->rgb = NULL;
  image->width = image->height = 0;
}

piola_status piola__image_resize(piola_image *image, int32_t width, int32_t height) {
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "image size %d x %d out of range 1..16384",
                      (int)width, (int)height);
  if (image->rgb && image->width == width && image->height == height) return PIOLA_OK;
  uint8_t *p = realloc(image->rgb, 3 * (size_t)width * (size_t)height);
  if (!p)
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "image %d x %d: out of memory", (int)width,
                      (int)height);
  image->rgb = p;
  image->width = width;
  image->height = height;
  return PIOLA_OK;
}

void piola__render_fill_rect(piola_image *image, int x0, int y0, int w, int h, uint8_t r, uint8_t g,
                             uint8_t b) {
  int x1 = x0 + w, y1 = y0 + h;
  if (x0 < 0) x0 = 0;
  if (y0 < 0) y0 = 0;
  if (x1 > image->width) x1 = image->width;
  if (y1 > image->height) y1 = image->height;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      uint8_t *p = image->rgb + 3 * ((size_t)y * (size_t)image->width + (size_t)x);
      p[0] = r, p[1] = g, p[2] = b;
    }
}

/* libpng reports errors by longjmp; these live outside the functions that call setjmp so
 * nothing a longjmp skips over is a non-volatile local. */
static void png_error_quiet(png_structp png, png_const_charp message) {
  (void)message;
  png_longjmp(png, 1);
}
static void png_warning_quiet(png_structp png, png_const_charp message) {
  (void)png, (void)message;
}

static int png_write_stream(FILE *stream, const piola_image *image) {
  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, png_error_quiet, png_warning_quiet);
  if (!png) return -1;
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return -1;
  }
  png_init_io(png, stream);
  png_set_compression_level(png, 3); /* previews: fast over small */
  png_set_IHDR(png, info, (png_uint_32)image->width, (png_uint_32)image->height, 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int32_t y = 0; y < image->height; ++y)
    png_write_row(png, image->rgb + 3 * (size_t)y * (size_t)image->width);
  png_write_end(png, NULL);
  png_destroy_write_struct(&png, &info);
  return 0;
}

piola_status piola_image_write_png(const char *path, const piola_image *image) {
  if (!path || !image || !image->rgb || image->width <= 0 || image->height <= 0)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "png write: NULL or empty image");
  piola_atomic_file f;
  PIOLA_TRY(piola_atomic_file_open(&f, path));
  if (png_write_stream(f.stream, image) != 0) {
    piola_atomic_file_abort(&f);
    return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: PNG encoding failed", path);
  }
  return piola_atomic_file_commit(&f);
}

static int png_read_stream(FILE *stream, piola_image *image) {
  png_structp png =
      png_create_read_struct(PNG_LIBPNG_VER_STRING, NULL, png_error_quiet, png_warning_quiet);
  if (!png) return -1;
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, NULL);
    return -1;
  }
  png_init_io(png, stream);
  png_read_info(png, info);
  png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
  int type = png_get_color_type(png, info), depth = png_get_bit_depth(png, info);
  if (depth == 16) png_set_strip_16(png);
  if (type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (type == PNG_COLOR_TYPE_GRAY || type == PNG_COLOR_TYPE_GRAY_ALPHA) png_set_gray_to_rgb(png);
  if (type & PNG_COLOR_MASK_ALPHA) png_set_strip_alpha(png);
  if (depth < 8) png_set_expand(png);
  png_read_update_info(png, info);
  if (w == 0 || h == 0 || w > 16384 || h > 16384 || png_get_rowbytes(png, info) != 3 * (size_t)w ||
      piola__image_resize(image, (int32_t)w, (int32_t)h) != PIOLA_OK) {
    png_destroy_read_struct(&png, &info, NULL);
    return -1;
  }
  for (png_uint_32 y = 0; y < h; ++y) png_read_row(png, image->rgb + 3 * (size_t)y * w, NULL);
  png_read_end(png, NULL);
  png_destroy_read_struct(&png, &info, NULL);
  return 0;
}

piola_status piola_image_read_png(const char *path, piola_image *image) {
  if (!path || !image) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "png read: NULL argument");
  FILE *f = fopen(path, "rb");
  if (!f) return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: cannot open", path);
  int rc = png_read_stream(f, image);
  fclose(f);
  if (rc != 0) return PIOLA_FAIL(PIOLA_ERROR_PARSE, "%s: not a readable 8-bit PNG", path);
  return PIOLA_OK;
}

/* Box-filter downscale of src into the w x h rectangle of dst at (x0, y0). */
static void downscale_into(const piola_image *src, piola_image *dst, int x0, int y0, int w, int h) {
  for (int y = 0; y < h; ++y) {
    int sy0 = (int)((int64_t)y * src->height / h), sy1 = (int)((int64_t)(y + 1) * src->height / h);
    if (sy1 <= sy0) sy1 = sy0 + 1;
    for (int x = 0; x < w; ++x) {
      int sx0 = (int)((int64_t)x * src->width / w), sx1 = (int)((int64_t)(x + 1) * src->width / w);
      if (sx1 <= sx0) sx1 = sx0 + 1;
      uint32_t sum[3] = {0, 0, 0}, n = 0;
      for (int sy = sy0; sy < sy1; ++sy)
        for (int sx = sx0; sx < sx1; ++sx) {
          const uint8_t *p = src->rgb + 3 * ((size_t)sy * (size_t)src->width + (size_t)sx);
          sum[0] += p[0], sum[1] += p[1], sum[2] += p[2], ++n;
        }
      uint8_t *q = dst->rgb + 3 * ((size_t)(y0 + y) * (size_t)dst->width + (size_t)(x0 + x));
      for (int c = 0; c < 3; ++c) q[c] = (uint8_t)((sum[c] + n / 2) / n);
    }
  }
}

piola_status piola_image_contact_sheet(const piola_image *images, const char *const *labels,
                                       int32_t count, int32_t columns, int32_t cell_width,
                                       piola_image *out) {
  if (!images || !out || count <= 0 || columns <= 0 || cell_width < 8)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "contact sheet: need images, count > 0, columns > 0, cell width >= 8");
  for (int32_t i = 0; i < count; ++i)
    if (!images[i].rgb || images[i].width <= 0 || images[i].height <= 0)
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "contact sheet: image %d is empty", (int)i);
  if (columns > count) columns = count;
  int32_t rows = (count + columns - 1) / columns;
  int32_t cell_height = (int32_t)((int64_t)cell_width * images[0].height / images[0].width);
  if (cell_height < 1) cell_height = 1;
  const int gap = 4;
  PIOLA_TRY(piola__image_resize(out, columns * cell_width + (columns + 1) * gap,
                                rows * cell_height + (rows + 1) * gap));
  memset(out->rgb, 40, 3 * (size_t)out->width * (size_t)out->height);
  int scale = cell_width >= 480 ? 2 : 1;
  for (int32_t i = 0; i < count; ++i) {
    int x0 = gap + (i % columns) * (cell_width + gap),
        y0 = gap + (i / columns) * (cell_height + gap);
    downscale_into(&images[i], out, x0, y0, cell_width, cell_height);
    if (labels && labels[i]) piola_image_draw_label(out, x0, y0, scale, labels[i]);
  }
  return PIOLA_OK;
}
