/* The ray pass: one camera ray per pixel finds the background, the ground and the
 * obstacles, and leaves their depth for the triangle pass.
 *
 * Planes are intersected analytically. Other obstacles are sphere-traced through their
 * signed distance, only inside their bounding sphere; a hit is accepted when the distance is
 * below a fraction of the pixel's footprint, so edges are as sharp as the pixel grid. The
 * pose of every obstacle is computed once per frame.
 *
 * The ground is stored a little deeper than it is (GROUND_DEPTH_BIAS, relative): a solid
 * resting exactly on a plane obstacle (a puddle whose nodes were projected onto it) has the
 * same depth as the plane up to rounding, and a tie must go to the solid, never to the
 * ground it lies on. Traced obstacles are likewise stored OBSTACLE_DEPTH_BIAS_PX pixel
 * footprints deeper: cloth draped over a sphere rests on it, and its flat triangles cut
 * into the curved surface by their sagitta (e^2 / 8R, a fraction of a millimetre), so the
 * obstacle would show through the cloth in patches. Two pixels are invisible as depth. */
#include <math.h>
#include <stdlib.h>

#include "piola/threads.h"
#include "render/render_internal.h"

/* Relative depth offset of the ground: 1e-4 of the view depth (0.5 mm at 5 m) is far above
 * float rounding (6e-8) and far below anything a viewer could see through. */
#define GROUND_DEPTH_BIAS 1e-4
#define OBSTACLE_DEPTH_BIAS_PX 2.0

/* A plane drawn as a floor fades out over this outer fraction of its half side. */
#define FLOOR_FADE 0.2

/* Planes facing further than this from `up` (cos 60 degrees) are walls or ceilings: not
 * drawn once the floor is finite. */
#define FLOOR_MIN_UP 0.5

typedef struct ground_plane {
  vec3 normal, t1, t2, point; /* unit normal; in-plane axes; a point on it */
  vec3 floor_origin;          /* the floor's centre on the plane */
  double camera_height;       /* signed distance of the camera above the plane, m */
  float light;                /* diffuse light of the plane: one value, lights are directional */
} ground_plane;

typedef struct traced_obstacle {
  const piola_obstacle *obstacle;
  piola_obstacle_pose pose;
  vec3 center; /* world centre of the bounding sphere at this pose */
  double radius;
} traced_obstacle;

static ground_plane make_plane(const render_camera *cam, vec3 point, vec3 n, vec3 camera) {
  ground_plane g;
  g.normal = n;
  g.point = point;
  vec3 a = fabs(n.z) < 0.9 ? (vec3){0, 0, 1} : (vec3){1, 0, 0};
  g.t1 = vec3_cross(n, a);
  g.t1 = vec3_scale(g.t1, 1.0 / vec3_norm(g.t1));
  g.t2 = vec3_cross(n, g.t1);
  g.camera_height = vec3_dot(vec3_sub(camera, point), n);
  float spec;
  g.light = render_light(cam, n, vec3_neg(cam->forward), &spec);
  return g;
}

static void background(const render_camera *c, int y, float out[3]) {
  float s = (float)y / (float)(c->height > 1 ? c->height - 1 : 1);
  out[0] = 236 - 40 * s;
  out[1] = 239 - 36 * s;
  out[2] = 244 - 28 * s;
}

