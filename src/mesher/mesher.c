/* piola_mesher_generate: lattice -> level set -> refinement -> keep tets -> manifold repair
 * -> snap the boundary to the surface under a quality guard. See docs/mesher.md. */
#include "piola/mesher.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "common/status_report.h"
#include "common/union_find.h"
#include "mesher/bcc_lattice.h"
#include "mesher/boundary_snap.h"
#include "mesher/lattice_phi.h"
#include "mesher/red_green.h"
#include "mesher/shape_union.h"
#include "mesher/tet_topology.h"
#include "piola/threads.h"

#define MAX_LATTICE_TETS 120000000LL
#define MAX_REFINEMENT_LEVELS 6
#define MAX_REPAIR_ROUNDS 64
#define PRUNE_ROUNDS 3
/* Pieces smaller than this many finest lattice cubes are dropped. */
#define CRUMB_CELLS 4.0

piola_mesher_def piola_default_mesher_def(void) {
  piola_mesher_def def;
  memset(&def, 0, sizeof(def));
  for (int i = 0; i < PIOLA_MESHER_MAX_SHAPES; ++i) {
    def.shapes[i].type = PIOLA_SHAPE_SPHERE;
    def.shapes[i].axis = (piola_vec3){0, 0, 1};
    def.shapes[i].radius = 1.0;
    def.shapes[i].minor_radius = 0.25;
    def.shapes[i].half_length = 1.0;
    def.shapes[i].half_extents = (piola_vec3){1, 1, 1};
  }
  def.shape_count = 0;
  def.cell_size = 0;
  def.refinement_levels = 0;
  return def;
}

void piola__tet_soup_free(piola__tet_soup *soup) {
  free(soup->positions);
  free(soup->phi);
  free(soup->tets);
  memset(soup, 0, sizeof(*soup));
}

/* Adjacency of the whole lattice (kept or not), built once: the boundary of any kept subset
 * is then the faces whose neighbour is missing or not kept. */
typedef struct lattice_topology {
  piola__csr vertex_tets;
  int32_t *neighbor; /* 4 per tet */
} lattice_topology;

static int is_open_face(const lattice_topology *topo, const uint8_t *keep, int64_t face) {
  int32_t n = topo->neighbor[face];
  return n == -1 || (n >= 0 && !keep[n]);
}

static int compare_u64(const void *pa, const void *pb) {
  uint64_t a = *(const uint64_t *)pa, b = *(const uint64_t *)pb;
  return a < b ? -1 : (a > b);
}

/* Marks (bad[v] = 1) the vertices where the boundary of the kept tets is not a 2-manifold:
 * on a boundary edge used by other than 2 boundary faces, or where the boundary faces
 * around a vertex form more than one fan. Returns the number of marked vertices, or -1 when
 * out of memory. */
