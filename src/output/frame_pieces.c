/* A frame written as pieces, one per process of a split run (docs/mpi.md, "Output"), and the
 * .pvtu that ties them (docs/file-formats.md).
 *
 * Piece K holds the tets of the blocks process K computes (piola_elastic_body_work_split;
 * every tet of a solid without a split is piece 0's), in the whole frame's cell order, and
 * the points those tets use, in the whole frame's point order: a node on the border of two
 * parts is in both pieces, with the same values (every process holds every node). The cell
 * and point fields are those of a single-process frame plus cell_id and point_id, each
 * cell's and point's index in the whole frame, so a reader can merge the pieces into the
 * single-process frame exactly. A process reads only its own blocks' per-tet state, which
 * it computed itself. With fracture the cuts change the meshes (and their split) between
 * frames, so the layout is built again for every frame, and the cells also get fragment and
 * material_fraction, as in a single-process frame. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "common/status_report.h"
#include "io/atomic_file_internal.h"
#include "output/frame_commit.h"
#include "output/output_internal.h"
#include "piola/files.h"
#include "piola/mesh_io.h"
#include "piola/work_split.h"
#include "piola/world_bodies.h"
#include "piola/world_fracture.h"
#include "piola/world_shells.h"

void piola__piece_layout_free(piece_layout *l) {
  free(l->points), free(l->cells), free(l->tets.tets), free(l->tets.positions);
  free(l->velocity), free(l->displacement), free(l->point_id);
  free(l->det_f), free(l->inverted), free(l->energy), free(l->solid), free(l->cell_id);
  free(l->fragment), free(l->fraction);
  memset(l, 0, sizeof *l);
}

/* The solid at body table position p (the whole frame's point and cell order), or NULL. */
static const piola_elastic_body *solid_at(const piola_world *world, int32_t p, piola_body_id *id) {
  *id = piola_world_body_at(world, p);
  if (piola_world_body_kind(world, *id) != PIOLA_BODY_SOLID) return NULL;
  return piola_world_solid_body(world, piola_world_body_index(world, *id));
}

static int in_piece(const piola_work_split *split, int32_t tet, int32_t piece) {
  return split ? split->block_part[tet / PIOLA_WORK_SPLIT_BLOCK] == piece : piece == 0;
}

