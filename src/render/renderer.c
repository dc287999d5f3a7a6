/* The renderer object: settings, obstacles, camera framing, and the frame pipeline (ray pass,
 * triangles, colour bar). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "piola/threads.h"
#include "render/render_internal.h"

piola_render_def piola_default_render_def(void) {
  piola_render_def d;
  memset(&d, 0, sizeof d);
  d.width = 1280;
  d.height = 720;
  d.color = PIOLA_RENDER_COLOR_PLAIN;
  d.camera_set = false;
  d.camera_position = (piola_vec3){3, -4, 2.5};
  d.camera_target = (piola_vec3){0, 0, 0};
  d.up = (piola_vec3){0, 0, 1};
  d.fov_degrees = 40;
  d.ground = true;
  d.ground_height = 0;
  d.shadows = true;
  d.supersample = 1;
  d.value_min = 0;
  d.value_max = 0;
  d.value_label = NULL;
  return d;
}

static bool finite3(vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

/* A "nice" length near x: 1, 2 or 5 times a power of ten. */
static double nice_length(double x) {
  if (!(x > 0) || !isfinite(x)) return 0.1;
  double p = pow(10.0, floor(log10(x)));
  double m = x / p;
  return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
}

piola_status piola_renderer_create(const piola_render_def *def, piola_renderer **out) {
  if (!def || !out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "renderer: NULL argument");
  *out = NULL;
  if (def->width < 16 || def->width > 16384 || def->height < 16 || def->height > 16384)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "render: width and height must be in 16..16384, got %d x %d", (int)def->width,
                      (int)def->height);
  if (!(def->fov_degrees > 1 && def->fov_degrees < 170))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "render: fov_degrees must be in (1, 170), got %g", def->fov_degrees);
  if ((unsigned)def->color > PIOLA_RENDER_COLOR_VALUE)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "render: unknown colour mode %d",
                      (int)def->color);
  double un = vec3_norm(def->up);
  if (!(un > 0) || !finite3(def->up))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "render: up must be a nonzero finite vector");
  if (def->camera_set) {
    if (!finite3(def->camera_position) || !finite3(def->camera_target))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "render: camera position and target must be finite");
    vec3 f = vec3_sub(def->camera_target, def->camera_position);
    if (!(vec3_norm(f) > 0))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "render: camera position equals its target");
  }
  if (def->supersample < 1 || def->supersample > 4 ||
      (int64_t)def->width * def->supersample > 16384 ||
      (int64_t)def->height * def->supersample > 16384)
    return PIOLA_FAIL(
        PIOLA_ERROR_INVALID_ARGUMENT,
        "render: supersample must be in 1..4 (and the supersampled size at most 16384), got %d",
        (int)def->supersample);
  if (!isfinite(def->ground_height) || !isfinite(def->value_min) || !isfinite(def->value_max))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "render: ground_height and value range must be finite");
  piola_renderer *r = calloc(1, sizeof *r);
  if (!r) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "renderer: out of memory");
  r->def = *def;
  r->def.up = vec3_scale(def->up, 1.0 / un);
  if (def->value_label) snprintf(r->label, sizeof r->label, "%s", def->value_label);
  r->def.value_label = NULL;
  r->camera_position = def->camera_position;
  r->camera_target = def->camera_target;
  r->ground_height = def->ground_height;
  r->scene_size =
      def->camera_set ? vec3_norm(vec3_sub(def->camera_target, def->camera_position)) : 1.0;
  r->checker_size = nice_length(r->scene_size / 6);
  r->floor_half_size = INFINITY;
  *out = r;
  return PIOLA_OK;
}

void piola_renderer_destroy(piola_renderer *r) {
  if (!r) return;
  for (int32_t i = 0; i < r->obstacle_count; ++i) {
    piola_obstacle_destroy(r->obstacles[i]);
    piola_tri_mesh_free(&r->obstacle_meshes[i]);
  }
  free(r->obstacles);
  free(r->obstacle_meshes);
  free(r->depth);
  free(r);
}

