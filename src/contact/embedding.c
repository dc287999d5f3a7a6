/* Embedded collision surfaces (piola_collision_surface_def.embed_nodes): vertices that are
 * fixed combinations of moving nodes, such as the crack faces of a cut solid, whose
 * points lie inside the cut tets' copies (docs/contact.md, "Embedded vertices").
 *
 * Detection works on the vertices as on any surface: a vertex moves on a straight line
 * over the step, since its nodes do and its weights are fixed. Impulses act on the nodes:
 * a pair's relative position sum_k w_k x_k is sum_j c_j y_j over its nodes y_j (c_j the
 * sum of w_k times vertex k's weight e_kj of node j). Vertex k's share w_k J of an impulse
 * J is split among its nodes as its mass is made of theirs: with M_k = sum_j e_kj m_j (its
 * unpinned nodes), node j's velocity changes by w_k e_kj J / M_k. Splitting by the inverse
 * masses instead (c_j J / m_j) would fling a light node: a crack point next to a real
 * node of a copy with little material weighs on a virtual node of tiny mass, and an
 * impact there swung that copy's crack face through its fragment's own boundary. This
 * keeps linear momentum (each vertex's nodes take exactly w_k J), is the plain formula
 * for a vertex of one node (and for nodes of equal mass), and changes the relative
 * velocity by J sum_j c_j g_j c_j, g_j the node's effective inverse mass below. Every
 * vertex of a node whose velocity changed is brought up to date before the next pair, so
 * Gauss-Seidel sees what the nodes do. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "contact/contact_internal.h"

enum { E = PIOLA_COLLISION_EMBED_NODES };

void piola__embedding_free(piola_collision_surface *s) {
  free(s->embed_nodes), free(s->embed_weights), free(s->node_vertex_start), free(s->node_vertices);
  free(s->vertex_x0), free(s->vertex_v), free(s->node_inverse_mass), free(s->node_zone_parent);
  free(s->node_zone_order), free(s->node_in_zone), free(s->node_dirty);
  free(s->vertex_inverse_node_mass);
}

int piola__embedding_create(piola_collision_surface *s, const piola_collision_surface_def *def,
                            const char **message) {
  const int32_t nv = s->vertex_count, nn = def->node_count;
  if (nn < 1 || !def->embed_nodes || !def->embed_weights) {
    *message = "an embedding needs node_count >= 1, embed_nodes and embed_weights";
    return -2;
  }
  for (int32_t i = 0; i < nv; ++i) {
    double sum = 0;
    int used = 0;
    for (int j = 0; j < E; ++j) {
      const int32_t node = def->embed_nodes[E * i + j];
      const double w = def->embed_weights[E * i + j];
      if (node < -1 || node >= nn || !(w >= 0 && w <= 1) || (node < 0) != (w == 0)) {
        *message = "an embedded vertex has a node outside [0, node_count) or a weight outside "
                   "[0, 1] (an unused slot has node -1 and weight 0)";
        return -2;
      }
      sum += w, used += node >= 0;
    }
    if (!used || fabs(sum - 1) > 1e-9) {
      *message = "the weights of an embedded vertex must sum to 1";
      return -2;
    }
  }
  s->node_count = nn;
  const size_t nn1 = (size_t)nn, nv1 = (size_t)(nv > 0 ? nv : 1);
  s->embed_nodes = malloc(sizeof(int32_t) * E * nv1);
  s->embed_weights = malloc(sizeof(double) * E * nv1);
  s->node_vertex_start = calloc(nn1 + 1, sizeof(int32_t));
  s->node_vertices = malloc(sizeof(int32_t) * E * nv1);
  s->vertex_x0 = malloc(sizeof(double) * 3 * nv1);
  s->vertex_v = malloc(sizeof(double) * 3 * nv1);
  s->node_inverse_mass = malloc(sizeof(double) * nn1);
  s->node_zone_parent = malloc(sizeof(int32_t) * nn1);
  s->node_zone_order = malloc(sizeof(int32_t) * nn1);
  s->node_in_zone = malloc(nn1);
  s->node_dirty = calloc(nn1, 1);
  s->vertex_inverse_node_mass = malloc(sizeof(double) * nv1);
  if (!s->vertex_inverse_node_mass || !s->embed_nodes || !s->embed_weights || !s->node_vertex_start || !s->node_vertices ||
      !s->vertex_x0 || !s->vertex_v || !s->node_inverse_mass || !s->node_zone_parent ||
      !s->node_zone_order || !s->node_in_zone || !s->node_dirty)
    return -1;
  memcpy(s->embed_nodes, def->embed_nodes, sizeof(int32_t) * E * (size_t)nv);
  memcpy(s->embed_weights, def->embed_weights, sizeof(double) * E * (size_t)nv);
  for (int32_t i = 0; i < E * nv; ++i)
    if (s->embed_nodes[i] >= 0) s->node_vertex_start[s->embed_nodes[i] + 1]++;
  for (int32_t n = 0; n < nn; ++n) s->node_vertex_start[n + 1] += s->node_vertex_start[n];
  int32_t *fill = malloc(sizeof(int32_t) * nn1);
  if (!fill) return -1;
  memcpy(fill, s->node_vertex_start, sizeof(int32_t) * nn1);
  for (int32_t i = 0; i < E * nv; ++i)
    if (s->embed_nodes[i] >= 0) s->node_vertices[fill[s->embed_nodes[i]]++] = i / E;
  free(fill);
  return 0;
}

static void vertex_from_nodes(const piola_collision_surface *s, int32_t i, const double *node,
                              double *out) {
  out[0] = out[1] = out[2] = 0;
  for (int j = 0; j < E; ++j) {
    const int32_t m = s->embed_nodes[E * i + j];
    if (m < 0) continue;
    const double w = s->embed_weights[E * i + j];
    for (int k = 0; k < 3; ++k) out[k] += w * node[3 * (size_t)m + k];
  }
}

void piola__embedding_gather(piola_collision_surface *s, const double *node_x0, double *node_v,
                             const double *node_mass) {
  s->node_x0 = node_x0, s->node_v = node_v;
  for (int32_t i = 0; i < s->vertex_count; ++i) {
    vertex_from_nodes(s, i, node_x0, s->vertex_x0 + 3 * (size_t)i);
    vertex_from_nodes(s, i, node_v, s->vertex_v + 3 * (size_t)i);
    double mass = 0, w2 = 0;
    for (int j = 0; j < E; ++j) {
      const int32_t m = s->embed_nodes[E * i + j];
      const double w = s->embed_weights[E * i + j];
      if (m < 0 || s->node_inverse_mass[m] == 0.0) continue; /* pinned nodes take nothing */
      mass += w * node_mass[m], w2 += w * w;
    }
    s->vertex_inverse_node_mass[i] = mass > 0 ? 1.0 / mass : 0.0;
    s->inverse_mass[i] = w2 * s->vertex_inverse_node_mass[i];
  }
}

