/* The preview renderer draws objects where they are: silhouettes of spheres (as triangle
 * meshes and as obstacles) cover their analytic projected area, the ground fills exactly
 * the half of the view below the horizon, the inverted-element highlight appears exactly
 * when there are inverted faces, a value colour map orders colours by value and shows a
 * colour bar, camera framing keeps the object inside the image, and output is deterministic
 * for any thread count. Set PIOLA_TEST_RENDER_OUT=folder to keep the images. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "piola/render.h"
#include "piola/threads.h"
#include "render/render_internal.h"
#include "test_render_support.h"
#include "test_support.h"

static void keep(const char *name, const piola_image *image) {
  const char *dir = getenv("PIOLA_TEST_RENDER_OUT");
  if (!dir || !dir[0]) return;
  char path[1024];
  snprintf(path, sizeof path, "%s/%s.png", dir, name);
  assert_int_equal(piola_image_write_png(path, image), PIOLA_OK);
}

static piola_render_mesh sphere_mesh(const test_sphere *s) {
  piola_render_mesh m;
  memset(&m, 0, sizeof m);
  m.vertex_count = s->vertex_count;
  m.positions = s->positions;
  m.triangle_count = s->triangle_count;
  m.triangles = s->triangles;
  return m;
}

/* A camera on the -y axis at distance D looking at the origin, z up, no ground. */
static piola_render_def axis_camera(double D, double fov) {
  piola_render_def def = piola_default_render_def();
  def.width = 480;
  def.height = 360;
  def.camera_set = true;
  def.camera_position = (piola_vec3){0, -D, 0};
  def.camera_target = (piola_vec3){0, 0, 0};
  def.fov_degrees = fov;
  def.ground = false;
  return def;
}

/* Projected disk area (pixels) of a sphere of radius R centred on the view axis at
 * distance D: its outline is a circle of angular radius asin(R / D). */
static double disk_area(const piola_render_def *def, double R, double D) {
  double f = 0.5 * def->height / tan(0.5 * def->fov_degrees * M_PI / 180);
  double r = f * tan(asin(R / D));
  return M_PI * r * r;
}

static void render_pair(const piola_render_def *def, const piola_render_mesh *mesh,
                        const piola_obstacle_def *obstacle, piola_image *empty, piola_image *full) {
  piola_renderer *r;
  assert_int_equal(piola_renderer_create(def, &r), PIOLA_OK);
  assert_int_equal(piola_renderer_render(r, NULL, empty), PIOLA_OK);
  if (obstacle) assert_int_equal(piola_renderer_add_obstacle(r, obstacle), PIOLA_OK);
  assert_int_equal(piola_renderer_render(r, mesh, full), PIOLA_OK);
  piola_renderer_destroy(r);
}

static void test_mesh_sphere_silhouette_area(void **state) {
  (void)state;
  const double cases[3][3] = {{0.5, 3, 40}, {0.2, 2, 30}, {1.0, 5, 60}}; /* R, D, fov */
  for (int c = 0; c < 3; ++c) {
    double R = cases[c][0], D = cases[c][1];
    piola_render_def def = axis_camera(D, cases[c][2]);
    test_sphere s = test_uv_sphere(256, 128, R, 0, 0, 0);
    piola_render_mesh m = sphere_mesh(&s);
    piola_image empty = {0}, full = {0};
    render_pair(&def, &m, NULL, &empty, &full);
    double expected = disk_area(&def, R, D);
    long covered = test_count_differing(&empty, &full);
    if (c == 0) keep("mesh_sphere", &full);
    /* the polygonal outline is inscribed in the circle: at most a fraction of a percent */
    assert_true(fabs(covered - expected) <= 0.02 * expected);
    /* the disk is centred: the centre pixel is covered, the corners are not */
    size_t centre = (size_t)(def.height / 2) * (size_t)def.width + (size_t)(def.width / 2);
    assert_memory_not_equal(empty.rgb + 3 * centre, full.rgb + 3 * centre, 3);
    assert_memory_equal(empty.rgb, full.rgb, 3);
    piola_image_free(&empty);
    piola_image_free(&full);
    test_sphere_free(&s);
  }
}

static void test_obstacle_sphere_silhouette_area(void **state) {
  (void)state;
  double R = 0.4, D = 3;
  piola_render_def def = axis_camera(D, 40);
  piola_obstacle_def ob = piola_default_obstacle_def();
  ob.type = PIOLA_OBSTACLE_SPHERE;
  ob.center = (piola_vec3){0, 0, 0};
  ob.radius = R;
  piola_image empty = {0}, full = {0};
  render_pair(&def, NULL, &ob, &empty, &full);
  keep("obstacle_sphere", &full);
  double expected = disk_area(&def, R, D);
  long covered = test_count_differing(&empty, &full);
  assert_true(fabs(covered - expected) <= 0.02 * expected);
  piola_image_free(&empty);
  piola_image_free(&full);
}

/* A mesh sphere in front of an obstacle sphere hides its middle; behind it, it is hidden. */
static void test_depth_compositing_of_mesh_and_obstacle(void **state) {
  (void)state;
  piola_render_def def = axis_camera(4, 40);
  piola_obstacle_def ob = piola_default_obstacle_def();
  ob.type = PIOLA_OBSTACLE_SPHERE;
  ob.radius = 0.6;
  for (int front = 0; front < 2; ++front) {
    /* small sphere at y = -1 (in front) or y = +1.5 (behind the obstacle) */
    test_sphere s = test_uv_sphere(64, 32, 0.2, 0, front ? -1.0 : 1.5, 0);
    piola_render_mesh m = sphere_mesh(&s);
    piola_image only_obstacle = {0}, both = {0};
    piola_renderer *r;
    assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
    assert_int_equal(piola_renderer_add_obstacle(r, &ob), PIOLA_OK);
    assert_int_equal(piola_renderer_render(r, NULL, &only_obstacle), PIOLA_OK);
    assert_int_equal(piola_renderer_render(r, &m, &both), PIOLA_OK);
    piola_renderer_destroy(r);
    long changed = test_count_differing(&only_obstacle, &both);
    if (front) {
      piola_render_def d2 = axis_camera(4, 40);
      double expected = M_PI * pow(0.5 * d2.height / tan(20 * M_PI / 180) * tan(asin(0.2 / 3)), 2);
      assert_true(fabs(changed - expected) <= 0.03 * expected);
    } else {
      assert_int_equal(changed, 0);
    }
    piola_image_free(&only_obstacle);
    piola_image_free(&both);
    test_sphere_free(&s);
  }
}

