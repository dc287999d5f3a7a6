/* Frame output: one VTU of every solid's tets, one OBJ of their boundary surfaces, a row of
 * stats.csv and an entry in sim.pvd per frame, each written whole or not at all.
 *
 * The solids of a world are concatenated into one mesh per frame (with a per-cell `solid`
 * index) so a viewer loads one file per frame. Topology and the boundary surface are built
 * once when the output opens; each frame only refreshes positions and fields. stats.csv and
 * sim.pvd are kept in memory and rewritten atomically after every frame, so the files on disk
 * always describe exactly the frames that exist.
 *
 * Shells (piola/world_shells.h) follow the solids: their vertices come after the solids'
 * in the point list, their triangles are the VTU's triangle cells (cell fields: det_f is
 * the signed area ratio fhat0 * fhat1, inverted flags triangles opposing their reference
 * normal, energy_density is 0, solid is -1 - the shell's index) and join the OBJ surface. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "io/atomic_file_internal.h"
#include "output/frame_commit.h"
#include "output/output_internal.h"
#include "piola/files.h"
#include "piola/mesh_io.h"
#include "piola/world_bodies.h"
#include "piola/world_fracture.h"
#include "piola/world_shells.h"

typedef struct pvd_entry {
  int32_t frame;
  double time;
} pvd_entry;

struct piola_output {
  char dir[4096];
  piola_tet_mesh tets;      /* concatenated; positions refreshed per frame */
  piola_tri_mesh surface;   /* concatenated boundary, shares vertex numbering with tets, then
                               the shells' triangles */
  piola_tri_mesh shells;    /* concatenated shell triangles, numbered from the first shell
                               vertex; positions borrowed per frame */
  int32_t solid_vertices, solid_cells; /* where the shells start in points and cells */
  double *rest;             /* 3 * vertex_count */
  double *velocity, *displacement, *det_f, *inverted, *energy, *solid;
  char *csv;
  size_t csv_len, csv_cap;
  pvd_entry *pvd;
  int32_t pvd_count, pvd_cap;
  obj_layout obj;           /* the OBJ surface: one object per body (obj_frame.c) */
  bool fractures;           /* a solid has fracture state: topology is rebuilt every frame,
                               cells get fragment and material_fraction, fractured solids'
                               OBJ objects are their fragments */
  double *fragment, *fraction; /* per cell, when fractures */
  const piola_world *world; /* of the frame being written */
  int32_t piece_count;      /* a split run's frames as pieces (frame_pieces.c), or 0 */
  bool lead;                /* writes the frame's .pvtu (or .vtu), OBJ and indexes */
  piece_layout piece;       /* this process's piece, when piece_count > 0 */
};

static piola_status csv_append(piola_output *o, const char *line) {
  size_t n = strlen(line);
  if (o->csv_len + n + 1 > o->csv_cap) {
    size_t cap = o->csv_cap ? o->csv_cap * 2 : 4096;
    while (cap < o->csv_len + n + 1) cap *= 2;
    char *grown = realloc(o->csv, cap);
    if (!grown) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "stats.csv: out of memory");
    o->csv = grown;
    o->csv_cap = cap;
  }
  memcpy(o->csv + o->csv_len, line, n + 1);
  o->csv_len += n;
  return PIOLA_OK;
}

static void free_topology(piola_output *o);

void piola_output_close(piola_output *o) {
  if (!o) return;
  free_topology(o);
  piola__piece_layout_free(&o->piece);
  free(o->csv), free(o->pvd);
  free(o);
}

static piola_status resume_indexes(piola_output *o, int32_t frame);
static piola_status pvd_append(piola_output *o, int32_t frame, double time);

/* One body as the output lays it out, whatever its kind. */
typedef struct body_mesh {
  piola_body_id id;
  piola_body_kind kind;
  int32_t index; /* among the bodies of its kind */
  const char *name;
  int32_t nodes, cells;   /* cells: a solid's tets, a shell's triangles */
  const double *rest;     /* 3 per node, m */
  const int32_t *elements; /* 4 (tets) or 3 (triangles) node indices per cell */
} body_mesh;