/* Where the camera was fitted to the bodies alone (before the obstacles were added), the
 * fallback floor through their lowest point would cut through a bounded obstacle under
 * them and hide it (a cloth draped over a sphere showed no sphere): the floor goes down to
 * the bottom of the bounding sphere (at t = 0) of each bounded obstacle of comparable size
 * near the bodies, the ones piola_renderer_fit_camera frames. */
static void lower_floor_below(piola_renderer *r, const piola_obstacle *o) {
  if (piola_obstacle_shape_type(o) == PIOLA_OBSTACLE_PLANE) return;
  const double radius = 0.5 * r->scene_size;
  vec3 c0;
  double b;
  piola_obstacle_bounding_sphere(o, &c0, &b);
  if (!(b < 2 * radius)) return;
  piola_obstacle_pose pose = piola_obstacle_pose_at(o, 0);
  vec3 c = vec3_add(mat3_mul_vec(pose.rotation, c0), pose.translation);
  if (!(vec3_norm(vec3_sub(c, r->floor_center)) < 3 * radius)) return;
  r->ground_height = fmin(r->ground_height, vec3_dot(c, r->def.up) - b);
}

piola_status piola_renderer_add_obstacle(piola_renderer *r, const piola_obstacle_def *def) {
  if (!r || !def) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "renderer: NULL argument");
  if (r->obstacle_count == r->obstacle_capacity) {
    int32_t cap = r->obstacle_capacity ? 2 * r->obstacle_capacity : 8;
    piola_obstacle **grown = realloc(r->obstacles, (size_t)cap * sizeof *grown);
    if (grown) r->obstacles = grown;
    piola_tri_mesh *grown_meshes = realloc(r->obstacle_meshes, (size_t)cap * sizeof *grown_meshes);
    if (grown_meshes) r->obstacle_meshes = grown_meshes;
    if (!grown || !grown_meshes)
      return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "renderer: out of memory");
    r->obstacle_capacity = cap;
  }
  piola_obstacle *o = NULL;
  PIOLA_TRY(piola_obstacle_create(def, &o));
  piola_tri_mesh copy = {0};
  if (def->type == PIOLA_OBSTACLE_MESH) { /* validated by piola_obstacle_create */
    const piola_tri_mesh *m = def->mesh;
    copy.vertex_count = m->vertex_count;
    copy.triangle_count = m->triangle_count;
    copy.positions = malloc(3 * (size_t)m->vertex_count * sizeof *copy.positions);
    copy.triangles = malloc(3 * (size_t)m->triangle_count * sizeof *copy.triangles);
    if (!copy.positions || !copy.triangles) {
      piola_tri_mesh_free(&copy);
      piola_obstacle_destroy(o);
      return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "renderer: out of memory");
    }
    memcpy(copy.positions, m->positions, 3 * (size_t)m->vertex_count * sizeof *copy.positions);
    memcpy(copy.triangles, m->triangles, 3 * (size_t)m->triangle_count * sizeof *copy.triangles);
  }
  r->obstacle_meshes[r->obstacle_count] = copy;
  r->obstacles[r->obstacle_count++] = o;
  if (isfinite(r->floor_half_size)) lower_floor_below(r, o);
  return PIOLA_OK;
}

int32_t piola_renderer_obstacle_count(const piola_renderer *r) { return r ? r->obstacle_count : 0; }