static bool same_rgb(const piola_image *a, const piola_image *b, int x, int y) {
  size_t i = 3 * ((size_t)y * (size_t)a->width + (size_t)x);
  return memcmp(a->rgb + i, b->rgb + i, 3) == 0;
}

/* A horizontal camera at height h above a ground plane sees ground below the horizon (the
 * centre row) and sky above it, for a plane obstacle and for the fallback ground. */
static void test_ground_fills_the_view_below_the_horizon(void **state) {
  (void)state;
  for (int fallback = 0; fallback < 2; ++fallback) {
    piola_render_def def = axis_camera(5, 50);
    def.camera_position = (piola_vec3){0, -5, 1};
    def.camera_target = (piola_vec3){0, 0, 1};
    piola_renderer *r;
    piola_image sky = {0}, img = {0};
    assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
    assert_int_equal(piola_renderer_render(r, NULL, &sky), PIOLA_OK);
    piola_renderer_destroy(r);
    def.ground = fallback == 1;
    def.ground_height = 0;
    assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
    if (!fallback) {
      piola_obstacle_def plane = piola_default_obstacle_def(); /* z = 0, normal +z */
      plane.type = PIOLA_OBSTACLE_PLANE;
      plane.center = (piola_vec3){0, 0, 0};
      plane.axis = (piola_vec3){0, 0, 1};
      assert_int_equal(piola_renderer_add_obstacle(r, &plane), PIOLA_OK);
    }
    assert_int_equal(piola_renderer_render(r, NULL, &img), PIOLA_OK);
    piola_renderer_destroy(r);
    if (!fallback) keep("ground_horizon", &img);
    int H = def.height, W = def.width;
    /* above the horizon: untouched sky */
    for (int y = 0; y < H / 2; ++y)
      for (int x = 0; x < W; x += 7) assert_true(same_rgb(&sky, &img, x, y));
    /* well below it (rays reach the ground within a few metres): all ground */
    for (int y = H / 2 + H / 8; y < H; ++y)
      for (int x = 0; x < W; x += 7) assert_false(same_rgb(&sky, &img, x, y));
    /* a checkerboard: the bottom row has light and dark squares */
    int lo = 255, hi = 0;
    for (int x = 0; x < W; ++x) {
      int g = img.rgb[3 * ((size_t)(H - 1) * (size_t)W + (size_t)x) + 1];
      lo = g < lo ? g : lo;
      hi = g > hi ? g : hi;
    }
    assert_true(hi - lo > 20);
    piola_image_free(&sky);
    piola_image_free(&img);
  }
}

/* A flat patch lying exactly on the ground (every node at z = 0, as a solid squashed into a
 * puddle on a plane obstacle is) is drawn over the ground, not hidden by it: every pixel
 * around its projected centre differs from the empty ground, for a plane obstacle and for
 * the fallback ground, from a steep and from a grazing camera. */
static void test_patch_lying_on_the_ground_is_visible(void **state) {
  (void)state;
  enum { N = 24 };
  double x[3 * (N + 1) * (N + 1)];
  int32_t tri[6 * N * N];
  for (int j = 0; j <= N; ++j)
    for (int i = 0; i <= N; ++i) {
      double *p = x + 3 * (j * (N + 1) + i);
      p[0] = -0.5 + (double)i / N, p[1] = -0.5 + (double)j / N, p[2] = 0;
    }
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < N; ++i) {
      int32_t a = j * (N + 1) + i, b = a + 1, c = a + N + 1, d = c + 1, *t = tri + 6 * (j * N + i);
      t[0] = a, t[1] = b, t[2] = d, t[3] = a, t[4] = d, t[5] = c;
    }
  piola_render_mesh m = {(N + 1) * (N + 1), x, 2 * N * N, tri, NULL, NULL, NULL, 0};
  const double heights[2] = {2.0, 0.25};
  for (int fallback = 0; fallback < 2; ++fallback)
    for (int h = 0; h < 2; ++h) {
      piola_render_def def = axis_camera(3, 40);
      def.camera_position = (piola_vec3){0.1, -3, heights[h]};
      def.ground = fallback == 1;
      def.ground_height = 0;
      piola_obstacle_def plane = piola_default_obstacle_def(); /* z = 0, normal +z */
      plane.type = PIOLA_OBSTACLE_PLANE;
      plane.center = (piola_vec3){0, 0, 0};
      plane.axis = (piola_vec3){0, 0, 1};
      piola_image ground = {0}, patch = {0};
      render_pair(&def, &m, fallback ? NULL : &plane, &ground, &patch);
      if (!fallback) {
        /* render_pair drew the empty image before adding the plane: redraw it with it */
        piola_renderer *r;
        assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
        assert_int_equal(piola_renderer_add_obstacle(r, &plane), PIOLA_OK);
        assert_int_equal(piola_renderer_render(r, NULL, &ground), PIOLA_OK);
        piola_renderer_destroy(r);
      }
      if (h == 0 && !fallback) keep("patch_on_ground", &patch);
      /* the target (origin, the patch centre) projects to the image centre; the patch
       * covers at least +-12 x +-4 pixels around it from both cameras */
      int W = def.width, H = def.height;
      for (int y = H / 2 - 4; y <= H / 2 + 4; ++y)
        for (int px = W / 2 - 12; px <= W / 2 + 12; ++px)
          assert_false(same_rgb(&ground, &patch, px, y));
      piola_image_free(&ground);
      piola_image_free(&patch);
    }
}