piola_status piola__piece_layout_build(piece_layout *l, const piola_world *world, int32_t piece,
                                       int32_t piece_count) {
  memset(l, 0, sizeof *l);
  l->piece = piece;
  l->piece_count = piece_count;
  for (int32_t s = 0; s < piola_world_solid_count(world); ++s)
    if (piola_world_solid_has_fracture(world, s)) l->fractures = 1;
  if (piola_world_shell_count(world) > 0)
    return PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED, "output: shells are not written as pieces");
  const int32_t nb = piola_world_body_count(world);
  int64_t all_points = 0, all_cells = 0;
  for (int32_t p = 0; p < nb; ++p) {
    piola_body_id id;
    const piola_elastic_body *b = solid_at(world, p, &id);
    if (!b) continue;
    all_points += piola_elastic_body_vertex_count(b);
    all_cells += piola_elastic_body_tet_count(b);
  }
  if (all_points > INT32_MAX || all_cells > INT32_MAX)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "output: too many points for a frame");
  /* local index of each point of the whole frame, -1 where the piece does not use it */
  int32_t *local = malloc((size_t)(all_points > 0 ? all_points : 1) * sizeof *local);
  if (!local) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "output: out of memory");
  for (int64_t i = 0; i < all_points; ++i) local[i] = -1;
  int32_t cells = 0, points = 0;
  for (int pass = 0; pass < 2; ++pass) {
    int32_t point0 = 0, cell0 = 0, c = 0;
    for (int32_t p = 0; p < nb; ++p) {
      piola_body_id id;
      const piola_elastic_body *b = solid_at(world, p, &id);
      if (!b) continue;
      const int32_t s = piola_world_body_index(world, id);
      const piola_work_split *split = piola_elastic_body_work_split(b);
      const int32_t nt = piola_elastic_body_tet_count(b);
      const int32_t *tv = piola_elastic_body_tets(b);
      const int32_t *frag = l->fractures ? piola_world_solid_fragments(world, s) : NULL;
      const double *fraction = l->fractures ? piola_world_solid_material_fractions(world, s) : NULL;
      for (int32_t t = 0; t < nt; ++t) {
        if (!in_piece(split, t, piece)) continue;
        if (pass == 0) {
          cells++;
          for (int k = 0; k < 4; ++k) local[point0 + tv[4 * t + k]] = 0;
          continue;
        }
        l->cells[c] = cell0 + t;
        l->solid[c] = s;
        if (l->fractures) l->fragment[c] = frag ? frag[t] : 0, l->fraction[c] = fraction ? fraction[t] : 1;
        for (int k = 0; k < 4; ++k) l->tets.tets[4 * (size_t)c + (size_t)k] = local[point0 + tv[4 * t + k]];
        c++;
      }
      point0 += piola_elastic_body_vertex_count(b);
      cell0 += nt;
    }
    if (pass == 1) break;
    for (int64_t i = 0; i < all_points; ++i)
      if (local[i] == 0) local[i] = points++;
    const size_t np = (size_t)(points > 0 ? points : 1), nc = (size_t)(cells > 0 ? cells : 1);
    l->points = malloc(np * sizeof(int32_t)), l->cells = malloc(nc * sizeof(int32_t));
    l->tets.tets = malloc(4 * nc * sizeof(int32_t));
    l->tets.positions = malloc(3 * np * sizeof(double));
    l->velocity = malloc(3 * np * sizeof(double)), l->displacement = malloc(3 * np * sizeof(double));
    l->point_id = malloc(np * sizeof(double));
    l->det_f = malloc(nc * sizeof(double)), l->inverted = malloc(nc * sizeof(double));
    l->energy = malloc(nc * sizeof(double)), l->solid = malloc(nc * sizeof(double));
    l->cell_id = malloc(nc * sizeof(double));
    if (l->fractures) l->fragment = malloc(nc * sizeof(double)), l->fraction = malloc(nc * sizeof(double));
    if (!l->points || !l->cells || !l->tets.tets || !l->tets.positions || !l->velocity ||
        !l->displacement || !l->point_id || !l->det_f || !l->inverted || !l->energy ||
        !l->solid || !l->cell_id || (l->fractures && (!l->fragment || !l->fraction))) {
      free(local);
      piola__piece_layout_free(l);
      return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "output: out of memory");
    }
    for (int64_t i = 0; i < all_points; ++i)
      if (local[i] >= 0) l->points[local[i]] = (int32_t)i, l->point_id[local[i]] = (double)i;
  }
  free(local);
  l->tets.vertex_count = points;
  l->tets.tet_count = cells;
  for (int32_t c = 0; c < cells; ++c) l->cell_id[c] = l->cells[c];
  return PIOLA_OK;
}

/* The piece's points and cells of the world's current state. */
static void fill_piece(piece_layout *l, const piola_world *world) {
  const int32_t nb = piola_world_body_count(world);
  int32_t point0 = 0, cell0 = 0, p = 0, c = 0;
  for (int32_t q = 0; q < nb; ++q) {
    piola_body_id id;
    const piola_elastic_body *b = solid_at(world, q, &id);
    if (!b) continue;
    const int32_t nv = piola_elastic_body_vertex_count(b), nt = piola_elastic_body_tet_count(b);
    const double *x = piola_world_body_positions(world, id), *v = piola_world_body_velocities(world, id);
    const double *rest = piola_elastic_body_rest_positions(b);
    for (; p < l->tets.vertex_count && l->points[p] < point0 + nv; ++p) {
      const size_t i = (size_t)(l->points[p] - point0);
      for (int k = 0; k < 3; ++k) {
        l->tets.positions[3 * (size_t)p + (size_t)k] = x[3 * i + (size_t)k];
        l->velocity[3 * (size_t)p + (size_t)k] = v[3 * i + (size_t)k];
        l->displacement[3 * (size_t)p + (size_t)k] = x[3 * i + (size_t)k] - rest[3 * i + (size_t)k];
      }
    }
    if (c < l->tets.tet_count && l->cells[c] < cell0 + nt) {
      const double *det = piola_elastic_body_det_f(b);
      const double *psi = piola_elastic_body_energy_density(b); /* this process's tets */
      for (; c < l->tets.tet_count && l->cells[c] < cell0 + nt; ++c) {
        const int32_t t = l->cells[c] - cell0;
        l->det_f[c] = det[t];
        l->inverted[c] = det[t] < 0 ? 1.0 : 0.0;
        l->energy[c] = psi[t];
      }
    }
    point0 += nv;
    cell0 += nt;
  }
}