static body_mesh body_mesh_at(const piola_world *world, int32_t position) {
  const piola_body_id id = piola_world_body_at(world, position);
  body_mesh m = {.id = id,
                 .kind = piola_world_body_kind(world, id),
                 .index = piola_world_body_index(world, id),
                 .name = piola_world_body_name(world, id)};
  switch (m.kind) {
    case PIOLA_BODY_SOLID: {
      const piola_elastic_body *b = piola_world_solid_body(world, m.index);
      m.nodes = piola_elastic_body_vertex_count(b), m.cells = piola_elastic_body_tet_count(b);
      m.rest = piola_elastic_body_rest_positions(b), m.elements = piola_elastic_body_tets(b);
      break;
    }
    case PIOLA_BODY_SHELL: {
      const piola_shell_body *b = piola_world_shell_body(world, m.index);
      m.nodes = piola_shell_body_vertex_count(b), m.cells = piola_shell_body_triangle_count(b);
      m.rest = piola_shell_body_rest_positions(b), m.elements = piola_shell_body_triangles(b);
      break;
    }
    case PIOLA_BODY_NONE:
      break;
  }
  return m;
}

/* The frame's topology: the concatenated tets, shell triangles, rest positions, the
 * boundary surface and the OBJ layout, for the world's current meshes. */
static piola_status build_topology(piola_output *o, const piola_world *world) {
  /* points: every body's nodes in the body table's order (the solids, then the shells);
   * cells: the solids' tets, then the shells' triangles */
  const int32_t nb = piola_world_body_count(world);
  int32_t nodes[PIOLA_BODY_KIND_COUNT] = {0}, cells[PIOLA_BODY_KIND_COUNT] = {0};
  for (int32_t p = 0; p < nb; ++p) {
    const body_mesh m = body_mesh_at(world, p);
    if (m.kind == PIOLA_BODY_NONE) continue;
    nodes[m.kind] += m.nodes;
    cells[m.kind] += m.cells;
  }
  const int32_t nv = nodes[PIOLA_BODY_SOLID], nt = cells[PIOLA_BODY_SOLID];
  const int32_t snv = nodes[PIOLA_BODY_SHELL], snt = cells[PIOLA_BODY_SHELL];
  o->solid_vertices = nv;
  o->solid_cells = nt;
  /* point arrays hold the solids' vertices then the shells'; cell arrays tets then triangles */
  size_t v3 = 3 * (size_t)(nv + snv > 0 ? nv + snv : 1) * sizeof(double);
  size_t tc = (size_t)(nt + snt > 0 ? nt + snt : 1);
  o->tets.vertex_count = nv;
  o->tets.tet_count = nt;
  o->shells.vertex_count = snv;
  o->shells.triangle_count = snt;
  o->shells.triangles = malloc(3 * (size_t)(snt > 0 ? snt : 1) * sizeof(int32_t));
  o->tets.positions = malloc(v3);
  o->tets.tets = malloc(4 * tc * sizeof(int32_t));
  o->rest = malloc(v3), o->velocity = malloc(v3), o->displacement = malloc(v3);
  o->det_f = malloc(tc * sizeof(double)), o->inverted = malloc(tc * sizeof(double));
  o->energy = malloc(tc * sizeof(double)), o->solid = malloc(tc * sizeof(double));
  if (o->fractures) o->fragment = malloc(tc * sizeof(double)), o->fraction = malloc(tc * sizeof(double));
  if (!o->tets.positions || !o->tets.tets || !o->shells.triangles || !o->rest || !o->velocity || !o->displacement ||
      !o->det_f || !o->inverted || !o->energy || !o->solid || (o->fractures && (!o->fragment || !o->fraction)))
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "output: out of memory");
  int32_t point = 0, toff = 0, stoff = 0;
  for (int32_t p = 0; p < nb; ++p) {
    const body_mesh m = body_mesh_at(world, p);
    if (m.kind == PIOLA_BODY_NONE) continue;
    memcpy(o->rest + 3 * (size_t)point, m.rest, 3 * (size_t)m.nodes * sizeof(double));
    switch (m.kind) {
      case PIOLA_BODY_SOLID:
        for (int64_t k = 0; k < 4 * (int64_t)m.cells; ++k)
          o->tets.tets[4 * (int64_t)toff + k] = m.elements[k] + point;
        for (int32_t k = 0; k < m.cells; ++k) o->solid[toff + k] = m.index;
        if (o->fractures) {
          const int32_t *frag = piola_world_solid_fragments(world, m.index);
          const double *fraction = piola_world_solid_material_fractions(world, m.index);
          for (int32_t k = 0; k < m.cells; ++k)
            o->fragment[toff + k] = frag ? frag[k] : 0, o->fraction[toff + k] = fraction ? fraction[k] : 1;
        }
        toff += m.cells;
        break;
      case PIOLA_BODY_SHELL: /* numbered from the first shell node */
        for (int64_t k = 0; k < 3 * (int64_t)m.cells; ++k)
          o->shells.triangles[3 * (int64_t)stoff + k] = m.elements[k] + point - nv;
        for (int32_t k = 0; k < m.cells; ++k) o->solid[nt + stoff + k] = -1 - m.index;
        if (o->fractures)
          for (int32_t k = 0; k < m.cells; ++k) o->fragment[nt + stoff + k] = -1, o->fraction[nt + stoff + k] = 1;
        stoff += m.cells;
        break;
      case PIOLA_BODY_NONE:
        break;
    }
    point += m.nodes;
  }
  memcpy(o->tets.positions, o->rest, 3 * (size_t)(nv + snv) * sizeof(double));
  piola_status st = PIOLA_OK;
  if (nt > 0) st = piola_tet_mesh_boundary(&o->tets, &o->surface);
  if (st == PIOLA_OK) {
    /* the surface shares the tets' numbering: each frame lends it the current positions */
    free(o->surface.positions);
    o->surface.positions = NULL;
  }
  if (st == PIOLA_OK && snt > 0) {
    /* the OBJ surface: the solids' boundary, then the shells' triangles */
    int32_t base = o->surface.triangle_count;
    int32_t *grown = realloc(o->surface.triangles, 3 * (size_t)(base + snt) * sizeof(int32_t));
    if (!grown) st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "output: out of memory");
    else {
      o->surface.triangles = grown;
      for (int64_t k = 0; k < 3 * (int64_t)snt; ++k) grown[3 * (int64_t)base + k] = o->shells.triangles[k] + nv;
      o->surface.triangle_count = base + snt;
      o->surface.vertex_count = nv + snv;
    }
  }
  if (st == PIOLA_OK) {
    /* bodies in point order */
    int32_t *first = malloc((size_t)(nb + 1) * sizeof *first);
    const char **names = malloc((size_t)(nb > 0 ? nb : 1) * sizeof *names);
    if (!first || !names) st = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "output: out of memory");
    else {
      int32_t v = 0;
      for (int32_t b = 0; b < nb; ++b) {
        const body_mesh m = body_mesh_at(world, b);
        first[b] = v;
        names[b] = m.name;
        v += m.nodes;
      }
      first[nb] = v;
      st = piola__obj_layout_build(&o->surface, first, nb, names, nv + snv, &o->obj);
    }
    free(first);
    free(names);
  }
  return st;
}