/* The highlight colour appears exactly when faces are flagged, and where they are. */
static void test_inverted_highlight_present_exactly_when_flagged(void **state) {
  (void)state;
  piola_render_def def = axis_camera(3, 40);
  def.color = PIOLA_RENDER_COLOR_INVERTED;
  def.ground = true; /* the ground must not look like an inverted face either */
  def.camera_position = (piola_vec3){0, -3, 0.3};
  test_sphere s = test_uv_sphere(96, 48, 0.5, 0, 0, 0);
  piola_render_mesh m = sphere_mesh(&s);
  uint8_t *flags = calloc((size_t)s.triangle_count, 1);
  m.inverted = flags;
  piola_renderer *r;
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
  piola_renderer_fit_camera(r, (piola_vec3){-0.5, -0.5, -0.5}, (piola_vec3){0.5, 0.5, 0.5});
  piola_image img = {0};
  assert_int_equal(piola_renderer_render(r, &m, &img), PIOLA_OK);
  assert_int_equal(test_count_red(&img), 0);
  /* flag the top cap (faces whose centroid has z > 0.3) */
  long flagged = 0;
  for (int32_t t = 0; t < s.triangle_count; ++t) {
    double z = 0;
    for (int k = 0; k < 3; ++k) z += s.positions[3 * (size_t)s.triangles[3 * t + k] + 2] / 3;
    flags[t] = z > 0.3;
    flagged += flags[t];
  }
  assert_true(flagged > 0);
  assert_int_equal(piola_renderer_render(r, &m, &img), PIOLA_OK);
  keep("inverted_cap", &img);
  long red = test_count_red(&img);
  assert_true(red > 200);
  /* every red pixel is in the upper part of the sphere's image */
  int W = img.width, H = img.height;
  for (int y = H / 2; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const uint8_t *p = img.rgb + 3 * ((size_t)y * (size_t)W + (size_t)x);
      assert_false(p[0] > 60 && p[1] * 2 < p[0] && p[2] * 2 < p[0]);
    }
  /* plain mode ignores the flags */
  piola_renderer_destroy(r);
  def.color = PIOLA_RENDER_COLOR_PLAIN;
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
  assert_int_equal(piola_renderer_render(r, &m, &img), PIOLA_OK);
  assert_int_equal(test_count_red(&img), 0);
  piola_renderer_destroy(r);
  piola_image_free(&img);
  free(flags);
  test_sphere_free(&s);
}

static long count_near(const piola_image *img, int x0, render_rgb c, int tol) {
  long n = 0;
  for (int y = 0; y < img->height; ++y)
    for (int x = x0; x < img->width; ++x) {
      const uint8_t *p = img->rgb + 3 * ((size_t)y * (size_t)img->width + (size_t)x);
      if (abs(p[0] - (int)lrintf(c.r)) <= tol && abs(p[1] - (int)lrintf(c.g)) <= tol &&
          abs(p[2] - (int)lrintf(c.b)) <= tol)
        ++n;
    }
  return n;
}

/* Value colouring: the colour map orders faces by value (top of a sphere coloured by height
 * is yellow, bottom dark blue) and a colour bar with both ends of the map is drawn. */
static void test_value_colors_and_color_bar(void **state) {
  (void)state;
  piola_render_def def = axis_camera(3, 40);
  def.color = PIOLA_RENDER_COLOR_VALUE;
  def.value_min = -0.5;
  def.value_max = 0.5;
  def.value_label = "Z (M)";
  test_sphere s = test_uv_sphere(96, 48, 0.5, 0, 0, 0);
  piola_render_mesh m = sphere_mesh(&s);
  double *values = malloc((size_t)s.triangle_count * sizeof *values);
  for (int32_t t = 0; t < s.triangle_count; ++t) {
    values[t] = 0;
    for (int k = 0; k < 3; ++k)
      values[t] += s.positions[3 * (size_t)s.triangles[3 * t + k] + 2] / 3;
  }
  m.values = values;
  piola_renderer *r;
  piola_image img = {0}, plain = {0};
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
  assert_int_equal(piola_renderer_render(r, &m, &img), PIOLA_OK);
  piola_renderer_destroy(r);
  keep("value_height", &img);
  int W = img.width, H = img.height;
  double f = 0.5 * H / tan(20 * M_PI / 180), rpx = f * tan(asin(0.5 / 3));
  const uint8_t *top =
      img.rgb + 3 * ((size_t)(H / 2 - (int)(0.8 * rpx)) * (size_t)W + (size_t)(W / 2));
  const uint8_t *bottom =
      img.rgb + 3 * ((size_t)(H / 2 + (int)(0.8 * rpx)) * (size_t)W + (size_t)(W / 2));
  assert_true(top[1] > top[2] + 40);       /* yellow-green: green over blue */
  assert_true(bottom[2] > bottom[1] + 20); /* dark blue-violet: blue over green */
  /* the colour bar holds both ends of the map, right of the sphere */
  render_rgb c0 = piola__render_colormap(0), c1 = piola__render_colormap(1);
  assert_true(count_near(&img, W / 2 + (int)rpx + 4, c0, 3) >= 10);
  assert_true(count_near(&img, W / 2 + (int)rpx + 4, c1, 3) >= 10);
  def.color = PIOLA_RENDER_COLOR_PLAIN;
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
  assert_int_equal(piola_renderer_render(r, &m, &plain), PIOLA_OK);
  piola_renderer_destroy(r);
  assert_int_equal(count_near(&plain, 0, c0, 3), 0);
  assert_int_equal(count_near(&plain, 0, c1, 3), 0);
  /* value colouring without values is refused */
  m.values = NULL;
  def.color = PIOLA_RENDER_COLOR_VALUE;
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
  assert_int_equal(piola_renderer_render(r, &m, &img), PIOLA_ERROR_INVALID_ARGUMENT);
  piola_renderer_destroy(r);
  piola_image_free(&img);
  piola_image_free(&plain);
  free(values);
  test_sphere_free(&s);
}

