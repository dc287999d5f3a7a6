/* Scene building: read or generate each solid's mesh, place it by its transform, and add
 * solids and obstacles to a new world. Errors name the key path of the solid or obstacle. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "math/mat3.h"
#include "piola/mesh_io.h"
#include "piola/mesher.h"
#include "piola/shell_body.h"
#include "scene/scene_desc.h"

/* R = Rz(c) Ry(b) Rx(a): rotate about x first, then y, then z (fixed axes). */
static mat3 euler_xyz_degrees(piola_vec3 deg) {
  double k = M_PI / 180.0;
  double a = deg.x * k, b = deg.y * k, c = deg.z * k;
  mat3 rx = {{{1, 0, 0}, {0, cos(a), -sin(a)}, {0, sin(a), cos(a)}}};
  mat3 ry = {{{cos(b), 0, sin(b)}, {0, 1, 0}, {-sin(b), 0, cos(b)}}};
  mat3 rz = {{{cos(c), -sin(c), 0}, {sin(c), cos(c), 0}, {0, 0, 1}}};
  return mat3_mul(rz, mat3_mul(ry, rx));
}

/* X' = translate + R (scale * X); fibres turn with the rest shape (piola_tet_mesh_transform).
 * Scales are > 0 and R a rotation, so the map is always accepted. */
static void place(piola_tet_mesh *mesh, const scene_solid_desc *d) {
  mat3 r = euler_xyz_degrees(d->rotate_degrees);
  mat3 scale = {{{d->scale.x, 0, 0}, {0, d->scale.y, 0}, {0, 0, d->scale.z}}};
  (void)piola_tet_mesh_transform(mesh, mat3_mul(r, scale), d->translate);
}

piola_status piola__scene_read_goal_mesh(const scene_solid_desc *d, const piola_tet_mesh *rest,
                                         piola_tet_mesh *goal) {
  PIOLA_TRY(piola_tet_mesh_read(d->goal_mesh_path, goal));
  if (goal->vertex_count != rest->vertex_count || goal->tet_count != rest->tet_count)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "the goal mesh has %d vertices and %d tets, the solid %d and %d: it must have the "
                      "same connectivity", (int)goal->vertex_count, (int)goal->tet_count,
                      (int)rest->vertex_count, (int)rest->tet_count);
  for (int64_t k = 0; k < 4 * (int64_t)rest->tet_count; ++k)
    if (goal->tets[k] != rest->tets[k])
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                        "tet %lld of the goal mesh has other vertices than the solid's", (long long)(k / 4));
  place(goal, d);
  return PIOLA_OK;
}

/* Index selectors can only be checked against the mesh: the first index past its
 * vertex_count fails, naming the scene key (KIND[i].fixed[c] or .driven[c]). */
static piola_status check_index_selectors(const char *label, const char *kind, int32_t i,
                                          const scene_solid_desc *d, int32_t vertex_count) {
  for (int32_t c = 0; c < d->constraint_count; ++c) {
    const piola_selector *sel = &d->constraints[c].selector;
    if (sel->type != PIOLA_SELECT_INDICES) continue;
    for (int32_t k = 0; k < sel->index_count; ++k)
      if (sel->indices[k] >= vertex_count) {
        const int fixed = c < d->fixed_count;
        return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                          "%s: %s[%d].%s[%d].indices[%d]: vertex %d is out of range (the mesh has "
                          "%d vertices)",
                          label, kind, (int)i, fixed ? "fixed" : "driven",
                          (int)(fixed ? c : c - d->fixed_count), (int)k, (int)sel->indices[k],
                          (int)vertex_count);
      }
  }
  return PIOLA_OK;
}