void piola__render_ray_pass(const piola_renderer *r, const render_camera *cam, double time,
                            const render_shadow *shadow, float *depth, uint8_t *rgb) {
  enum { MAX_PLANES = 16, MAX_TRACED = 64 };
  ground_plane planes[MAX_PLANES];
  traced_obstacle traced[MAX_TRACED];
  int np = 0, nt = 0;
  for (int32_t i = 0; i < r->obstacle_count; ++i) {
    const piola_obstacle *o = r->obstacles[i];
    piola_obstacle_pose pose = piola_obstacle_pose_at(o, time);
    piola_obstacle_type type = piola_obstacle_shape_type(o);
    if (type == PIOLA_OBSTACLE_MESH) continue; /* rasterized with the triangles */
    if (type == PIOLA_OBSTACLE_PLANE) {
      if (np == MAX_PLANES) continue;
      vec3 n;
      double d = piola_obstacle_posed_distance(o, &pose, cam->position, &n);
      if (isfinite(r->floor_half_size) && vec3_dot(n, r->def.up) < FLOOR_MIN_UP) continue;
      vec3 foot = vec3_sub(cam->position, vec3_scale(n, d));
      planes[np++] = make_plane(cam, foot, n, cam->position);
    } else if (nt < MAX_TRACED) {
      traced_obstacle *t = &traced[nt++];
      t->obstacle = o;
      t->pose = pose;
      vec3 center;
      piola_obstacle_bounding_sphere(o, &center, &t->radius);
      t->center = vec3_add(mat3_mul_vec(pose.rotation, center), pose.translation);
    }
  }
  if (np == 0 && r->def.ground)
    planes[np++] =
        make_plane(cam, vec3_scale(r->def.up, r->ground_height), r->def.up, cam->position);
  const double floor_half = r->floor_half_size;
  for (int k = 0; k < np; ++k) {
    ground_plane *g = &planes[k];
    g->floor_origin =
        vec3_sub(r->floor_center, vec3_scale(g->normal, vec3_dot(vec3_sub(r->floor_center, g->point),
                                                                 g->normal)));
  }

  const double checker = r->checker_size, fog = 10 * (r->scene_size > 0 ? r->scene_size : 1);
  const double inv_f = 1.0 / cam->focal_px;
  const int W = cam->width, H = cam->height;
#pragma omp parallel for schedule(dynamic, 4) num_threads(piola_thread_count())
  for (int y = 0; y < H; ++y) {
    float bg[3];
    background(cam, y, bg);
    for (int x = 0; x < W; ++x) {
      vec3 dir =
          vec3_add(cam->forward, vec3_add(vec3_scale(cam->right, (x + 0.5 - 0.5 * W) * inv_f),
                                          vec3_scale(cam->up, -(y + 0.5 - 0.5 * H) * inv_f)));
      double dir_len = vec3_norm(dir);
      vec3 dn = vec3_scale(dir, 1.0 / dir_len);
      double best = INFINITY; /* view depth, m */
      bool ground_nearest = false, obstacle_nearest = false;
      float col[3] = {bg[0], bg[1], bg[2]};
      for (int k = 0; k < np; ++k) {
        const ground_plane *g = &planes[k];
        double denom = vec3_dot(g->normal, dir);
        if (!(g->camera_height > 0) || !(denom < 0)) continue;
        double s = -g->camera_height / denom;
        if (!(s < best)) continue;
        vec3 p = vec3_add(cam->position, vec3_scale(dir, s));
        double edge = 0; /* 0 inside the floor, 1 at its border */
        if (isfinite(floor_half)) {
          vec3 from = vec3_sub(p, g->floor_origin);
          double m = fmax(fabs(vec3_dot(from, g->t1)), fabs(vec3_dot(from, g->t2))) / floor_half;
          if (m >= 1) continue;
          edge = m > 1 - FLOOR_FADE ? (m - (1 - FLOOR_FADE)) / FLOOR_FADE : 0;
        }
        best = s;
        ground_nearest = true;
        obstacle_nearest = false;
        vec3 rel = vec3_sub(p, g->point);
        double u = vec3_dot(rel, g->t1) / checker, v = vec3_dot(rel, g->t2) / checker;
        long parity = ((long)floor(u) + (long)floor(v)) & 1;
        float base = parity ? 206.f : 160.f;
        /* far away the squares are smaller than a pixel: blend to their mean, then fog */
        double footprint = s * dir_len * inv_f / fabs(vec3_dot(dn, g->normal)) / checker;
        float w = (float)fmin(1.0, footprint);
        base = base * (1 - w) + 183.f * w;
        double q = s * dir_len / fog;
        float fade = q < 1e-3 ? 0.f : (float)(1 - exp(-q * q));
        fade = fade + (1 - fade) * (float)(edge * edge);
        float lit = base * (0.55f + 0.45f * g->light);
        if (shadow->size > 0) lit *= (float)(1 - 0.42 * piola__render_shadow_at(shadow, p));
        col[0] = lit * (1 - fade) + bg[0] * fade;
        col[1] = lit * (1 - fade) + bg[1] * fade;
        col[2] = (lit + 4) * (1 - fade) + bg[2] * fade;
      }
      for (int k = 0; k < nt; ++k) {
        const traced_obstacle *t = &traced[k];
        vec3 oc = vec3_sub(cam->position, t->center);
        double b = vec3_dot(oc, dn), cc = vec3_norm2(oc) - t->radius * t->radius;
        double disc = b * b - cc;
        if (!(disc >= 0)) continue;
        double sq = sqrt(disc), t0 = -b - sq, t1 = -b + sq;
        if (t1 <= 0 || t0 / dir_len >= best) continue;
        double s = t0 > 0 ? t0 : 0, s_max = fmin(t1, best * dir_len);
        vec3 n = {0, 0, 1};
        bool hit = false;
        for (int it = 0; it < 200 && s <= s_max; ++it) {
          vec3 p = vec3_add(cam->position, vec3_scale(dn, s));
          double d = piola_obstacle_posed_distance(t->obstacle, &t->pose, p, &n);
          if (it == 0 && d < 0 && s == 0) break; /* camera inside: draw nothing */
          double eps = 0.25 * s * inv_f + 1e-9 * t->radius;
          if (d < eps) {
            hit = true;
            break;
          }
          s += d;
        }
        if (!hit || !(s / dir_len < best)) continue;
        best = s / dir_len;
        ground_nearest = false;
        obstacle_nearest = true;
        float spec;
        float light = render_light(cam, n, vec3_neg(dn), &spec);
        col[0] = RENDER_OBSTACLE_R * light + 255 * spec;
        col[1] = RENDER_OBSTACLE_G * light + 255 * spec;
        col[2] = RENDER_OBSTACLE_B * light + 255 * spec;
      }
      size_t i = (size_t)y * (size_t)W + (size_t)x;
      depth[i] = (float)(ground_nearest     ? best * (1 + GROUND_DEPTH_BIAS)
                         : obstacle_nearest ? best * (1 + OBSTACLE_DEPTH_BIAS_PX * inv_f)
                                            : best);
      for (int c = 0; c < 3; ++c) {
        float v = col[c] + 0.5f;
        rgb[3 * i + (size_t)c] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v);
      }
    }
  }
}