/* A field uniform up to rounding (1 + 1e-15 noise, as det F of a uniformly stretched cube)
 * is one value: every face takes the middle colour, exactly as a field of 0.5 in 0..1 does,
 * and the bar shows that colour alone, not a ramp stretched over the noise. The same holds
 * for a negative field whose range the renderer chooses itself. Values beyond the tolerance
 * band take the end colours. */
static void test_uniform_field_is_one_colour(void **state) {
  (void)state;
  assert_true(piola__render_range_is_uniform(0, 0));
  assert_true(piola__render_range_is_uniform(1 - 1e-15, 1 + 1e-15));
  assert_true(piola__render_range_is_uniform(-2e3 * (1 + 1e-10), -2e3));
  assert_false(piola__render_range_is_uniform(1, 1 + 1e-5));
  assert_false(piola__render_range_is_uniform(-1e-3, 1e-3));
  assert_true(piola__render_range_position(1 + 3e-16, 1 - 1e-15, 1 + 1e-15) == 0.5);
  assert_true(piola__render_range_position(0.5, 1 - 1e-15, 1 + 1e-15) == 0);
  assert_true(piola__render_range_position(2, 1 - 1e-15, 1 + 1e-15) == 1);
  assert_true(piola__render_range_position(0.25, 0, 1) == 0.25);

  piola_render_def def = axis_camera(3, 40);
  def.color = PIOLA_RENDER_COLOR_VALUE;
  def.value_label = "det_f";
  test_sphere s = test_uv_sphere(96, 48, 0.5, 0, 0, 0);
  piola_render_mesh m = sphere_mesh(&s);
  double *values = malloc((size_t)s.triangle_count * sizeof *values);
  double lo = INFINITY, hi = -INFINITY;
  uint32_t seed = 12345;
  for (int32_t t = 0; t < s.triangle_count; ++t) {
    seed = seed * 1664525u + 1013904223u;
    values[t] = 1.0 + 1e-15 * ((double)(seed >> 8) / (double)(1u << 24) - 0.5);
    lo = fmin(lo, values[t]), hi = fmax(hi, values[t]);
  }
  assert_true(hi > lo); /* the noise is there: a plain map would stretch over it */
  m.values = values;
  def.value_min = lo, def.value_max = hi;
  piola_renderer *r;
  piola_image noisy = {0}, middle = {0}, negative = {0};
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
  assert_int_equal(piola_renderer_render(r, &m, &noisy), PIOLA_OK);
  piola_renderer_destroy(r);
  keep("value_uniform", &noisy);
  /* reference: every face at 0.5 of a 0..1 range, the middle of the map */
  double *halves = malloc((size_t)s.triangle_count * sizeof *halves);
  for (int32_t t = 0; t < s.triangle_count; ++t) halves[t] = 0.5;
  m.values = halves;
  def.value_min = 0, def.value_max = 1;
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
  assert_int_equal(piola_renderer_render(r, &m, &middle), PIOLA_OK);
  piola_renderer_destroy(r);
  /* a negative field with the renderer's own range (min to 99th percentile) */
  for (int32_t t = 0; t < s.triangle_count; ++t) halves[t] = -values[t];
  def.value_min = def.value_max = 0;
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
  assert_int_equal(piola_renderer_render(r, &m, &negative), PIOLA_OK);
  piola_renderer_destroy(r);
  int W = noisy.width, H = noisy.height;
  double f = 0.5 * H / tan(20 * M_PI / 180), rpx = f * tan(asin(0.5 / 3));
  int bar_x = W / 2 + (int)rpx + 4;
  long differ = 0, differ_negative = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < bar_x; ++x) {
      differ += !same_rgb(&noisy, &middle, x, y);
      differ_negative += !same_rgb(&negative, &middle, x, y);
    }
  assert_int_equal(differ, 0);
  assert_int_equal(differ_negative, 0);
  /* the bar: the middle colour over its whole height, neither end of the map */
  render_rgb c0 = piola__render_colormap(0), c_mid = piola__render_colormap(0.5),
             c1 = piola__render_colormap(1);
  assert_true(count_near(&noisy, bar_x, c_mid, 1) >= 10L * (H / 2));
  assert_int_equal(count_near(&noisy, bar_x, c0, 3), 0);
  assert_int_equal(count_near(&noisy, bar_x, c1, 3), 0);
  assert_true(count_near(&middle, bar_x, c0, 3) >= 10);
  piola_image_free(&noisy);
  piola_image_free(&middle);
  piola_image_free(&negative);
  free(halves);
  free(values);
  test_sphere_free(&s);
}

/* The bitmap font draws letters in the case they are given: field names such as
 * "energy_density" read in lowercase throughout (no "eNeRGY_DeNSITY" from a lowercase 'e'
 * among capitals), every lowercase letter has a glyph of its own, and short lowercase letters
 * leave the top two rows (the ascender zone) empty while every capital reaches the top. */