/* Shells: read or generate the triangle mesh, place it, add the shell. */
static piola_status build_shell(piola_world *world, const scene_shell_desc *d, const char *label,
                                int32_t index) {
  piola_tri_mesh mesh;
  memset(&mesh, 0, sizeof mesh);
  piola_status st;
  if (d->generator == 1)
    st = piola_tri_mesh_rectangle(d->size[0], d->size[1], d->resolution[0], d->resolution[1], &mesh);
  else if (d->generator == 2)
    st = piola_tri_mesh_disk(d->radius, d->resolution[0], &mesh);
  else if (d->generator == 3)
    st = piola_tri_mesh_torus(d->radius, d->minor_radius, d->resolution[0], d->resolution[1],
                              d->sweep_degrees, &mesh);
  else
    st = piola_tri_mesh_read(d->base.mesh_path, &mesh);
  if (st == PIOLA_OK && mesh.triangle_count < 1)
    st = PIOLA_FAIL(PIOLA_ERROR_PARSE, "the mesh has no triangles");
  if (st != PIOLA_OK) {
    piola_tri_mesh_free(&mesh);
    return PIOLA_FAIL(st, "%s: shells[%d]: mesh: %s", label, (int)index, piola_last_error());
  }
  st = check_index_selectors(label, "shells", index, &d->base, mesh.vertex_count);
  if (st != PIOLA_OK) {
    piola_tri_mesh_free(&mesh);
    return st;
  }
  mat3 r = euler_xyz_degrees(d->base.rotate_degrees);
  for (int32_t i = 0; i < mesh.vertex_count; ++i) {
    double *p = mesh.positions + 3 * i;
    vec3 s = {p[0] * d->base.scale.x, p[1] * d->base.scale.y, p[2] * d->base.scale.z};
    vec3_store(p, vec3_add(mat3_mul_vec(r, s), d->base.translate));
  }
  piola_shell_def def = d->def;
  def.mesh = &mesh;
  def.name = d->base.name;
  def.material = d->base.def.material;
  def.density = d->base.def.density;
  def.stiffness_scale = d->base.def.stiffness_scale;
  def.shear_viscosity = d->base.def.shear_viscosity;
  def.bulk_viscosity = d->base.def.bulk_viscosity;
  def.velocity = d->base.def.velocity;
  def.constraints = d->base.constraints;
  def.constraint_count = d->base.constraint_count;
  st = piola_world_add_shell(world, &def, NULL);
  piola_tri_mesh_free(&mesh);
  return st == PIOLA_OK
             ? st
             : PIOLA_FAIL(st, "%s: shells[%d]: %s", label, (int)index, piola_last_error());
}

/* Bones: the obstacle part as for obstacles, then the attachments (solids are in). */
static piola_status build_bone(piola_world *world, const scene_bone_desc *d) {
  piola_bone_def def = piola_default_bone_def();
  def.shape = d->obstacle.def;
  def.attachments = d->attachments;
  def.attachment_count = d->attachment_count;
  piola_tri_mesh surface;
  memset(&surface, 0, sizeof surface);
  piola_status st = PIOLA_OK;
  if (def.shape.type == PIOLA_OBSTACLE_MESH) {
    st = piola_tri_mesh_read(d->obstacle.mesh_path, &surface);
    def.shape.mesh = &surface;
  }
  if (st == PIOLA_OK) st = piola_world_add_bone(world, &def, NULL, NULL);
  piola_tri_mesh_free(&surface);
  return st;
}