int piola__pair_nodes(const piola_collision_surface *s, const int32_t v[4], const double w[4],
                      int32_t node[16], double weight[16], double inverse_mass[16]) {
  int n = 0;
  double share[16];
  int from[16];
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < E; ++j) {
      const int32_t m = s->embed_nodes[E * v[k] + j];
      if (m < 0) continue;
      const double c = w[k] * s->embed_weights[E * v[k] + j];
      const double g = s->node_inverse_mass[m] == 0.0 ? 0.0 : s->vertex_inverse_node_mass[v[k]];
      int at = 0;
      while (at < n && node[at] != m) ++at;
      if (at == n) node[n] = m, weight[n] = c, share[n] = c * g, inverse_mass[n] = g, from[n++] = 1;
      else weight[at] += c, share[at] += c * g, from[at]++;
    }
  /* a node of several vertices: the mean of their inverse masses, weighted by its weights
   * in them (all of one sign, since the two sides of a pair share no node) */
  for (int j = 0; j < n; ++j)
    if (from[j] > 1) inverse_mass[j] = weight[j] != 0.0 ? share[j] / weight[j] : 0.0;
  return n;
}

int piola__pair_shares_node(const piola_collision_surface *s, const int32_t v[4], int edge_edge) {
  /* one side against the other (the vertices of one triangle or edge may share nodes) */
  const int first_b = edge_edge ? 2 : 1;
  for (int a = 0; a < first_b; ++a)
    for (int b = first_b; b < 4; ++b)
      for (int i = 0; i < E; ++i) {
        const int32_t m = s->embed_nodes[E * v[a] + i];
        if (m < 0) continue;
        for (int j = 0; j < E; ++j)
          if (s->embed_nodes[E * v[b] + j] == m) return 1;
      }
  return 0;
}

void piola__embedding_apply(piola_collision_surface *s, int n, const int32_t node[16],
                            const double weight[16], const double inverse_mass[16], vec3 impulse) {
  for (int j = 0; j < n; ++j) {
    const double f = weight[j] * inverse_mass[j];
    if (f == 0.0) continue;
    double *vn = s->node_v + 3 * (size_t)node[j];
    vn[0] += f * impulse.x, vn[1] += f * impulse.y, vn[2] += f * impulse.z;
  }
  for (int j = 0; j < n; ++j) {
    if (weight[j] * inverse_mass[j] == 0.0) continue;
    for (int32_t q = s->node_vertex_start[node[j]]; q < s->node_vertex_start[node[j] + 1]; ++q) {
      const int32_t vertex = s->node_vertices[q];
      vertex_from_nodes(s, vertex, s->node_v, s->vertex_v + 3 * (size_t)vertex);
      s->dirty[vertex] = 1;
    }
  }
}