static bool glyph_rows(char c, uint8_t rows[7]) {
  piola_image img = {0};
  assert_int_equal(piola__image_resize(&img, 5, 7), PIOLA_OK);
  memset(img.rgb, 0, 3 * 5 * 7);
  char text[2] = {c, 0};
  piola__render_text(&img, 0, 0, 1, text, 255, 255, 255);
  bool ink = false;
  for (int y = 0; y < 7; ++y) {
    rows[y] = 0;
    for (int x = 0; x < 5; ++x)
      if (img.rgb[3 * (y * 5 + x)]) rows[y] |= (uint8_t)(0x10 >> x), ink = true;
  }
  piola_image_free(&img);
  return ink;
}

static void test_font_keeps_the_case_of_letters(void **state) {
  (void)state;
  for (char c = 'a'; c <= 'z'; ++c) {
    uint8_t lower[7], upper[7];
    assert_true(glyph_rows(c, lower));
    assert_true(glyph_rows((char)(c - 'a' + 'A'), upper));
    assert_true(upper[0] != 0);
    assert_true(memcmp(lower, upper, sizeof lower) != 0);
  }
  for (const char *c = "acemnorsuvwxz_"; *c; ++c) {
    uint8_t rows[7];
    assert_true(glyph_rows(*c, rows));
    assert_true(rows[0] == 0 && rows[1] == 0);
  }
  /* a caption is its letters side by side, each in its own case */
  const char *caption = "energy_density";
  int n = (int)strlen(caption), w = piola__render_text_width(caption, 1);
  assert_int_equal(w, 6 * n - 1);
  piola_image img = {0};
  assert_int_equal(piola__image_resize(&img, w, 7), PIOLA_OK);
  memset(img.rgb, 0, 3 * (size_t)w * 7);
  piola__render_text(&img, 0, 0, 1, caption, 255, 255, 255);
  for (int i = 0; i < n; ++i) {
    uint8_t rows[7];
    glyph_rows(caption[i], rows);
    for (int y = 0; y < 7; ++y)
      for (int x = 0; x < 5; ++x)
        assert_int_equal(img.rgb[3 * ((size_t)y * (size_t)w + (size_t)(6 * i + x))] != 0,
                         (rows[y] & (0x10 >> x)) != 0);
  }
  piola_image_free(&img);
}

/* The automatic camera frames the box: the object is inside the image, away from its
 * border, and fills a fair part of it. */
static void test_auto_camera_frames_the_object(void **state) {
  (void)state;
  const double boxes[3][6] = {
      {-1, -1, 0, 1, 1, 2}, {10, 20, 5, 10.4, 20.6, 5.3}, {-50, -5, 0, 50, 5, 3}};
  for (int b = 0; b < 3; ++b) {
    piola_vec3 lo = {boxes[b][0], boxes[b][1], boxes[b][2]},
               hi = {boxes[b][3], boxes[b][4], boxes[b][5]};
    piola_vec3 c = {0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), 0.5 * (lo.z + hi.z)};
    double R = 0.5 * fmin(hi.x - lo.x, fmin(hi.y - lo.y, hi.z - lo.z));
    test_sphere s = test_uv_sphere(64, 32, R, c.x, c.y, c.z);
    /* a sphere at a corner of the box too, so the box extent matters */
    test_sphere s2 = test_uv_sphere(64, 32, R, hi.x - R, hi.y - R, hi.z - R);
    piola_render_def def = piola_default_render_def();
    def.width = 320;
    def.height = 180;
    def.ground = false;
    piola_renderer *r;
    assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
    piola_renderer_fit_camera(r, lo, hi);
    piola_image empty = {0}, img = {0};
    assert_int_equal(piola_renderer_render(r, NULL, &empty), PIOLA_OK);
    for (int which = 0; which < 2; ++which) {
      piola_render_mesh m = sphere_mesh(which ? &s2 : &s);
      assert_int_equal(piola_renderer_render(r, &m, &img), PIOLA_OK);
      long covered = test_count_differing(&empty, &img);
      assert_true(covered >= 4); /* the widest box leaves its sphere a few pixels across */
      for (int x = 0; x < img.width; ++x) {
        assert_true(same_rgb(&empty, &img, x, 0));
        assert_true(same_rgb(&empty, &img, x, img.height - 1));
      }
      for (int y = 0; y < img.height; ++y) {
        assert_true(same_rgb(&empty, &img, 0, y));
        assert_true(same_rgb(&empty, &img, img.width - 1, y));
      }
    }
    piola_renderer_destroy(r);
    piola_image_free(&empty);
    piola_image_free(&img);
    test_sphere_free(&s);
    test_sphere_free(&s2);
  }
}

/* A mesh obstacle (a closed sphere surface) covers its projected disk like the analytic
 * sphere, and both follow their scripted motion: moving at v for t seconds shifts the
 * silhouette's centroid by the projected v t. */
static double centroid_x(const piola_image *empty, const piola_image *full, long *count) {
  double sx = 0;
  long n = 0;
  for (int y = 0; y < full->height; ++y)
    for (int x = 0; x < full->width; ++x) {
      size_t i = 3 * ((size_t)y * (size_t)full->width + (size_t)x);
      if (memcmp(empty->rgb + i, full->rgb + i, 3) != 0) sx += x + 0.5, ++n;
    }
  *count = n;
  return n ? sx / n : NAN;
}