void piola_renderer_fit_camera(piola_renderer *r, piola_vec3 lo, piola_vec3 hi) {
  if (!r || !finite3(lo) || !finite3(hi)) return;
  vec3 up = r->def.up;
  vec3 center = vec3_scale(vec3_add(lo, hi), 0.5);
  double radius = 0.5 * vec3_norm(vec3_sub(hi, lo));
  if (!(radius > 1e-9)) radius = 0.5;
  /* Obstacles the solids meet belong in the picture: grow the box by the bounding sphere
   * (at t = 0) of each bounded obstacle of comparable size near it. Big or far ones (a
   * floor slab, a distant wall) would shrink the solids to a speck and are left out. */
  vec3 glo = lo, ghi = hi;
  for (int32_t i = 0; i < r->obstacle_count; ++i) {
    vec3 c0;
    double b;
    piola_obstacle_bounding_sphere(r->obstacles[i], &c0, &b);
    if (!(b < 2 * radius)) continue;
    piola_obstacle_pose pose = piola_obstacle_pose_at(r->obstacles[i], 0);
    vec3 c = vec3_add(mat3_mul_vec(pose.rotation, c0), pose.translation);
    if (!(vec3_norm(vec3_sub(c, center)) < 3 * radius)) continue;
    glo = (vec3){fmin(glo.x, c.x - b), fmin(glo.y, c.y - b), fmin(glo.z, c.z - b)};
    ghi = (vec3){fmax(ghi.x, c.x + b), fmax(ghi.y, c.y + b), fmax(ghi.z, c.z + b)};
  }
  lo = glo, hi = ghi;
  center = vec3_scale(vec3_add(lo, hi), 0.5);
  radius = 0.5 * vec3_norm(vec3_sub(hi, lo));
  /* lowest corner of the box along up: the fallback ground */
  double low = INFINITY;
  for (int k = 0; k < 8; ++k) {
    vec3 c = {(k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z};
    double h = vec3_dot(c, up);
    if (h < low) low = h;
  }
  r->ground_height = low;
  r->scene_size = 2 * radius;
  r->floor_center = center;
  r->floor_half_size = 4 * radius;
  r->checker_size = nice_length(radius / 3);
  if (r->def.camera_set) return;
  /* A 3/4 view: from the front right (world -y, +x for z up) and 30 degrees above. Build
   * the horizontal directions from `up` so other up axes work too. */
  vec3 a = fabs(up.z) < 0.9 ? (vec3){0, 0, 1} : (vec3){0, 1, 0};
  vec3 side = vec3_cross(a, up);
  side = vec3_scale(side, 1.0 / vec3_norm(side)); /* +x for z up */
  vec3 front = vec3_cross(up, side);              /* +y for z up */
  vec3 dir =
      vec3_add(vec3_add(vec3_scale(side, 0.5), vec3_scale(front, -0.866)), vec3_scale(up, 0.0));
  double elev = 25.0 * M_PI / 180;
  dir = vec3_add(vec3_scale(dir, cos(elev)), vec3_scale(up, sin(elev)));
  double vfov = r->def.fov_degrees * M_PI / 180;
  double hfov = 2 * atan(tan(vfov / 2) * r->def.width / r->def.height);
  double half = 0.5 * fmin(vfov, hfov);
  double dist = radius / sin(half) * 1.08;
  r->camera_target = center;
  r->camera_position = vec3_add(center, vec3_scale(dir, dist));
}

void piola_renderer_camera(const piola_renderer *r, piola_vec3 *position, piola_vec3 *target) {
  if (!r) return;
  if (position) *position = r->camera_position;
  if (target) *target = r->camera_target;
}

render_camera piola__render_camera(const piola_renderer *r) {
  render_camera c;
  c.position = r->camera_position;
  vec3 f = vec3_sub(r->camera_target, r->camera_position);
  c.forward = vec3_scale(f, 1.0 / vec3_norm(f));
  vec3 up = r->def.up;
  vec3 right = vec3_cross(c.forward, up);
  if (vec3_norm(right) < 1e-9) { /* looking straight along up: any horizontal right */
    vec3 a = fabs(up.x) < 0.9 ? (vec3){1, 0, 0} : (vec3){0, 1, 0};
    right = vec3_cross(c.forward, a);
  }
  c.right = vec3_scale(right, 1.0 / vec3_norm(right));
  c.up = vec3_cross(c.right, c.forward);
  /* key light from the upper left of the view, fill from the right */
  c.key = vec3_add(vec3_add(vec3_scale(c.right, -0.45), vec3_scale(c.up, 0.7)),
                   vec3_scale(c.forward, -0.55));
  c.key = vec3_scale(c.key, 1.0 / vec3_norm(c.key));
  c.fill = vec3_add(vec3_add(vec3_scale(c.right, 0.7), vec3_scale(c.up, -0.2)),
                    vec3_scale(c.forward, -0.68));
  c.fill = vec3_scale(c.fill, 1.0 / vec3_norm(c.fill));
  c.width = r->def.width;
  c.height = r->def.height;
  c.focal_px = 0.5 * r->def.height / tan(0.5 * r->def.fov_degrees * M_PI / 180);
  return c;
}

static int compare_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* 0 and the 99th percentile of the finite values: energy densities are heavy-tailed (a few
 * crushed elements dwarf the rest), and a max-scaled map would show nothing else. Values
 * that are all equal give lo == hi, a uniform range (one colour); no finite value gives 0..1. */
static void auto_range(const double *v, int32_t n, double *lo, double *hi) {
  double *s = malloc((size_t)(n > 0 ? n : 1) * sizeof *s);
  int32_t m = 0;
  double mn = INFINITY;
  if (s)
    for (int32_t i = 0; i < n; ++i)
      if (isfinite(v[i])) {
        s[m++] = v[i];
        if (v[i] < mn) mn = v[i];
      }
  *lo = 0;
  *hi = 1;
  if (m > 0) {
    qsort(s, (size_t)m, sizeof *s, compare_double);
    *lo = mn < 0 ? mn : 0;
    *hi = s[(int32_t)floor(0.99 * (m - 1))];
    if (!(*hi > *lo)) *hi = s[m - 1];
  }
  free(s);
}

static const float part_palette[6][3] = {{86, 140, 205},  {64, 170, 160}, {226, 186, 84},
                                         {150, 128, 205}, {120, 184, 92}, {200, 200, 210}};

static piola_status render_once(piola_renderer *r, const piola_render_mesh *mesh,
                                piola_image *image);

/* Supersampling: render at s times the size and average each s x s block, which smooths
 * edges and the far checkerboard at s^2 times the cost. */
piola_status piola_renderer_render(piola_renderer *r, const piola_render_mesh *mesh,
                                   piola_image *image) {
  if (!r || !image) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "render: NULL argument");
  int s = r->def.supersample;
  if (s <= 1) return render_once(r, mesh, image);
  piola_image big = {0};
  int32_t w = r->def.width, h = r->def.height;
  r->def.width = w * s, r->def.height = h * s;
  piola_status st = render_once(r, mesh, &big);
  r->def.width = w, r->def.height = h;
  if (st == PIOLA_OK) st = piola__image_resize(image, w, h);
  if (st == PIOLA_OK) {
#pragma omp parallel for schedule(static) num_threads(piola_thread_count())
    for (int32_t y = 0; y < h; ++y)
      for (int32_t x = 0; x < w; ++x) {
        uint32_t sum[3] = {0, 0, 0};
        for (int dy = 0; dy < s; ++dy)
          for (int dx = 0; dx < s; ++dx) {
            const uint8_t *p =
                big.rgb + 3 * ((size_t)(y * s + dy) * (size_t)big.width + (size_t)(x * s + dx));
            sum[0] += p[0], sum[1] += p[1], sum[2] += p[2];
          }
        uint8_t *q = image->rgb + 3 * ((size_t)y * (size_t)w + (size_t)x);
        for (int c = 0; c < 3; ++c)
          q[c] = (uint8_t)((sum[c] + (uint32_t)(s * s) / 2) / (uint32_t)(s * s));
      }
  }
  piola_image_free(&big);
  return st;
}

