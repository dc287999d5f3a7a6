/* A collision surface's history as bytes (surface_history.h). */
#include "contact/surface_history.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "contact/contact_internal.h"

enum { MAX_TREE_DEPTH = 64 };

/* The three trees and their primitive counts, in the order of the bytes. */
static int trees(piola_collision_surface *s, piola__bvh *tree[3], int32_t count[3]) {
  tree[0] = &s->triangle_tree, tree[1] = &s->edge_tree, tree[2] = &s->vertex_tree;
  count[0] = s->triangle_count, count[1] = s->edge_count, count[2] = s->vertex_count;
  return 3;
}

static size_t tree_bytes(int32_t node_count, int32_t primitives) {
  return 4 + 8 * (size_t)node_count + 4 * (size_t)primitives;
}

size_t piola__collision_surface_history_size(const piola_collision_surface *surface) {
  piola__bvh *tree[3];
  int32_t count[3];
  size_t n = 4;
  for (int k = 0, m = trees((piola_collision_surface *)surface, tree, count); k < m; ++k)
    n += tree_bytes(tree[k]->node_count, tree[k]->node_count ? count[k] : 0);
  return n;
}

static unsigned char *put_i32(unsigned char *p, int32_t v) {
  memcpy(p, &v, 4);
  return p + 4;
}

static int32_t get_i32(const unsigned char *p) {
  int32_t v;
  memcpy(&v, p, 4);
  return v;
}

void piola__collision_surface_history_save(const piola_collision_surface *surface,
                                           unsigned char *out) {
  piola__bvh *tree[3];
  int32_t count[3];
  out = put_i32(out, surface->tree_age);
  for (int k = 0, m = trees((piola_collision_surface *)surface, tree, count); k < m; ++k) {
    const piola__bvh *t = tree[k];
    out = put_i32(out, t->node_count);
    for (int32_t i = 0; i < t->node_count; ++i)
      out = put_i32(put_i32(out, t->nodes[i].first), t->nodes[i].count);
    for (int32_t i = 0; t->node_count && i < count[k]; ++i) out = put_i32(out, t->order[i]);
  }
}

/* Checks one tree's bytes at p (nodes of node_count, then primitives entries): returns 0 when
 * they make a tree over [0, primitives), -1 otherwise. parents is scratch of node_count. */
static int check_tree(const unsigned char *p, int32_t node_count, int32_t primitives,
                      uint8_t *parents, uint8_t *depth) {
  if (node_count == 0) return 0;
  memset(parents, 0, (size_t)node_count);
  depth[0] = 0;
  for (int32_t i = 0; i < node_count; ++i) {
    const int32_t first = get_i32(p + 8 * (size_t)i), count = get_i32(p + 8 * (size_t)i + 4);
    if (i > 0 && parents[i] != 1) return -1; /* every node below the root is reached once */
    if (count > 0) {
      if (first < 0 || first > primitives - count) return -1;
      continue;
    }
    /* inner: children i + 1 and first, both later in preorder, so walks end */
    if (count < 0 || first <= i + 1 || first >= node_count || depth[i] >= MAX_TREE_DEPTH)
      return -1;
    parents[i + 1]++, parents[first]++;
    depth[i + 1] = depth[first] = (uint8_t)(depth[i] + 1);
  }
  const unsigned char *order = p + 8 * (size_t)node_count;
  for (int32_t i = 0; i < primitives; ++i) {
    const int32_t id = get_i32(order + 4 * (size_t)i);
    if (id < 0 || id >= primitives) return -1;
  }
  return 0;
}

int piola__collision_surface_history_load(piola_collision_surface *surface,
                                          const unsigned char *bytes, size_t n, int store) {
  piola__bvh *tree[3];
  int32_t count[3];
  const int m = trees(surface, tree, count);
  if (n < 4 || get_i32(bytes) < 0) return -1;
  const int32_t age = get_i32(bytes);
  /* the node count of each tree, and where its nodes start */
  int32_t nodes[3];
  size_t at[3], pos = 4;
  int32_t most = 1;
  for (int k = 0; k < m; ++k) {
    if (n - pos < 4) return -1;
    nodes[k] = get_i32(bytes + pos);
    const int32_t limit = 2 * (count[k] > 0 ? count[k] : 1);
    if (nodes[k] < 0 || nodes[k] >= limit || (age > 0 && count[k] > 0 && nodes[k] == 0))
      return -1;
    at[k] = pos + 4;
    const size_t length = tree_bytes(nodes[k], nodes[k] ? count[k] : 0);
    if (n - pos < length) return -1;
    pos += length;
    most = nodes[k] > most ? nodes[k] : most;
  }
  if (pos != n) return -1;
  uint8_t *scratch = malloc(2 * (size_t)most);
  if (!scratch) return -2;
  int bad = 0;
  for (int k = 0; k < m && !bad; ++k)
    bad = check_tree(bytes + at[k], nodes[k], count[k], scratch, scratch + most) != 0;
  free(scratch);
  if (bad) return -1;
  if (!store) return 0;
  surface->tree_age = 0; /* until every tree is in place: a failure leaves a rebuild due */
  for (int k = 0; k < m; ++k)
    if (piola__bvh_reserve(tree[k], count[k])) return -2;
  for (int k = 0; k < m; ++k) {
    piola__bvh *t = tree[k];
    const unsigned char *p = bytes + at[k];
    t->node_count = nodes[k];
    for (int32_t i = 0; i < nodes[k]; ++i) {
      t->nodes[i].first = get_i32(p + 8 * (size_t)i);
      t->nodes[i].count = get_i32(p + 8 * (size_t)i + 4);
    }
    for (int32_t i = 0; nodes[k] && i < count[k]; ++i)
      t->order[i] = get_i32(p + 8 * (size_t)nodes[k] + 4 * (size_t)i);
  }
  surface->tree_age = age;
  return 0;
}