static void test_mesh_and_moving_obstacles(void **state) {
  (void)state;
  double R = 0.4, D = 3, v = 0.5, t = 0.6;
  piola_render_def def = axis_camera(D, 40);
  test_sphere s = test_uv_sphere(128, 64, R, 0, 0, 0);
  piola_tri_mesh tm = {s.vertex_count, s.positions, s.triangle_count, s.triangles};
  for (int kind = 0; kind < 2; ++kind) {
    piola_obstacle_def ob = piola_default_obstacle_def();
    ob.type = kind ? PIOLA_OBSTACLE_MESH : PIOLA_OBSTACLE_SPHERE;
    ob.radius = R;
    ob.mesh = kind ? &tm : NULL;
    ob.motion.velocity[0] = piola_track_constant(v); /* along +x: to the right in the image */
    piola_renderer *r;
    piola_image empty = {0}, at0 = {0}, at_t = {0};
    assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
    assert_int_equal(piola_renderer_render(r, NULL, &empty), PIOLA_OK);
    assert_int_equal(piola_renderer_add_obstacle(r, &ob), PIOLA_OK);
    piola_render_mesh none = {0, NULL, 0, NULL, NULL, NULL, NULL, 0};
    assert_int_equal(piola_renderer_render(r, &none, &at0), PIOLA_OK);
    none.time = t;
    assert_int_equal(piola_renderer_render(r, &none, &at_t), PIOLA_OK);
    piola_renderer_destroy(r);
    if (kind) keep("mesh_obstacle", &at0);
    long n0, nt;
    double c0 = centroid_x(&empty, &at0, &n0), ct = centroid_x(&empty, &at_t, &nt);
    double expected = disk_area(&def, R, D);
    assert_true(fabs(n0 - expected) <= 0.02 * expected);
    assert_close(c0, 0.5 * def.width, 0.5);
    /* the centre moved to x = v t at depth D: f v t / D pixels to the right (the outline of
       an off-axis sphere is an ellipse, whose centroid lies a little further out) */
    double f = 0.5 * def.height / tan(20 * M_PI / 180);
    assert_close(ct - c0, f * v * t / D, 0.03 * f * v * t / D);
    piola_image_free(&empty);
    piola_image_free(&at0);
    piola_image_free(&at_t);
  }
  test_sphere_free(&s);
}

/* A sphere above the ground, out of the camera's view (behind a camera looking straight
 * down), casts a shadow: under parallel light at angle theta from the vertical, an ellipse of
 * area pi R^2 / cos(theta), where the light through the centre meets the ground. */
static void test_shadow_of_a_sphere_on_the_ground(void **state) {
  (void)state;
  piola_render_def def = piola_default_render_def();
  def.width = 640;
  def.height = 480;
  def.fov_degrees = 60;
  def.camera_set = true;
  def.camera_position = (piola_vec3){0, 0, 2};
  def.camera_target = (piola_vec3){0, 0, 0};
  def.ground = true;
  def.ground_height = 0;
  piola_renderer *r;
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
  render_camera cam = piola__render_camera(r);
  piola_vec3 sun = piola__render_sun(&cam, def.up);
  double cos_theta = sun.z, R = 0.3, h = 3;
  assert_true(cos_theta > 0.5 && cos_theta < 1);
  /* centre so that its shadow falls on the origin */
  test_sphere s = test_uv_sphere(128, 64, R, sun.x * h / sun.z, sun.y * h / sun.z, h);
  piola_render_mesh m = sphere_mesh(&s);
  piola_image bare = {0}, shaded = {0};
  assert_int_equal(piola_renderer_render(r, NULL, &bare), PIOLA_OK);
  assert_int_equal(piola_renderer_render(r, &m, &shaded), PIOLA_OK);
  keep("shadow", &shaded);
  double f = 0.5 * def.height / tan(30 * M_PI / 180), metres_per_pixel = 2 / f;
  double expected = M_PI * R * R / cos_theta / (metres_per_pixel * metres_per_pixel);
  long n;
  double cx = centroid_x(&bare, &shaded, &n);
  assert_true(fabs(n - expected) <= 0.03 * expected);
  assert_close(cx, 0.5 * def.width, 1.0);
  /* darker, never lighter */
  for (size_t i = 0; i < 3 * (size_t)def.width * (size_t)def.height; ++i)
    assert_true(shaded.rgb[i] <= bare.rgb[i]);
  piola_renderer_destroy(r);
  /* without shadows nothing changes */
  def.shadows = false;
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
  assert_int_equal(piola_renderer_render(r, &m, &shaded), PIOLA_OK);
  assert_int_equal(test_count_differing(&bare, &shaded), 0);
  piola_renderer_destroy(r);
  piola_image_free(&bare);
  piola_image_free(&shaded);
  test_sphere_free(&s);
}

/* Antialiasing is exactly the average (rounded) of s x s blocks of a render s times the
 * size, so it inherits that render's geometry; s out of 1..4 is refused. */
static void test_supersampling_averages_a_larger_render(void **state) {
  (void)state;
  piola_render_def def = axis_camera(3, 40);
  def.width = 240, def.height = 180;
  test_sphere s = test_uv_sphere(128, 64, 0.5, 0, 0, 0);
  piola_render_mesh m = sphere_mesh(&s);
  piola_render_def big_def = def;
  big_def.width *= 2, big_def.height *= 2;
  def.supersample = 2;
  piola_image aa = {0}, big = {0};
  piola_renderer *r;
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
  assert_int_equal(piola_renderer_render(r, &m, &aa), PIOLA_OK);
  piola_renderer_destroy(r);
  assert_int_equal(piola_renderer_create(&big_def, &r), PIOLA_OK);
  assert_int_equal(piola_renderer_render(r, &m, &big), PIOLA_OK);
  piola_renderer_destroy(r);
  assert_int_equal(aa.width, 240);
  assert_int_equal(aa.height, 180);
  for (int y = 0; y < aa.height; ++y)
    for (int x = 0; x < aa.width; ++x)
      for (int c = 0; c < 3; ++c) {
        unsigned sum = 0;
        for (int k = 0; k < 4; ++k)
          sum +=
              big.rgb[3 * ((size_t)(2 * y + k / 2) * (size_t)big.width + (size_t)(2 * x + k % 2)) +
                      c];
        assert_int_equal(aa.rgb[3 * ((size_t)y * (size_t)aa.width + (size_t)x) + c], (sum + 2) / 4);
      }
  def.supersample = 5;
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_ERROR_INVALID_ARGUMENT);
  piola_image_free(&aa);
  piola_image_free(&big);
  test_sphere_free(&s);
}