/* A solid's fracture: the blades of cuts by a mesh are read here (the def keeps copies). */
static piola_status build_fracture(piola_world *world, int32_t i, const scene_solid_desc *d,
                                   const char *label) {
  piola_fracture_def def = d->fracture;
  const int32_t n = def.cut_count;
  piola_fracture_cut *cuts = calloc((size_t)(n > 0 ? n : 1), sizeof *cuts);
  piola_tri_mesh *blades = calloc((size_t)(n > 0 ? n : 1), sizeof *blades);
  piola_status st = cuts && blades ? PIOLA_OK
                                   : PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "%s: out of memory", label);
  for (int32_t c = 0; c < n && st == PIOLA_OK; ++c) {
    cuts[c] = def.cuts[c];
    if (!d->fracture_blade_paths[c][0]) continue;
    st = piola_tri_mesh_read(d->fracture_blade_paths[c], &blades[c]);
    if (st != PIOLA_OK)
      st = PIOLA_FAIL(st, "%s: solids[%d].fracture.cuts[%d].mesh: %s", label, (int)i, (int)c, piola_last_error());
    cuts[c].blade = &blades[c];
  }
  def.cuts = cuts;
  if (st == PIOLA_OK) {
    st = piola_world_solid_set_fracture(world, i, &def);
    if (st != PIOLA_OK) st = PIOLA_FAIL(st, "%s: solids[%d].fracture: %s", label, (int)i, piola_last_error());
  }
  for (int32_t c = 0; blades && c < n; ++c) piola_tri_mesh_free(&blades[c]);
  free(blades), free(cuts);
  return st;
}