static void free_topology(piola_output *o) {
  piola_tet_mesh_free(&o->tets);
  piola_tri_mesh_free(&o->surface);
  o->shells.positions = NULL; /* borrowed */
  piola_tri_mesh_free(&o->shells);
  free(o->rest), free(o->velocity), free(o->displacement), free(o->det_f), free(o->inverted);
  free(o->energy), free(o->solid), free(o->fragment), free(o->fraction);
  o->rest = o->velocity = o->displacement = o->det_f = o->inverted = NULL;
  o->energy = o->solid = o->fragment = o->fraction = NULL;
  piola__obj_layout_free(&o->obj);
  memset(&o->tets, 0, sizeof o->tets), memset(&o->surface, 0, sizeof o->surface);
  memset(&o->shells, 0, sizeof o->shells);
}


/* resume_frame < 0: a new run (force as in piola_output_open); else a resume after it.
 * piece_count > 0: a split run's output for piece `piece` (piola_output_open_pieces). */
static piola_status open_output(const char *dir, bool force, int32_t resume_frame,
                                const piola_world *world, int32_t piece, int32_t piece_count,
                                piola_output **out) {
  if (!dir || !world || !out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "output: NULL argument");
  *out = NULL;
  if (strlen(dir) > 3500) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "output: path too long");
  piola_output *o = calloc(1, sizeof *o);
  if (!o) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "output: out of memory");
  snprintf(o->dir, sizeof o->dir, "%s", dir);
  for (int32_t s = 0; s < piola_world_solid_count(world); ++s)
    if (piola_world_solid_has_fracture(world, s)) o->fractures = true;
  o->piece_count = piece_count;
  o->lead = piece == 0;
  piola_status st = PIOLA_OK;
  if (piece_count > 0) st = piola__piece_layout_build(&o->piece, world, piece, piece_count);
  if (st == PIOLA_OK && !o->lead) { /* the folder and the indexes are piece 0's */
    *out = o;
    return PIOLA_OK;
  }
  if (st == PIOLA_OK) st = build_topology(o, world);
  if (st == PIOLA_OK && resume_frame < 0) st = piola__output_prepare_folder(dir, force);
  if (st == PIOLA_OK) st = csv_append(o, "frame,time,substeps,cg_iterations,kinetic_energy,elastic_energy,"
                                         "inverted,min_det_f,wall_seconds,plastic_yielded,max_fp_log_stretch,"
                                         "contacts,impacts,impact_zones,newton_iterations,"
                                         "linear_iterations,newton_failures,step_retries,energy_redos,fragments,cut_tets\n");
  if (st == PIOLA_OK && resume_frame >= 0) st = resume_indexes(o, resume_frame);
  if (st != PIOLA_OK) {
    piola_output_close(o);
    return st;
  }
  *out = o;
  return PIOLA_OK;
}