/* Same input, same bytes, for 1 and 2 threads and on a repeat. */
static void test_deterministic_for_any_thread_count(void **state) {
  (void)state;
  piola_render_def def = piola_default_render_def();
  def.width = 400;
  def.height = 300;
  def.color = PIOLA_RENDER_COLOR_INVERTED;
  test_sphere s = test_uv_sphere(128, 64, 0.3, 0, 0, 0.3);
  piola_render_mesh m = sphere_mesh(&s);
  uint8_t *flags = calloc((size_t)s.triangle_count, 1);
  for (int32_t t = 0; t < s.triangle_count; t += 7) flags[t] = 1;
  m.inverted = flags;
  piola_obstacle_def plane = piola_default_obstacle_def();
  plane.type = PIOLA_OBSTACLE_PLANE;
  piola_obstacle_def box = piola_default_obstacle_def();
  box.type = PIOLA_OBSTACLE_BOX;
  box.center = (piola_vec3){0.6, 0.2, 0.15};
  box.half_extents = (piola_vec3){0.15, 0.15, 0.15};
  piola_image a = {0}, b = {0};
  for (int threads = 1; threads <= 2; ++threads) {
    piola_set_thread_count(threads);
    piola_renderer *r;
    assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
    assert_int_equal(piola_renderer_add_obstacle(r, &plane), PIOLA_OK);
    assert_int_equal(piola_renderer_add_obstacle(r, &box), PIOLA_OK);
    piola_renderer_fit_camera(r, (piola_vec3){-0.3, -0.3, 0}, (piola_vec3){0.8, 0.4, 0.6});
    assert_int_equal(piola_renderer_render(r, &m, threads == 1 ? &a : &b), PIOLA_OK);
    if (threads == 2) {
      piola_image c = {0};
      assert_int_equal(piola_renderer_render(r, &m, &c), PIOLA_OK);
      assert_memory_equal(b.rgb, c.rgb, 3 * (size_t)b.width * (size_t)b.height);
      piola_image_free(&c);
    }
    piola_renderer_destroy(r);
  }
  piola_set_thread_count(0);
  keep("determinism_scene", &a);
  assert_memory_equal(a.rgb, b.rgb, 3 * (size_t)a.width * (size_t)a.height);
  piola_image_free(&a);
  piola_image_free(&b);
  free(flags);
  test_sphere_free(&s);
}

/* A coarse triangulated sphere lying exactly on an obstacle sphere (every vertex on its
 * surface, as draped cloth is): the flat triangles cut into the obstacle by their sagitta,
 * yet the mesh covers the obstacle everywhere around the image centre, with no patches of
 * the obstacle showing through. */
static void test_mesh_lying_on_an_obstacle_is_not_pierced(void **state) {
  (void)state;
  piola_render_def def = axis_camera(4, 40);
  piola_obstacle_def ob = piola_default_obstacle_def();
  ob.type = PIOLA_OBSTACLE_SPHERE;
  ob.radius = 0.5;
  test_sphere s = test_uv_sphere(24, 12, 0.5, 0, 0, 0);
  piola_render_mesh m = sphere_mesh(&s);
  piola_image only_obstacle = {0}, both = {0};
  piola_renderer *r;
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
  assert_int_equal(piola_renderer_add_obstacle(r, &ob), PIOLA_OK);
  assert_int_equal(piola_renderer_render(r, NULL, &only_obstacle), PIOLA_OK);
  assert_int_equal(piola_renderer_render(r, &m, &both), PIOLA_OK);
  piola_renderer_destroy(r);
  /* the sphere's disk has a radius of about 0.5 * 494 / 4 = 62 pixels: check +-30 */
  for (int y = def.height / 2 - 30; y <= def.height / 2 + 30; ++y)
    for (int x = def.width / 2 - 30; x <= def.width / 2 + 30; ++x)
      assert_false(same_rgb(&only_obstacle, &both, x, y));
  piola_image_free(&only_obstacle);
  piola_image_free(&both);
  test_sphere_free(&s);
}

/* Once the camera is fitted, planes are a finite floor: a wall (a plane facing sideways)
 * is not drawn at all, and the floor covers fewer pixels than the same plane unbounded
 * (drawn by a renderer with the same camera set and never fitted), yet still the pixels
 * under the framed box. */
static int count_differing(const piola_image *a, const piola_image *b) {
  int n = 0;
  for (int y = 0; y < a->height; ++y)
    for (int x = 0; x < a->width; ++x) n += !same_rgb(a, b, x, y);
  return n;
}

static void test_fitted_planes_are_a_finite_floor(void **state) {
  (void)state;
  piola_render_def def = piola_default_render_def();
  def.width = 320, def.height = 240;
  def.ground = false;
  def.shadows = false;
  piola_obstacle_def floor_def = piola_default_obstacle_def(), wall = piola_default_obstacle_def();
  floor_def.type = wall.type = PIOLA_OBSTACLE_PLANE;
  floor_def.center = (piola_vec3){0, 0, -0.5};
  floor_def.axis = (piola_vec3){0, 0, 1};
  wall.center = (piola_vec3){0, 2, 0}; /* behind the box, facing the camera */
  wall.axis = (piola_vec3){0, -1, 0};
  piola_vec3 lo = {-0.5, -0.5, -0.5}, hi = {0.5, 0.5, 0.5};
  piola_image sky = {0}, with_wall = {0}, fitted = {0}, unbounded = {0};
  piola_renderer *r;
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
  piola_renderer_fit_camera(r, lo, hi);
  piola_vec3 pos, target;
  piola_renderer_camera(r, &pos, &target);
  assert_int_equal(piola_renderer_render(r, NULL, &sky), PIOLA_OK);
  assert_int_equal(piola_renderer_add_obstacle(r, &wall), PIOLA_OK);
  assert_int_equal(piola_renderer_render(r, NULL, &with_wall), PIOLA_OK);
  assert_int_equal(count_differing(&sky, &with_wall), 0);
  assert_int_equal(piola_renderer_add_obstacle(r, &floor_def), PIOLA_OK);
  assert_int_equal(piola_renderer_render(r, NULL, &fitted), PIOLA_OK);
  piola_renderer_destroy(r);
  def.camera_set = true;
  def.camera_position = pos, def.camera_target = target;
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
  assert_int_equal(piola_renderer_add_obstacle(r, &floor_def), PIOLA_OK);
  assert_int_equal(piola_renderer_render(r, NULL, &unbounded), PIOLA_OK);
  piola_renderer_destroy(r);
  int finite = count_differing(&sky, &fitted), whole = count_differing(&sky, &unbounded);
  assert_true(finite > 0);
  assert_true(finite < whole);
  /* the image centre looks at the box centre, above the floor's middle: floor there */
  assert_false(same_rgb(&sky, &fitted, def.width / 2, def.height - 1));
  piola_image_free(&sky);
  piola_image_free(&with_wall);
  piola_image_free(&fitted);
  piola_image_free(&unbounded);
}