static piola_status render_once(piola_renderer *r, const piola_render_mesh *mesh,
                                piola_image *image) {
  if (mesh) {
    if (mesh->triangle_count < 0 || mesh->vertex_count < 0 ||
        (mesh->triangle_count > 0 && (!mesh->triangles || !mesh->positions)))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "render: mesh needs positions and triangles");
    for (int64_t i = 0; i < 3 * (int64_t)mesh->triangle_count; ++i)
      if (mesh->triangles[i] < 0 || mesh->triangles[i] >= mesh->vertex_count)
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                          "render: triangle %lld has a vertex out of range", (long long)(i / 3));
    if (r->def.color == PIOLA_RENDER_COLOR_VALUE && mesh->triangle_count > 0 && !mesh->values)
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "render: value colouring needs per-face values");
  }
  double time = mesh ? mesh->time : 0;
  PIOLA_TRY(piola__image_resize(image, r->def.width, r->def.height));
  size_t pixels = (size_t)r->def.width * (size_t)r->def.height;
  if (r->depth_capacity < pixels) {
    float *d = realloc(r->depth, pixels * sizeof *d);
    if (!d) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "render: out of memory");
    r->depth = d;
    r->depth_capacity = pixels;
  }
  render_camera cam = piola__render_camera(r);
  render_shadow shadow = {.size = 0};
  if (r->def.shadows) piola__render_shadow_build(piola__render_sun(&cam, r->def.up), mesh, &shadow);
  piola__render_ray_pass(r, &cam, time, &shadow, r->depth, image->rgb);
  piola__render_shadow_free(&shadow);

  for (int32_t i = 0; i < r->obstacle_count; ++i) {
    const piola_tri_mesh *om = &r->obstacle_meshes[i];
    if (om->triangle_count == 0) continue;
    piola_obstacle_pose st = piola_obstacle_pose_at(r->obstacles[i], time);
    double *x = malloc(3 * (size_t)om->vertex_count * sizeof *x);
    float *face_rgb = malloc(3 * (size_t)om->triangle_count * sizeof *face_rgb);
    if (!x || !face_rgb) {
      free(x), free(face_rgb);
      return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "render: out of memory");
    }
    for (int32_t v = 0; v < om->vertex_count; ++v)
      vec3_store(x + 3 * (size_t)v,
                 vec3_add(mat3_mul_vec(st.rotation, vec3_load(om->positions + 3 * (size_t)v)),
                          st.translation));
    for (int32_t t = 0; t < om->triangle_count; ++t)
      face_rgb[3 * t] = RENDER_OBSTACLE_R, face_rgb[3 * t + 1] = RENDER_OBSTACLE_G,
                   face_rgb[3 * t + 2] = RENDER_OBSTACLE_B;
    piola_render_mesh posed = {
        om->vertex_count, x, om->triangle_count, om->triangles, NULL, NULL, NULL, time};
    piola_status st_draw = piola__render_triangles(&cam, &posed, face_rgb, r->depth, image->rgb);
    free(x), free(face_rgb);
    PIOLA_TRY(st_draw);
  }
  double lo = r->def.value_min, hi = r->def.value_max;
  int32_t nt = mesh ? mesh->triangle_count : 0;
  if (nt > 0) {
    float *face_rgb = malloc(3 * (size_t)nt * sizeof *face_rgb);
    if (!face_rgb) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "render: out of memory");
    if (r->def.color == PIOLA_RENDER_COLOR_VALUE && !(hi > lo))
      auto_range(mesh->values, nt, &lo, &hi);
    for (int32_t t = 0; t < nt; ++t) {
      float *c = face_rgb + 3 * (size_t)t;
      if (r->def.color == PIOLA_RENDER_COLOR_VALUE) {
        render_rgb m =
            piola__render_colormap(piola__render_range_position(mesh->values[t], lo, hi));
        c[0] = m.r, c[1] = m.g, c[2] = m.b;
      } else if (r->def.color == PIOLA_RENDER_COLOR_INVERTED) {
        bool inv = mesh->inverted && mesh->inverted[t];
        c[0] = inv ? RENDER_INVERTED_R : 176;
        c[1] = inv ? RENDER_INVERTED_G : 184;
        c[2] = inv ? RENDER_INVERTED_B : 196;
      } else {
        int32_t p = mesh->parts ? mesh->parts[t] : 0;
        const float *pc = part_palette[(p < 0 ? -p : p) % 6];
        c[0] = pc[0], c[1] = pc[1], c[2] = pc[2];
      }
    }
    piola_status st = piola__render_triangles(&cam, mesh, face_rgb, r->depth, image->rgb);
    free(face_rgb);
    PIOLA_TRY(st);
  } else if (r->def.color == PIOLA_RENDER_COLOR_VALUE && !(hi > lo)) {
    lo = 0, hi = 1;
  }
  if (r->def.color == PIOLA_RENDER_COLOR_VALUE) piola__render_color_bar(image, lo, hi, r->label);
  return PIOLA_OK;
}