piola_status piola__scene_build(const scene_desc *desc, const char *label,
                                const piola_work_split_planner *planner, piola_world **out) {
  *out = NULL;
  if (!label) label = "scene";
  piola_world *world = NULL;
  if (piola_world_create(&desc->world, &world) != PIOLA_OK)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "%s: integrator: %s", label, piola_last_error());
  piola_world_set_work_split_planner(world, planner);
  if (desc->ignored_integrator_keys[0]) {
    char text[1024];
    const int newmark = desc->world.integrator == PIOLA_INTEGRATOR_NEWMARK;
    const int several = strchr(desc->ignored_integrator_keys, ',') != NULL;
    snprintf(text, sizeof text,
             "%s: %s %s to %s only: the scene's integrator is \"%s\"%s, which ignores %s "
             "(scene-format.md, \"integrator\")",
             label, desc->ignored_integrator_keys, several ? "apply" : "applies",
             newmark ? "\"backward_euler\" and \"quasistatic\"" : "\"newmark\"",
             piola_integrator_type_name(desc->world.integrator),
             newmark ? " (integrator.type, default \"newmark\")" : "", several ? "them" : "it");
    piola_world_raise_warning(world, PIOLA_WARNING_IGNORED_KEYS, text);
  }
  for (int32_t i = 0; i < desc->solid_count; ++i) {
    const scene_solid_desc *d = &desc->solids[i];
    piola_tet_mesh mesh;
    memset(&mesh, 0, sizeof mesh);
    piola_status st = d->mesh_generated ? piola_mesher_generate(&d->mesher, &mesh)
                                        : piola_tet_mesh_read(d->mesh_path, &mesh);
    if (st == PIOLA_OK && mesh.tet_count < 1) st = PIOLA_FAIL(PIOLA_ERROR_PARSE, "the mesh has no tetrahedra");
    if (st != PIOLA_OK) {
      piola_tet_mesh_free(&mesh);
      piola_world_destroy(world);
      return PIOLA_FAIL(st, "%s: solids[%d].mesh: %s", label, (int)i, piola_last_error());
    }
    st = check_index_selectors(label, "solids", i, d, mesh.vertex_count);
    if (st != PIOLA_OK) {
      piola_tet_mesh_free(&mesh);
      piola_world_destroy(world);
      return st;
    }
    place(&mesh, d);
    piola_solid_def def = d->def;
    def.mesh = &mesh;
    def.name = d->name;
    def.constraints = d->constraints;
    def.constraint_count = d->constraint_count;
    piola_plasticity_def plasticity;
    piola_tet_mesh goal;
    memset(&goal, 0, sizeof goal);
    if (d->plastic) {
      plasticity = d->plasticity;
      def.plasticity = &plasticity;
      if (plasticity.control.goal == PIOLA_PLASTIC_GOAL_MESH) {
        st = piola__scene_read_goal_mesh(d, &mesh, &goal);
        if (st != PIOLA_OK) {
          piola_tet_mesh_free(&mesh);
          piola_tet_mesh_free(&goal);
          piola_world_destroy(world);
          return PIOLA_FAIL(st, "%s: solids[%d].plasticity.control.goal.mesh: %s", label, (int)i,
                            piola_last_error());
        }
        plasticity.control.goal_positions = goal.positions;
        plasticity.control.goal_vertex_count = goal.vertex_count;
      }
    }
    double *fibers = NULL;
    st = piola__scene_fiber_directions(&d->fibers, &mesh, &fibers);
    if (st != PIOLA_OK) {
      piola_tet_mesh_free(&mesh);
      piola_tet_mesh_free(&goal);
      piola_world_destroy(world);
      return PIOLA_FAIL(st, "%s: solids[%d].%s", label, (int)i, piola_last_error());
    }
    def.fiber_directions = fibers;
    /* a solid that can break is split after it is added, in the replicated mode: every
     * process takes the fracture decisions from every tet's state (docs/mpi.md) */
    piola_world_set_work_split_planner(world, d->fractures ? NULL : planner);
    /* the material's own checks, under its key path */
    piola_material checked;
    st = piola_material_init(&def.material, &checked);
    if (st != PIOLA_OK) {
      free(fibers);
      piola_tet_mesh_free(&mesh);
      piola_tet_mesh_free(&goal);
      piola_world_destroy(world);
      return PIOLA_FAIL(st, "%s: solids[%d].material.%s", label, (int)i, piola_last_error());
    }
    st = piola_world_add_solid(world, &def, NULL);
    free(fibers);
    piola_tet_mesh_free(&mesh);
    piola_tet_mesh_free(&goal);
    if (st != PIOLA_OK) {
      piola_world_destroy(world);
      return PIOLA_FAIL(st, "%s: solids[%d]: %s", label, (int)i, piola_last_error());
    }
  }
  piola_world_set_work_split_planner(world, planner);
  for (int32_t i = 0; i < desc->shell_count; ++i) {
    piola_status st = build_shell(world, &desc->shells[i], label, i);
    if (st != PIOLA_OK) {
      piola_world_destroy(world);
      return st;
    }
  }
  for (int32_t i = 0; i < desc->obstacle_count; ++i) {
    const scene_obstacle_desc *d = &desc->obstacles[i];
    piola_obstacle_def def = d->def;
    piola_tri_mesh surface;
    memset(&surface, 0, sizeof surface);
    piola_status st = PIOLA_OK;
    if (def.type == PIOLA_OBSTACLE_MESH) {
      st = piola_tri_mesh_read(d->mesh_path, &surface);
      if (st != PIOLA_OK) {
        piola_world_destroy(world);
        return PIOLA_FAIL(st, "%s: obstacles[%d].path: %s", label, (int)i, piola_last_error());
      }
      def.mesh = &surface;
    }
    if (st == PIOLA_OK) st = piola_world_add_obstacle(world, &def, NULL);
    piola_tri_mesh_free(&surface);
    if (st != PIOLA_OK) {
      piola_world_destroy(world);
      return PIOLA_FAIL(st, "%s: obstacles[%d]: %s", label, (int)i, piola_last_error());
    }
  }
  for (int32_t i = 0; i < desc->bone_count; ++i) {
    piola_status st = build_bone(world, &desc->bones[i]);
    if (st != PIOLA_OK) {
      piola_world_destroy(world);
      /* world messages start with "attachments[k]..." or describe the shape */
      const char *msg = piola_last_error();
      int attachment = strncmp(msg, "attachments[", 12) == 0;
      return PIOLA_FAIL(st, "%s: bones[%d]%s%s", label, (int)i, attachment ? "." : ": ", msg);
    }
  }
  /* last: a cut due at t = 0 renumbers nodes, which bones select by index */
  for (int32_t i = 0; i < desc->solid_count; ++i) {
    if (!desc->solids[i].fractures) continue;
    piola_status st = build_fracture(world, i, &desc->solids[i], label);
    if (st != PIOLA_OK) {
      piola_world_destroy(world);
      return st;
    }
  }
  *out = world;
  return PIOLA_OK;
}