static int64_t mark_nonmanifold(const piola__tet_soup *soup, const lattice_topology *topo,
                                const uint8_t *keep, uint8_t *bad) {
  int32_t nv = soup->vertex_count, nt = soup->tet_count;
  const int32_t *neighbor = topo->neighbor;
  int64_t faces = 0;
  for (int64_t i = 0; i < (int64_t)nt * 4; ++i)
    if (keep[i / 4] && is_open_face(topo, keep, i)) faces++;
  int32_t *tri = malloc((size_t)(faces + 1) * 3 * sizeof(int32_t));
  uint64_t *edges = malloc((size_t)(faces + 1) * 3 * sizeof(uint64_t));
  if (!tri || !edges) {
    free(tri);
    free(edges);
    return -1;
  }
  memset(bad, 0, (size_t)nv);
  int64_t nf = 0;
  for (int32_t t = 0; t < nt; ++t) {
    if (!keep[t]) continue;
    for (int f = 0; f < 4; ++f) {
      if (neighbor[4 * t + f] == -2)
        for (int k = 0; k < 3; ++k) bad[soup->tets[4 * t + piola__tet_face[f][k]]] = 1;
      if (!is_open_face(topo, keep, 4 * (int64_t)t + f)) continue;
      for (int k = 0; k < 3; ++k) tri[3 * nf + k] = soup->tets[4 * t + piola__tet_face[f][k]];
      nf++;
    }
  }
  for (int64_t f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      uint64_t a = (uint64_t)tri[3 * f + k], b = (uint64_t)tri[3 * f + (k + 1) % 3];
      edges[3 * f + k] = a < b ? (a << 32 | b) : (b << 32 | a);
    }
  qsort(edges, (size_t)nf * 3, sizeof(uint64_t), compare_u64);
  for (int64_t i = 0; i < nf * 3;) {
    int64_t j = i;
    while (j < nf * 3 && edges[j] == edges[i]) ++j;
    if (j - i != 2) {
      bad[edges[i] >> 32] = 1;
      bad[edges[i] & 0xffffffffu] = 1;
    }
    i = j;
  }
  free(edges);
  /* Fans around each vertex: faces are linked when they share an edge through the vertex. */
  int32_t *count = calloc((size_t)nv + 1, sizeof(int32_t));
  if (!count) {
    free(tri);
    return -1;
  }
  for (int64_t f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) count[tri[3 * f + k] + 1]++;
  for (int32_t v = 0; v < nv; ++v) count[v + 1] += count[v];
  int32_t *items = malloc((size_t)(nf * 3 + 1) * sizeof(int32_t));
  int32_t *fill = malloc((size_t)(nv + 1) * sizeof(int32_t));
  if (!items || !fill) {
    free(items);
    free(fill);
    free(count);
    free(tri);
    return -1;
  }
  memcpy(fill, count, (size_t)nv * sizeof(int32_t));
  for (int64_t f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) items[fill[tri[3 * f + k]]++] = (int32_t)f;
  free(fill);
#pragma omp parallel for schedule(dynamic, 256) num_threads(piola_thread_count())
  for (int32_t v = 0; v < nv; ++v) {
    int32_t begin = count[v], n = count[v + 1] - begin;
    if (n == 0 || bad[v]) continue;
    enum { MAX_FAN = 128 };
    if (n > MAX_FAN) {
      bad[v] = 1;
      continue;
    }
    int32_t other[MAX_FAN][2];
    uint8_t seen[MAX_FAN] = {0};
    for (int32_t i = 0; i < n; ++i) {
      const int32_t *t3 = tri + 3 * (int64_t)items[begin + i];
      int m = 0;
      for (int k = 0; k < 3; ++k)
        if (t3[k] != v) other[i][m++] = t3[k];
    }
    int32_t queue[MAX_FAN], head = 0, tail = 0;
    queue[tail++] = 0;
    seen[0] = 1;
    while (head < tail) {
      int32_t i = queue[head++];
      for (int32_t j = 0; j < n; ++j) {
        if (seen[j]) continue;
        if (other[j][0] == other[i][0] || other[j][0] == other[i][1] ||
            other[j][1] == other[i][0] || other[j][1] == other[i][1]) {
          seen[j] = 1;
          queue[tail++] = j;
        }
      }
    }
    if (tail != n) bad[v] = 1;
  }
  free(items);
  free(count);
  free(tri);
  int64_t marked = 0;
  for (int32_t v = 0; v < nv; ++v) marked += bad[v];
  return marked;
}

/* Adds back every tet around a vertex where the boundary is not manifold, until it is. */
static piola_status repair_manifold(const piola__tet_soup *soup, const lattice_topology *topo,
                                    uint8_t *keep) {
  const piola__csr all = topo->vertex_tets;
  uint8_t *bad = malloc((size_t)soup->vertex_count + 1);
  if (!bad) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "mesher: manifold repair");
  piola_status status = PIOLA_OK;
  for (int round = 0;; ++round) {
    int64_t marked = mark_nonmanifold(soup, topo, keep, bad);
    if (marked < 0) {
      status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "mesher: manifold repair");
      break;
    }
    if (marked == 0) break;
    if (round == MAX_REPAIR_ROUNDS) {
      int32_t v = 0;
      while (!bad[v]) ++v;
      status = PIOLA_FAIL(PIOLA_ERROR_UNSUPPORTED,
                          "mesher: the boundary is still not manifold at vertex %d after %d "
                          "repair rounds; try a smaller cell_size",
                          (int)v, MAX_REPAIR_ROUNDS);
      break;
    }
    for (int32_t v = 0; v < soup->vertex_count; ++v) {
      if (!bad[v]) continue;
      for (int32_t i = all.offsets[v]; i < all.offsets[v + 1]; ++i) keep[all.items[i]] = 1;
    }
  }
  free(bad);
  return status;
}

/* Drops kept tets whose four nodes all lie on the boundary: snapping would flatten them
 * onto the surface (MBTF03 prunes them for the same reason). Returns how many were dropped,
 * or -1 when out of memory. */
static int64_t drop_boundary_only_tets(const piola__tet_soup *soup, const lattice_topology *topo,
                                       uint8_t *keep) {
  int32_t nv = soup->vertex_count, nt = soup->tet_count;
  uint8_t *on_boundary = calloc((size_t)nv + 1, 1);
  if (!on_boundary) return -1;
  for (int32_t t = 0; t < nt; ++t) {
    if (!keep[t]) continue;
    for (int f = 0; f < 4; ++f)
      if (is_open_face(topo, keep, 4 * (int64_t)t + f))
        for (int k = 0; k < 3; ++k) on_boundary[soup->tets[4 * t + piola__tet_face[f][k]]] = 1;
  }
  int64_t dropped = 0;
  for (int32_t t = 0; t < nt; ++t) {
    if (!keep[t]) continue;
    const int32_t *tet = soup->tets + 4 * (size_t)t;
    if (on_boundary[tet[0]] && on_boundary[tet[1]] && on_boundary[tet[2]] && on_boundary[tet[3]]) {
      keep[t] = 0;
      dropped++;
    }
  }
  free(on_boundary);
  return dropped;
}