/* An obstacle added after the camera was fitted to the bodies alone (piola render without
 * --frame-obstacles) is not cut by the fallback floor: a sphere under a sheet at 0.3 m
 * lowers the floor from the sheet to the sphere's bottom; a plane or a far obstacle does
 * not. */
static void test_fallback_floor_passes_under_obstacles(void **state) {
  (void)state;
  piola_render_def def = piola_default_render_def();
  piola_renderer *r;
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
  piola_renderer_fit_camera(r, (piola_vec3){-0.3, -0.3, 0.3}, (piola_vec3){0.3, 0.3, 0.31});
  assert_true(fabs(r->ground_height - 0.3) < 1e-12);
  piola_obstacle_def far = piola_default_obstacle_def();
  far.type = PIOLA_OBSTACLE_SPHERE;
  far.center = (piola_vec3){30, 0, -5};
  far.radius = 0.2;
  assert_int_equal(piola_renderer_add_obstacle(r, &far), PIOLA_OK);
  piola_obstacle_def plane = piola_default_obstacle_def();
  plane.type = PIOLA_OBSTACLE_PLANE;
  plane.center = (piola_vec3){0, 0, -1};
  plane.axis = (piola_vec3){0, 0, 1};
  assert_int_equal(piola_renderer_add_obstacle(r, &plane), PIOLA_OK);
  assert_true(fabs(r->ground_height - 0.3) < 1e-12);
  piola_obstacle_def ball = piola_default_obstacle_def();
  ball.type = PIOLA_OBSTACLE_SPHERE;
  ball.center = (piola_vec3){0, 0, 0.1};
  ball.radius = 0.2;
  assert_int_equal(piola_renderer_add_obstacle(r, &ball), PIOLA_OK);
  assert_true(fabs(r->ground_height - (-0.1)) < 1e-9);
  piola_renderer_destroy(r);
}

static void test_bad_arguments_are_refused(void **state) {
  (void)state;
  piola_renderer *r = NULL;
  piola_render_def def = piola_default_render_def();
  def.width = 8;
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_ERROR_INVALID_ARGUMENT);
  def = piola_default_render_def();
  def.fov_degrees = 180;
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_ERROR_INVALID_ARGUMENT);
  def = piola_default_render_def();
  def.camera_set = true;
  def.camera_target = def.camera_position;
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_ERROR_INVALID_ARGUMENT);
  def = piola_default_render_def();
  assert_int_equal(piola_renderer_create(&def, &r), PIOLA_OK);
  double x[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  int32_t tri[3] = {0, 1, 3};
  piola_render_mesh m = {3, x, 1, tri, NULL, NULL, NULL, 0};
  piola_image img = {0};
  assert_int_equal(piola_renderer_render(r, &m, &img), PIOLA_ERROR_INVALID_ARGUMENT);
  assert_non_null(strstr(piola_last_error(), "triangle 0"));
  piola_obstacle_def bad = piola_default_obstacle_def();
  bad.type = PIOLA_OBSTACLE_SPHERE;
  bad.radius = -1;
  assert_int_not_equal(piola_renderer_add_obstacle(r, &bad), PIOLA_OK);
  assert_int_equal(piola_renderer_obstacle_count(r), 0);
  piola_renderer_destroy(r);
  piola_image_free(&img);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_mesh_sphere_silhouette_area),
      cmocka_unit_test(test_obstacle_sphere_silhouette_area),
      cmocka_unit_test(test_depth_compositing_of_mesh_and_obstacle),
      cmocka_unit_test(test_patch_lying_on_the_ground_is_visible),
      cmocka_unit_test(test_ground_fills_the_view_below_the_horizon),
      cmocka_unit_test(test_inverted_highlight_present_exactly_when_flagged),
      cmocka_unit_test(test_value_colors_and_color_bar),
      cmocka_unit_test(test_uniform_field_is_one_colour),
      cmocka_unit_test(test_font_keeps_the_case_of_letters),
      cmocka_unit_test(test_auto_camera_frames_the_object),
      cmocka_unit_test(test_mesh_and_moving_obstacles),
      cmocka_unit_test(test_shadow_of_a_sphere_on_the_ground),
      cmocka_unit_test(test_supersampling_averages_a_larger_render),
      cmocka_unit_test(test_deterministic_for_any_thread_count),
      cmocka_unit_test(test_mesh_lying_on_an_obstacle_is_not_pierced),
      cmocka_unit_test(test_fitted_planes_are_a_finite_floor),
      cmocka_unit_test(test_fallback_floor_passes_under_obstacles),
      cmocka_unit_test(test_bad_arguments_are_refused),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