/* Writes text to a temporary file next to path and queues its rename to path. */
static piola_status stage_text(frame_commit *c, const char *path, const char *text, size_t len) {
  piola_atomic_file f;
  PIOLA_TRY(piola_atomic_file_open(&f, path));
  if (len && fwrite(text, 1, len, f.stream) != len) {
    piola_atomic_file_abort(&f);
    return PIOLA_FAIL(PIOLA_ERROR_IO, "%s: write failed", path);
  }
  PIOLA_TRY(piola__atomic_file_finish(&f));
  piola__frame_commit_add(c, f.temporary, f.target, 1);
  return PIOLA_OK;
}

static piola_status stage_pvd(piola_output *o, frame_commit *c) {
  char path[4200];
  snprintf(path, sizeof path, "%s/sim.pvd", o->dir);
  piola_atomic_file f;
  PIOLA_TRY(piola_atomic_file_open(&f, path));
  fprintf(f.stream, "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" "
                    "byte_order=\"LittleEndian\">\n  <Collection>\n");
  for (int32_t i = 0; i < o->pvd_count; ++i)
    fprintf(f.stream, "    <DataSet timestep=\"%.17g\" group=\"\" part=\"0\" file=\"frames/frame_%04d.%s\"/>\n",
            o->pvd[i].time, (int)o->pvd[i].frame, o->piece_count > 0 ? "pvtu" : "vtu");
  fprintf(f.stream, "  </Collection>\n</VTKFile>\n");
  PIOLA_TRY(piola__atomic_file_finish(&f));
  piola__frame_commit_add(c, f.temporary, f.target, 1);
  return PIOLA_OK;
}

static piola_status pvd_append(piola_output *o, int32_t frame, double time) {
  if (o->pvd_count == o->pvd_cap) {
    int32_t cap = o->pvd_cap ? 2 * o->pvd_cap : 64;
    pvd_entry *grown = realloc(o->pvd, (size_t)cap * sizeof *grown);
    if (!grown) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "sim.pvd: out of memory");
    o->pvd = grown;
    o->pvd_cap = cap;
  }
  o->pvd[o->pvd_count++] = (pvd_entry){frame, time};
  return PIOLA_OK;
}

/* Writes the frame's files under temporary names and publishes them at one commit point
 * (output/frame_commit.h); on any failure nothing of the frame is listed and the indexes in
 * memory are as before. */