/* Drops face-connected pieces of the kept tets whose volume is below min_volume: crumbs cut off
 * thin, unresolved parts (an ear tip thinner than the lattice), not shapes of their own.
 * Pieces never touch (the repair made the boundary manifold), so this keeps it manifold.
 * Returns the number of tets dropped, or -1 when out of memory. */
static int64_t drop_crumbs(const piola__tet_soup *soup, const lattice_topology *topo, uint8_t *keep,
                           double min_volume) {
  int32_t nt = soup->tet_count;
  int32_t *parent = malloc((size_t)nt * sizeof(int32_t) + 1);
  double *volume = calloc((size_t)nt + 1, sizeof(double));
  if (!parent || !volume) {
    free(parent);
    free(volume);
    return -1;
  }
  for (int32_t t = 0; t < nt; ++t) parent[t] = t;
  for (int32_t t = 0; t < nt; ++t) {
    if (!keep[t]) continue;
    for (int f = 0; f < 4; ++f) {
      int32_t u = topo->neighbor[4 * (size_t)t + f];
      if (u < 0 || !keep[u]) continue;
      piola__union_find_join(parent, t, u);
    }
  }
  for (int32_t t = 0; t < nt; ++t) {
    if (!keep[t]) continue;
    const int32_t *tet = soup->tets + 4 * (size_t)t;
    volume[piola__union_find_root(parent, t)] += piola__tet_volume(
        vec3_load(soup->positions + 3 * (size_t)tet[0]), vec3_load(soup->positions + 3 * (size_t)tet[1]),
        vec3_load(soup->positions + 3 * (size_t)tet[2]), vec3_load(soup->positions + 3 * (size_t)tet[3]));
  }
  double largest = 0;
  for (int32_t t = 0; t < nt; ++t) largest = fmax(largest, volume[t]);
  int64_t dropped = 0;
  for (int32_t t = 0; t < nt; ++t) {
    if (!keep[t]) continue;
    double v = volume[piola__union_find_root(parent, t)];
    /* Never drop the largest piece, so a small shape still gets a mesh. */
    if (v < min_volume && v < largest) {
      keep[t] = 0;
      dropped++;
    }
  }
  free(parent);
  free(volume);
  return dropped;
}

static piola_status extract(const piola__tet_soup *soup, const uint8_t *keep, piola_tet_mesh *out) {
  int32_t *map = malloc((size_t)soup->vertex_count * sizeof(int32_t));
  if (!map) return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "mesher: output");
  for (int32_t v = 0; v < soup->vertex_count; ++v) map[v] = -1;
  int32_t nt = 0, nv = 0;
  for (int32_t t = 0; t < soup->tet_count; ++t) {
    if (!keep[t]) continue;
    nt++;
    for (int k = 0; k < 4; ++k) {
      int32_t v = soup->tets[4 * t + k];
      if (map[v] < 0) map[v] = nv++;
    }
  }
  if (nt == 0) {
    free(map);
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "mesher: no tetrahedra inside the shape; cell_size must be smaller than "
                      "the shape");
  }
  out->positions = malloc((size_t)nv * 3 * sizeof(double));
  out->tets = malloc((size_t)nt * 4 * sizeof(int32_t));
  if (!out->positions || !out->tets) {
    free(map);
    free(out->positions);
    free(out->tets);
    memset(out, 0, sizeof(*out));
    return PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "mesher: output of %d tets", (int)nt);
  }
  for (int32_t v = 0; v < soup->vertex_count; ++v)
    if (map[v] >= 0) memcpy(out->positions + 3 * (size_t)map[v], soup->positions + 3 * (size_t)v, 3 * sizeof(double));
  int32_t t2 = 0;
  for (int32_t t = 0; t < soup->tet_count; ++t) {
    if (!keep[t]) continue;
    for (int k = 0; k < 4; ++k) out->tets[4 * (size_t)t2 + k] = map[soup->tets[4 * t + k]];
    t2++;
  }
  out->vertex_count = nv;
  out->tet_count = nt;
  out->tet_regions = NULL;
  free(map);
  return PIOLA_OK;
}

