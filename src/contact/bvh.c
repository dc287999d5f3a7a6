/* Bounding-volume hierarchy: top-down median build, refit, overlap queries. */
#include "contact/bvh.h"

#include <stdlib.h>

#include "common/grow.h"
#include "piola/threads.h"

enum { LEAF_SIZE = 4, MAX_DEPTH = 128 };

static void box_union(piola__box *a, const piola__box *b) {
  for (int k = 0; k < 3; ++k) {
    a->lo[k] = b->lo[k] < a->lo[k] ? b->lo[k] : a->lo[k];
    a->hi[k] = b->hi[k] > a->hi[k] ? b->hi[k] : a->hi[k];
  }
}

static double centre(const piola__box *b, int axis) { return b->lo[axis] + b->hi[axis]; }

/* Puts the k-th smallest (by centre along axis, ties by index) at order[k]; deterministic. */
static void select_kth(int32_t *order, int32_t lo, int32_t hi, int32_t k, const piola__box *boxes,
                       int axis) {
  while (hi - lo > 1) {
    int32_t mid = lo + (hi - lo) / 2;
    /* Median of three as pivot. */
    int32_t cand[3] = {order[lo], order[mid], order[hi - 1]};
    double c[3] = {centre(&boxes[cand[0]], axis), centre(&boxes[cand[1]], axis),
                   centre(&boxes[cand[2]], axis)};
    int pick = (c[0] < c[1]) == (c[1] < c[2]) ? 1 : ((c[1] < c[0]) == (c[0] < c[2]) ? 0 : 2);
    double pivot = c[pick];
    int32_t pivot_id = cand[pick];
    /* Three-way partition: less, equal key, greater. */
    int32_t i = lo, lt = lo, gt = hi;
    while (i < gt) {
      int32_t id = order[i];
      double ci = centre(&boxes[id], axis);
      int less = ci < pivot || (ci == pivot && id < pivot_id);
      int greater = ci > pivot || (ci == pivot && id > pivot_id);
      if (less) {
        int32_t t = order[lt];
        order[lt++] = id, order[i++] = t;
      } else if (greater) {
        int32_t t = order[--gt];
        order[gt] = id, order[i] = t;
      } else {
        ++i;
      }
    }
    if (k < lt)
      hi = lt;
    else if (k >= gt)
      lo = gt;
    else
      return;
  }
}

/* Builds the subtree over order[begin, end) at the next free node; nodes come out in preorder
 * (a node, its left subtree, its right subtree). Median splits keep the depth near log2(n). */
static int32_t build_node(piola__bvh *bvh, const piola__box *boxes, int32_t begin, int32_t end) {
  int32_t index = bvh->node_count++;
  piola__bvh_node *node = &bvh->nodes[index];
  piola__box cb = {{1e300, 1e300, 1e300}, {-1e300, -1e300, -1e300}};
  node->box = boxes[bvh->order[begin]];
  for (int32_t i = begin; i < end; ++i) {
    const piola__box *b = &boxes[bvh->order[i]];
    box_union(&node->box, b);
    for (int k = 0; k < 3; ++k) {
      double c = centre(b, k);
      cb.lo[k] = c < cb.lo[k] ? c : cb.lo[k];
      cb.hi[k] = c > cb.hi[k] ? c : cb.hi[k];
    }
  }
  int32_t count = end - begin;
  if (count <= LEAF_SIZE) {
    node->first = begin, node->count = count;
    return index;
  }
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (cb.hi[k] - cb.lo[k] > cb.hi[axis] - cb.lo[axis]) axis = k;
  int32_t mid = begin + count / 2;
  select_kth(bvh->order, begin, end, mid, boxes, axis);
  node->count = 0;
  build_node(bvh, boxes, begin, mid);
  int32_t right = build_node(bvh, boxes, mid, end);
  node->first = right;
  return index;
}

int piola__bvh_reserve(piola__bvh *bvh, int32_t n) {
  if (n > bvh->primitive_count || !bvh->nodes) {
    piola__bvh_node *nodes = realloc(bvh->nodes, sizeof(*nodes) * (size_t)(2 * (n > 0 ? n : 1)));
    if (!nodes) return -1;
    bvh->nodes = nodes;
    int32_t *order = realloc(bvh->order, sizeof(*order) * (size_t)(n > 0 ? n : 1));
    if (!order) return -1;
    bvh->order = order;
    piola__box *leaf_boxes =
        realloc(bvh->leaf_boxes, sizeof(*leaf_boxes) * (size_t)(n > 0 ? n : 1));
    if (!leaf_boxes) return -1;
    bvh->leaf_boxes = leaf_boxes;
  }
  bvh->primitive_count = n;
  bvh->node_count = 0;
  return 0;
}

int piola__bvh_build(piola__bvh *bvh, const piola__box *boxes, int32_t n) {
  if (piola__bvh_reserve(bvh, n)) return -1;
  if (n == 0) return 0;
  for (int32_t i = 0; i < n; ++i) bvh->order[i] = i;
  build_node(bvh, boxes, 0, n);
  for (int32_t i = 0; i < n; ++i) bvh->leaf_boxes[i] = boxes[bvh->order[i]];
  return 0;
}

void piola__bvh_refit(piola__bvh *bvh, const piola__box *boxes) {
  const int32_t count = bvh->node_count;
  piola__bvh_node *nodes = bvh->nodes;
#pragma omp parallel for schedule(static) num_threads(piola_thread_count()) if (count >= 4096)
  for (int32_t i = 0; i < count; ++i) {
    if (nodes[i].count == 0) continue;
    piola__box *leaf = bvh->leaf_boxes + nodes[i].first;
    leaf[0] = boxes[bvh->order[nodes[i].first]];
    piola__box b = leaf[0];
    for (int32_t j = 1; j < nodes[i].count; ++j) {
      leaf[j] = boxes[bvh->order[nodes[i].first + j]];
      box_union(&b, &leaf[j]);
    }
    nodes[i].box = b;
  }
  for (int32_t i = count - 1; i >= 0; --i) {
    if (nodes[i].count != 0) continue;
    piola__box b = nodes[i + 1].box;
    box_union(&b, &nodes[nodes[i].first].box);
    nodes[i].box = b;
  }
}

int piola__index_list_push(piola__index_list *list, int32_t value) {
  if ((size_t)list->count == list->capacity &&
      piola__grow((void **)&list->items, &list->capacity, (size_t)list->count + 1,
                  sizeof *list->items))
    return -1;
  list->items[list->count++] = value;
  return 0;
}

int piola__bvh_query(const piola__bvh *bvh, const piola__box *query, piola__index_list *out) {
  if (bvh->node_count == 0) return 0;
  int32_t stack[MAX_DEPTH];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const piola__bvh_node *node = &bvh->nodes[stack[--top]];
    if (!piola__boxes_overlap(&node->box, query)) continue;
    if (node->count > 0) {
      for (int32_t j = 0; j < node->count; ++j) {
        int32_t id = bvh->order[node->first + j];
        if (piola__boxes_overlap(&bvh->leaf_boxes[node->first + j], query) &&
            piola__index_list_push(out, id))
          return -1;
      }
    } else {
      int32_t self = (int32_t)(node - bvh->nodes);
      stack[top++] = node->first;
      stack[top++] = self + 1;
    }
  }
  return 0;
}

void piola__bvh_free(piola__bvh *bvh) {
  free(bvh->nodes);
  free(bvh->order);
  free(bvh->leaf_boxes);
  *bvh = (piola__bvh){0};
}