static piola_status commit_frame(piola_output *o, const piola_vtu_frame *frame, int32_t number,
                                 const char *row, double time) {
  frame_commit commit = {0};
  char path[4200], pending[4200];
  if (o->piece_count > 0) { /* the pieces are in place (piola_output_write_piece) */
    PIOLA_TRY(piola__pvtu_stage(&commit, o->dir, number, o->piece_count, o->fractures));
  } else {
    snprintf(path, sizeof path, "%s/frames/frame_%04d.vtu", o->dir, (int)number);
    if (!piola__frame_pending_name(path, pending, sizeof pending))
      return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "output: path too long");
    PIOLA_TRY(piola_vtu_write(pending, frame));
    piola__frame_commit_add(&commit, pending, path, 0);
  }
  snprintf(path, sizeof path, "%s/surface/frame_%04d.obj", o->dir, (int)number);
  piola__frame_pending_name(path, pending, sizeof pending);
  piola_status st = o->fractures ? piola__obj_write_fragments(&o->obj, pending, o->tets.positions, o->world)
                                 : piola__obj_layout_write(&o->obj, pending, o->tets.positions);
  if (st == PIOLA_OK) piola__frame_commit_add(&commit, pending, path, 0);
  size_t csv_len = o->csv_len;
  int32_t pvd_count = o->pvd_count;
  if (st == PIOLA_OK) st = csv_append(o, row);
  if (st == PIOLA_OK) st = pvd_append(o, number, time);
  snprintf(path, sizeof path, "%s/stats.csv", o->dir);
  if (st == PIOLA_OK) st = stage_text(&commit, path, o->csv, o->csv_len);
  if (st == PIOLA_OK) st = stage_pvd(o, &commit);
  if (st == PIOLA_OK) st = piola__frame_commit_publish(&commit);
  if (st != PIOLA_OK) {
    piola__frame_commit_discard(&commit);
    o->csv_len = csv_len;
    if (o->csv) o->csv[csv_len] = '\0';
    o->pvd_count = pvd_count;
  }
  return st;
}

piola_status piola_output_write_frame(piola_output *o, const piola_world *world,
                                      const piola_frame_info *info) {
  if (!o || !world || !info) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "output: NULL argument");
  if (!o->lead)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "output: piece %d writes its piece only",
                      (int)o->piece.piece);
  int32_t ns = piola_world_solid_count(world);
  long long fragments = 0, cut_tets = 0;
  for (int32_t s = 0; s < ns; ++s) {
    fragments += piola_world_solid_fragment_count(world, s);
    cut_tets += piola_world_solid_cut_tet_count(world, s);
  }
  if (o->fractures) {
    /* cuts change the meshes between frames */
    free_topology(o);
    PIOLA_TRY(build_topology(o, world));
  }
  int32_t voff = 0, toff = 0;
  double ke = 0, ee = 0, min_det = INFINITY;
  long long inverted = 0, yielded = 0;
  double max_fp_log = 0; /* plastic solids: yielded tets in the last step, largest |log stretch| of Fp */
  /* the bodies in step order: the solids, then the shells, as the points and cells are laid out */
  for (int32_t p = 0; p < piola_world_body_count(world); ++p) {
    const piola_body_id id = piola_world_body_at(world, p);
    const int32_t index = piola_world_body_index(world, id);
    const int32_t n = piola_world_body_node_count(world, id);
    const int32_t t = piola_world_body_element_count(world, id);
    const double *x = piola_world_body_positions(world, id);
    const double *v = piola_world_body_velocities(world, id);
    for (int64_t k = 0; k < 3 * (int64_t)n; ++k) {
      int64_t g = 3 * (int64_t)voff + k;
      o->tets.positions[g] = x[k];
      o->velocity[g] = v[k];
      o->displacement[g] = x[k] - o->rest[g];
    }
    const piola_body_stats st = piola_world_body_stats(world, id);
    ke += st.kinetic_energy;
    ee += st.elastic_energy;
    inverted += st.inverted_count;
    switch (piola_world_body_kind(world, id)) {
      case PIOLA_BODY_SOLID: {
        const piola_elastic_body *b = piola_world_solid_body(world, index);
        const double *det = piola_elastic_body_det_f(b);
        const double *psi = piola_elastic_body_energy_density(b);
        for (int32_t k = 0; k < t; ++k) {
          o->det_f[toff + k] = det[k];
          o->inverted[toff + k] = det[k] < 0 ? 1.0 : 0.0;
          o->energy[toff + k] = psi[k];
        }
        double solid_min_det = piola_world_solid_stats(world, index).min_det_f;
        if (solid_min_det < min_det) min_det = solid_min_det;
        const piola_plastic_state *plastic = piola_world_solid_plastic_state(world, index);
        if (plastic) {
          double largest;
          piola_plastic_state_measure(plastic, &largest, NULL);
          if (largest > max_fp_log) max_fp_log = largest;
          yielded += piola_world_solid_plastic_stats(world, index).yielded_count;
        }
        break;
      }
      case PIOLA_BODY_SHELL: {
        const double *fhat = piola_shell_body_fhat(piola_world_shell_body(world, index));
        for (int32_t k = 0; k < t; ++k) {
          o->det_f[toff + k] = fhat[2 * k] * fhat[2 * k + 1];
          o->inverted[toff + k] = fhat[2 * k + 1] < 0 ? 1.0 : 0.0;
          o->energy[toff + k] = 0.0;
        }
        break;
      }
      case PIOLA_BODY_NONE: break;
    }
    voff += n;
    toff += t;
  }
  o->shells.positions = o->tets.positions + 3 * (size_t)o->solid_vertices;
  piola_vtu_field points[2] = {{"velocity", 3, o->velocity}, {"displacement", 3, o->displacement}};
  piola_vtu_field cells[6] = {{"det_f", 1, o->det_f},
                              {"inverted", 1, o->inverted},
                              {"energy_density", 1, o->energy},
                              {"solid", 1, o->solid},
                              {"fragment", 1, o->fragment},
                              {"material_fraction", 1, o->fraction}};
  piola_vtu_frame frame = {.tets = o->solid_cells > 0 ? &o->tets : NULL,
                           .triangles = o->shells.triangle_count > 0 ? &o->shells : NULL,
                           .point_fields = points, .point_field_count = 2, .cell_fields = cells,
                           .cell_field_count = o->fractures ? 6 : 4, .positions = o->tets.positions};
  char line[600];
  snprintf(line, sizeof line, "%d,%.17g,%d,%d,%.17g,%.17g,%lld,%.17g,%.6f,%lld,%.17g,%lld,%lld,%d,%d,%d,%d,%d,%d,%lld,%lld\n",
           (int)info->frame, piola_world_time(world), (int)info->substeps, (int)info->cg_iterations,
           ke, ee, inverted, ns > 0 ? min_det : 1.0, info->wall_seconds, yielded, max_fp_log,
           (long long)info->contacts, (long long)info->impacts, (int)info->impact_zones,
           (int)info->newton_iterations, (int)info->linear_iterations, (int)info->newton_failures,
           (int)info->step_retries, (int)info->energy_redos, fragments, cut_tets);
  o->world = world;
  return commit_frame(o, &frame, info->frame, line, piola_world_time(world));
}