piola_status piola_mesher_generate(const piola_mesher_def *def, piola_tet_mesh *out) {
  if (!def || !out) return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "mesher: NULL argument");
  memset(out, 0, sizeof(*out));
  double h = def->cell_size;
  if (!(h > 0) || !isfinite(h))
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT, "mesher: cell_size must be > 0 m, got %g", h);
  if (def->refinement_levels < 0 || def->refinement_levels > MAX_REFINEMENT_LEVELS)
    return PIOLA_FAIL(PIOLA_ERROR_INVALID_ARGUMENT,
                      "mesher: refinement_levels must be in [0, %d], got %d",
                      MAX_REFINEMENT_LEVELS, def->refinement_levels);
  piola__shape_union shapes;
  PIOLA_TRY(piola__shape_union_create(def, &shapes));
  vec3 lo, hi;
  piola__shape_union_bounds(&shapes, &lo, &hi);
  /* Two cells of margin so every tet crossing the surface is in the lattice. */
  lo = vec3_sub(lo, vec3_make(2 * h, 2 * h, 2 * h));
  hi = vec3_add(hi, vec3_make(2 * h, 2 * h, 2 * h));
  piola__bcc_lattice lattice;
  piola_status status = piola__bcc_lattice_build(lo, hi, h, MAX_LATTICE_TETS, &lattice);
  if (status != PIOLA_OK) {
    piola__shape_union_destroy(&shapes);
    return status;
  }
  piola__tet_soup soup = {0};
  soup.vertex_count = soup.vertex_capacity = lattice.vertex_count;
  soup.positions = lattice.positions;
  soup.tet_count = soup.tet_capacity = lattice.tet_count;
  soup.tets = lattice.tets;
  soup.phi = malloc((size_t)soup.vertex_count * sizeof(double));
  uint8_t *keep = NULL;
  lattice_topology topo = {0};
  if (!soup.phi) {
    status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "mesher: level set values");
    goto done;
  }
  /* The band must exceed the longest lattice edge (h) for the far-field sign rule. */
  status = piola__lattice_phi(&shapes, soup.positions, soup.vertex_count, soup.tets,
                              soup.tet_count, 1.5 * h, soup.phi);
  if (status != PIOLA_OK) goto done;
  if (def->refinement_levels > 0) {
    status = piola__red_green_refine(&soup, &shapes, def->refinement_levels, h);
    if (status != PIOLA_OK) goto done;
  }
  /* Keep a tet when the mean of phi at its nodes is negative: a first-order estimate of phi
   * at its centroid, so the kept set approximates the shape's volume from both sides. */
  keep = malloc((size_t)soup.tet_count + 1);
  if (!keep) {
    status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "mesher: tet selection");
    goto done;
  }
  for (int32_t t = 0; t < soup.tet_count; ++t) {
    const int32_t *tet = soup.tets + 4 * (size_t)t;
    double mean = soup.phi[tet[0]] + soup.phi[tet[1]] + soup.phi[tet[2]] + soup.phi[tet[3]];
    keep[t] = mean < 0;
  }
  status = piola__vertex_tets(soup.vertex_count, soup.tets, soup.tet_count, NULL, &topo.vertex_tets);
  if (status != PIOLA_OK) goto done;
  topo.neighbor = malloc((size_t)soup.tet_count * 4 * sizeof(int32_t) + 1);
  if (!topo.neighbor) {
    status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "mesher: lattice adjacency");
    goto done;
  }
  piola__face_neighbors(soup.tets, soup.tet_count, NULL, &topo.vertex_tets, topo.neighbor);
  status = repair_manifold(&soup, &topo, keep);
  for (int round = 0; round < PRUNE_ROUNDS && status == PIOLA_OK; ++round) {
    int64_t dropped = drop_boundary_only_tets(&soup, &topo, keep);
    if (dropped < 0) status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "mesher: pruning");
    if (dropped <= 0) break;
    status = repair_manifold(&soup, &topo, keep);
  }
  if (status != PIOLA_OK) goto done;
  double h_fine = h / (double)(1 << def->refinement_levels);
  if (drop_crumbs(&soup, &topo, keep, CRUMB_CELLS * h_fine * h_fine * h_fine) < 0) {
    status = PIOLA_FAIL(PIOLA_ERROR_OUT_OF_MEMORY, "mesher: connected pieces");
    goto done;
  }
  status = extract(&soup, keep, out);
  if (status != PIOLA_OK) goto done;
  status = piola__boundary_snap(out, &shapes, h_fine);
  if (status != PIOLA_OK) {
    free(out->positions);
    free(out->tets);
    memset(out, 0, sizeof(*out));
  }
done:
  piola__csr_free(&topo.vertex_tets);
  free(topo.neighbor);
  free(keep);
  piola__tet_soup_free(&soup);
  piola__shape_union_destroy(&shapes);
  return status;
}
