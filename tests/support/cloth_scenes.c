/* Cloth scenes shared by the contact tests (cloth_scenes.h). */
#include "test_support.h"

#include <math.h>

#include "cloth_scenes.h"
#include "piola/elastic_body.h"
#include "piola/shell_body.h"
#include "piola/world.h"
#include "triangle_referee.h"

piola_tri_mesh cloth_sheet(double size, int cells, double z, double shift) {
  piola_tri_mesh m;
  assert_int_equal(piola_tri_mesh_rectangle(size, size, cells, cells, &m), PIOLA_OK);
  for (int32_t i = 0; i < m.vertex_count; ++i) {
    m.positions[3 * i] += shift, m.positions[3 * i + 1] += 0.5 * shift;
    m.positions[3 * i + 2] = z;
  }
  return m;
}

piola_shell_def cloth_shell_def(const piola_tri_mesh *mesh, int self_collision, double h) {
  piola_shell_def d = piola_default_shell_def();
  d.mesh = mesh;
  d.thickness = 5e-4;
  d.density = 400;
  d.material.youngs_modulus = 5e4;
  d.material.poisson_ratio = 0.3;
  d.shear_viscosity = piola_track_constant(0.05);
  d.bulk_viscosity = piola_track_constant(0.05);
  d.bending.stiffness = 2e-6;
  d.self_collision.enabled = self_collision != 0;
  d.self_collision.thickness = h;
  d.self_collision.friction = 0.3;
  return d;
}

static void momentum(const double *v, const double *m, int32_t n, double out[3]) {
  for (int32_t i = 0; i < n; ++i)
    for (int d = 0; d < 3; ++d) out[d] += m[i] * v[3 * i + d];
}

/* Block and cloth momenta (kg m/s) of the block-and-cloth world. */
static void pair_momenta(const piola_world *w, double block[3], double cloth[3]) {
  const piola_elastic_body *b = piola_world_solid_body(w, 0);
  const piola_shell_body *c = piola_world_shell_body(w, 0);
  for (int d = 0; d < 3; ++d) block[d] = cloth[d] = 0;
  momentum(piola_world_solid_velocities(w, 0), piola_elastic_body_masses(b),
           piola_elastic_body_vertex_count(b), block);
  momentum(piola_world_shell_velocities(w, 0), piola_shell_body_masses(c),
           piola_shell_body_vertex_count(c), cloth);
}

void block_hits_free_cloth(double speed, double h, double collision_interval) {
  const double dtc = collision_interval;
  piola_world_def wd = piola_default_world_def();
  for (int d = 0; d < 3; ++d) wd.gravity[d] = piola_track_constant(0.0);
  wd.max_dt = 5e-4;
  wd.collision_interval = dtc;
  piola_world *w = NULL;
  assert_int_equal(piola_world_create(&wd, &w), PIOLA_OK);
  piola_tet_mesh block;
  assert_int_equal(piola_tet_mesh_box_grid(4, 4, 2, (piola_vec3){0.015, 0.015, 0.015}, &block),
                   PIOLA_OK);
  for (int32_t i = 0; i < block.vertex_count; ++i) {
    block.positions[3 * i] -= 0.03 + 1e-3, block.positions[3 * i + 1] -= 0.03 + 2e-3;
    block.positions[3 * i + 2] += 0.01;
  }
  piola_tet_mesh_orient(&block);
  piola_solid_def sd = piola_default_solid_def();
  sd.mesh = &block;
  sd.density = 300;
  sd.material.youngs_modulus = 1e5;
  sd.material.poisson_ratio = 0.3;
  sd.velocity = (piola_vec3){0.1 * speed, 0, speed};
  sd.self_collision.enabled = true;
  sd.self_collision.thickness = h;
  sd.self_collision.friction = 0.3;
  assert_int_equal(piola_world_add_solid(w, &sd, NULL), PIOLA_OK);
  piola_tri_mesh cloth = cloth_sheet(0.12, 12, 0.05, 0.0);
  piola_shell_def cd = cloth_shell_def(&cloth, 1, h);
  cd.density = 2000; /* 1 kg/m^2: heavy enough to visibly slow the block */
  assert_int_equal(piola_world_add_shell(w, &cd, NULL), PIOLA_OK);
  piola_tri_mesh_free(&cloth);

  piola_tri_mesh boundary;
  assert_int_equal(piola_tet_mesh_boundary(&block, &boundary), PIOLA_OK);
  double p_block0[3], p_cloth0[3], pb[3], pc[3];
  pair_momenta(w, p_block0, p_cloth0);
  const double scale = fabs(p_block0[2]);
  judged sets[2] = {{piola_world_solid_positions(w, 0), boundary.triangles, boundary.triangle_count},
                    referee_shell_set(w, 0)};
  assert_int_equal(referee_count_intersections(sets, 2), 0);
  piola_step_stats total = {0};
  const double t_end = 0.08 / speed;
  for (int k = 1; dtc > 0 ? k * dtc <= t_end + dtc : piola_world_time(w) < t_end; ++k) {
    if (dtc > 0) { /* judged at interval ends, where collision processing has run */
      assert_int_equal(piola_world_advance_to(w, k * dtc, &total), PIOLA_OK);
    } else { /* judged after every step */
      piola_step_stats one;
      assert_int_equal(piola_world_step(w, 0, &one), PIOLA_OK);
      total.substeps += one.substeps, total.contacts += one.contacts;
      total.impacts += one.impacts, total.impact_zones += one.impact_zones;
    }
    long bad = referee_count_intersections(sets, 2);
    if (bad) fail_msg("t = %g s: %ld intersecting triangle pairs", piola_world_time(w), bad);
    pair_momenta(w, pb, pc);
    for (int d = 0; d < 3; ++d) assert_close(pb[d] + pc[d], p_block0[d] + p_cloth0[d], 1e-10 * scale);
  }
  pair_momenta(w, pb, pc);
  print_message("block into cloth at %g m/s, interval %g s: %lld steps, %lld contacts, %lld impacts,"
                " %lld zones; block p_z %.4g -> %.4g, cloth p_z %.4g -> %.4g kg m/s\n",
                speed, dtc, (long long)total.substeps, (long long)total.contacts,
                (long long)total.impacts, (long long)total.impact_zones, p_block0[2], pb[2],
                p_cloth0[2], pc[2]);
  assert_true(total.contacts + total.impacts > 0);
  if (speed >= 10) assert_true(total.impacts > 0);
  /* two-way: the block lost a real part of its momentum to the cloth */
  assert_true(pb[2] < 0.9 * p_block0[2]);
  assert_true(pc[2] > 0.1 * p_block0[2]);
  piola_tri_mesh_free(&boundary);
  piola_tet_mesh_free(&block);
  piola_world_destroy(w);
}