piola_status piola_output_open(const char *dir, bool force, const piola_world *world,
                               piola_output **out) {
  return open_output(dir, force, -1, world, 0, 0, out);
}

piola_status piola_output_open_resume(const char *dir, int32_t frame, const piola_world *world,
                                      piola_output **out) {
  if (frame < 0) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "output: resume frame must be >= 0");
  return open_output(dir, false, frame, world, 0, 0, out);
}

piola_status piola_output_open_pieces(const char *dir, bool force, int32_t resume_frame,
                                      const piola_world *world, int32_t piece,
                                      int32_t piece_count, piola_output **out) {
  if (out) *out = NULL;
  if (piece_count < 1 || piece < 0 || piece >= piece_count)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "output: piece %d of %d", (int)piece, (int)piece_count);
  return open_output(dir, force, resume_frame < 0 ? -1 : resume_frame, world, piece, piece_count, out);
}

piola_status piola_output_write_piece(piola_output *o, const piola_world *world, int32_t frame) {
  if (!o || !world) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "output: NULL argument");
  if (o->piece_count == 0)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "output: not opened for pieces");
  return piola__piece_write(&o->piece, world, o->dir, frame);
}

/* Takes over frames 0..frame of the folder (output_reconcile.c) and rewrites both indexes
 * to list exactly those. */