void piola__piece_name(char *out, size_t size, const char *dir, int32_t frame, int32_t piece) {
  snprintf(out, size, "%s/frames/frame_%04d_p%d.vtu", dir, (int)frame, (int)piece);
}

piola_status piola__piece_write(piece_layout *l, const piola_world *world, const char *dir,
                                int32_t frame) {
  if (l->fractures) { /* cuts change the meshes and their split between frames */
    const int32_t piece = l->piece, piece_count = l->piece_count;
    piola__piece_layout_free(l);
    PIOLA_TRY(piola__piece_layout_build(l, world, piece, piece_count));
  }
  fill_piece(l, world);
  piola_vtu_field points[3] = {{"velocity", 3, l->velocity},
                               {"displacement", 3, l->displacement},
                               {"point_id", 1, l->point_id}};
  piola_vtu_field cells[7] = {{"det_f", 1, l->det_f},
                              {"inverted", 1, l->inverted},
                              {"energy_density", 1, l->energy},
                              {"solid", 1, l->solid},
                              {"cell_id", 1, l->cell_id},
                              {"fragment", 1, l->fragment},
                              {"material_fraction", 1, l->fraction}};
  piola_vtu_frame vtu = {.tets = l->tets.tet_count > 0 ? &l->tets : NULL,
                         .point_fields = points, .point_field_count = 3,
                         .cell_fields = cells, .cell_field_count = l->fractures ? 7 : 5,
                         .positions = l->tets.positions};
  char path[4200], pending[4200];
  piola__piece_name(path, sizeof path, dir, frame, l->piece);
  if (!piola__frame_pending_name(path, pending, sizeof pending))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "output: path too long");
  /* one data file: written whole under its pending name, then renamed; without the .pvtu
   * that process 0 writes after every piece is in place, no index lists it */
  frame_commit commit = {0};
  PIOLA_TRY(piola_vtu_write(pending, &vtu));
  piola__frame_commit_add(&commit, pending, path, 0);
  return piola__frame_commit_publish(&commit);
}

piola_status piola__pvtu_stage(frame_commit *c, const char *dir, int32_t frame, int32_t piece_count,
                               int fractures) {
  char path[4200];
  struct stat st;
  for (int32_t k = 0; k < piece_count; ++k) { /* never tie a frame whose pieces are missing */
    piola__piece_name(path, sizeof path, dir, frame, k);
    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode))
      return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: piece %d of frame %d is missing", path, (int)k, (int)frame);
  }
  snprintf(path, sizeof path, "%s/frames/frame_%04d.pvtu", dir, (int)frame);
  piola_atomic_file f;
  PIOLA_TRY(piola_atomic_file_open(&f, path));
  FILE *o = f.stream;
  fprintf(o, "<?xml version=\"1.0\"?>\n"
             "<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
             "header_type=\"UInt64\">\n  <PUnstructuredGrid GhostLevel=\"0\">\n    <PPointData>\n");
  static const char *const point_fields[][2] = {{"velocity", "3"}, {"displacement", "3"}, {"point_id", "1"}};
  static const char *const cell_fields[] = {"det_f", "inverted", "energy_density", "solid", "cell_id",
                                            "fragment", "material_fraction"};
  for (int i = 0; i < 3; ++i)
    fprintf(o, "      <PDataArray type=\"Float64\" Name=\"%s\" NumberOfComponents=\"%s\"/>\n",
            point_fields[i][0], point_fields[i][1]);
  fprintf(o, "    </PPointData>\n    <PCellData>\n");
  for (int i = 0; i < (fractures ? 7 : 5); ++i)
    fprintf(o, "      <PDataArray type=\"Float64\" Name=\"%s\" NumberOfComponents=\"1\"/>\n",
            cell_fields[i]);
  fprintf(o, "    </PCellData>\n    <PPoints>\n"
             "      <PDataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"/>\n"
             "    </PPoints>\n");
  for (int32_t k = 0; k < piece_count; ++k)
    fprintf(o, "    <Piece Source=\"frame_%04d_p%d.vtu\"/>\n", (int)frame, (int)k);
  fprintf(o, "  </PUnstructuredGrid>\n</VTKFile>\n");
  PIOLA_TRY(piola__atomic_file_finish(&f));
  piola__frame_commit_add(c, f.temporary, f.target, 0);
  return PIOLA_OK;
}