static piola_status resume_indexes(piola_output *o, int32_t frame) {
  char *rows;
  size_t length;
  PIOLA_TRY(piola__output_reconcile(o->dir, frame, o->piece_count, &rows, &length));
  piola_status st = csv_append(o, rows);
  for (const char *line = rows; st == PIOLA_OK && *line;) {
    char *end;
    long k = strtol(line, &end, 10);
    double time = strtod(end + 1, NULL);
    st = pvd_append(o, (int32_t)k, time);
    const char *next = strchr(line, '\n');
    line = next ? next + 1 : line + strlen(line);
  }
  free(rows);
  frame_commit commit = {0};
  char path[4200];
  snprintf(path, sizeof path, "%s/stats.csv", o->dir);
  if (st == PIOLA_OK) st = stage_text(&commit, path, o->csv, o->csv_len);
  if (st == PIOLA_OK) st = stage_pvd(o, &commit);
  if (st == PIOLA_OK) st = piola__frame_commit_publish(&commit);
  if (st != PIOLA_OK) piola__frame_commit_discard(&commit);
  return st;
}

typedef struct ranked {
  int32_t element;
  double key;
} ranked;

static int by_key(const void *a, const void *b) {
  double x = ((const ranked *)a)->key, y = ((const ranked *)b)->key;
  return (x > y) - (x < y);
}

enum { WORST = 10 }; /* elements listed per ranking */

/* Ranks cells by key times sign (ascending; non-finite keys first) into r. */
static void rank(ranked *r, int32_t cells, const double *key, double sign) {
  for (int32_t k = 0; k < cells; ++k) {
    double v = sign * key[k];
    r[k].element = k;
    r[k].key = isfinite(v) ? v : -INFINITY; /* non-finite values rank worst */
  }
  qsort(r, (size_t)cells, sizeof *r, by_key);
}

/* A solid: its stats and the tets with the smallest det F and the largest energy density. */
static void report_solid(FILE *out, const piola_world *world, const body_mesh *m, ranked *r) {
  const piola_elastic_body *b = piola_world_solid_body(world, m->index);
  const double *det = piola_elastic_body_det_f(b);
  const double *psi = piola_elastic_body_energy_density(b);
  const double *fhat = piola_elastic_body_fhat(b);
  const int32_t *tets = m->elements;
  piola_solid_stats st = piola_world_solid_stats(world, m->index);
  fprintf(out, "solid '%s': %d tets, %d inverted, min det F %.6g, kinetic %.6g J, elastic %.6g J\n",
          m->name, (int)m->cells, (int)st.inverted_count, st.min_det_f, st.kinetic_energy,
          st.elastic_energy);
  for (int pass = 0; pass < 2; ++pass) {
    rank(r, m->cells, pass == 0 ? det : psi, pass == 0 ? 1.0 : -1.0);
    fprintf(out, "  worst by %s:\n", pass == 0 ? "smallest det F" : "largest energy density");
    for (int32_t k = 0; k < m->cells && k < WORST; ++k) {
      int32_t e = r[k].element;
      fprintf(out,
              "    tet %d (vertices %d %d %d %d): det F %.6g, energy density %.6g J/m^3, "
              "Fhat (%.4g, %.4g, %.4g)\n",
              (int)e, (int)tets[4 * e], (int)tets[4 * e + 1], (int)tets[4 * e + 2],
              (int)tets[4 * e + 3], det[e], psi[e], fhat[3 * e], fhat[3 * e + 1], fhat[3 * e + 2]);
    }
  }
}

/* A shell: its stats and the triangles with the smallest signed area ratio fhat0 * fhat1
 * (negative: the triangle opposes its reference normal). */
static piola_status report_shell(FILE *out, const piola_world *world, const body_mesh *m,
                                 ranked *r) {
  const double *fhat = piola_shell_body_fhat(piola_world_shell_body(world, m->index));
  const int32_t *tris = m->elements;
  piola_body_stats st = piola_world_body_stats(world, m->id);
  fprintf(out, "shell '%s': %d triangles, %d inverted, kinetic %.6g J, elastic %.6g J\n", m->name,
          (int)m->cells, (int)st.inverted_count, st.kinetic_energy, st.elastic_energy);
  double *ratio = malloc((size_t)(m->cells > 0 ? m->cells : 1) * sizeof *ratio);
  if (!ratio) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "failure report: out of memory");
  for (int32_t k = 0; k < m->cells; ++k) ratio[k] = fhat[2 * k] * fhat[2 * k + 1];
  rank(r, m->cells, ratio, 1.0);
  fprintf(out, "  worst by smallest area ratio (Fhat1 Fhat2):\n");
  for (int32_t k = 0; k < m->cells && k < WORST; ++k) {
    int32_t e = r[k].element;
    fprintf(out, "    triangle %d (vertices %d %d %d): area ratio %.6g, Fhat (%.4g, %.4g)\n", (int)e,
            (int)tris[3 * e], (int)tris[3 * e + 1], (int)tris[3 * e + 2], ratio[e], fhat[2 * e],
            fhat[2 * e + 1]);
  }
  free(ratio);
  return PIOLA_OK;
}

piola_status piola_output_write_failure_report(piola_output *o, const piola_world *world,
                                               const char *message) {
  char path[4200];
  snprintf(path, sizeof path, "%s/failure_report.txt", o->dir);
  piola_atomic_file f;
  PIOLA_TRY(piola_atomic_file_open(&f, path));
  fprintf(f.stream, "piola run stopped: %s\n", message ? message : "(no message)");
  fprintf(f.stream, "last good state: t = %.9g s (frames written up to that point are complete)\n\n",
          piola_world_time(world));
  for (int32_t p = 0; p < piola_world_body_count(world); ++p) {
    const body_mesh m = body_mesh_at(world, p);
    if (m.kind == PIOLA_BODY_NONE) continue;
    ranked *r = malloc((size_t)(m.cells > 0 ? m.cells : 1) * sizeof *r);
    if (!r) {
      piola_atomic_file_abort(&f);
      return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "failure report: out of memory");
    }
    piola_status st = PIOLA_OK;
    switch (m.kind) {
      case PIOLA_BODY_SOLID:
        report_solid(f.stream, world, &m, r);
        break;
      case PIOLA_BODY_SHELL:
        st = report_shell(f.stream, world, &m, r);
        break;
      case PIOLA_BODY_NONE:
        break;
    }
    free(r);
    if (st != PIOLA_OK) {
      piola_atomic_file_abort(&f);
      return st;
    }
  }
  return piola_atomic_file_commit(&f);
}

/* The lines of an earlier warnings.txt in dir (a resumed run's), or NULL; malloc'ed. */
static char *earlier_warnings(const char *path) {
  FILE *in = fopen(path, "rb");
  if (!in) return NULL;
  char *text = NULL;
  size_t len = 0, cap = 0;
  for (int c; (c = fgetc(in)) != EOF;) {
    if (len + 2 > cap) {
      cap = cap ? 2 * cap : 4096;
      char *grown = realloc(text, cap);
      if (!grown) break;
      text = grown;
    }
    text[len++] = (char)c;
  }
  fclose(in);
  if (text) text[len] = 0;
  return text;
}

/* True when text holds line (without its newline) as a whole line. */
static bool has_line(const char *text, const char *line) {
  size_t n = strlen(line);
  for (const char *p = text; p && *p;) {
    const char *end = strchr(p, '\n');
    size_t k = end ? (size_t)(end - p) : strlen(p);
    if (k == n && memcmp(p, line, n) == 0) return true;
    p = end ? end + 1 : NULL;
  }
  return false;
}

piola_status piola_output_write_warnings(piola_output *output, const piola_world *world) {
  char path[4200];
  snprintf(path, sizeof path, "%s/warnings.txt", output->dir);
  /* the file's lines are kept: they are this run's own, or, after --resume, those of the run
   * it continues (--force removes an earlier run's file when the output opens) */
  char *kept = earlier_warnings(path);
  bool fresh = false;
  for (int k = 0; k < PIOLA_WARNING_KIND_COUNT; ++k) {
    const char *w = piola_world_warning(world, (piola_warning_kind)k);
    if (w && !has_line(kept, w)) fresh = true;
  }
  if (!fresh) {
    free(kept);
    return PIOLA_OK;
  }
  piola_atomic_file f;
  piola_status st = piola_atomic_file_open(&f, path);
  if (st != PIOLA_OK) {
    free(kept);
    return st;
  }
  if (kept) fputs(kept, f.stream);
  if (kept && *kept && kept[strlen(kept) - 1] != '\n') fputc('\n', f.stream);
  for (int k = 0; k < PIOLA_WARNING_KIND_COUNT; ++k) {
    const char *w = piola_world_warning(world, (piola_warning_kind)k);
    if (w && !has_line(kept, w)) fprintf(f.stream, "%s\n", w);
  }
  free(kept);
  return piola_atomic_file_commit(&f);
}
