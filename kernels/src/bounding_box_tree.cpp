// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#include <dolfinx_mortar/bounding_box_tree.h>

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace dolfinx_mortar
{
namespace
{
bool
overlap(std::span<const double, 6> a, std::span<const double, 6> b)
{
  for (int k = 0; k < 3; ++k)
    if (a[k] > b[k + 3] or b[k] > a[k + 3])
      return false;
  return true;
}
} // namespace

BoundingBoxTree::BoundingBoxTree(std::span<const double> boxes)
  : _num_boxes(boxes.size() / 6)
{
  if (boxes.size() % 6 != 0)
    throw std::invalid_argument("boxes must have shape (n, 6)");
  if (_num_boxes == 0)
    return;
  _nodes.reserve(2 * _num_boxes);
  std::vector<std::int32_t> order(_num_boxes);
  std::iota(order.begin(), order.end(), 0);
  build(order, 0, _num_boxes, boxes);
}

std::int32_t
BoundingBoxTree::build(std::vector<std::int32_t>& order,
                       std::size_t begin,
                       std::size_t end,
                       std::span<const double> boxes)
{
  Node node;
  node.box = { 1e300, 1e300, 1e300, -1e300, -1e300, -1e300 };
  for (std::size_t i = begin; i < end; ++i)
    for (int k = 0; k < 3; ++k)
    {
      node.box[k] = std::min(node.box[k], boxes[6 * order[i] + k]);
      node.box[k + 3] = std::max(node.box[k + 3], boxes[6 * order[i] + k + 3]);
    }
  const auto index = static_cast<std::int32_t>(_nodes.size());
  _nodes.push_back(node);
  if (end - begin == 1)
  {
    _nodes[index].left = -1;
    _nodes[index].right = order[begin];
    return index;
  }
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (node.box[k + 3] - node.box[k] > node.box[axis + 3] - node.box[axis])
      axis = k;
  const std::size_t mid = begin + (end - begin) / 2;
  auto centre = [&](std::int32_t i)
  { return boxes[6 * i + axis] + boxes[6 * i + axis + 3]; };
  std::nth_element(order.begin() + begin,
                   order.begin() + mid,
                   order.begin() + end,
                   [&](std::int32_t i, std::int32_t j)
                   { return centre(i) < centre(j); });
  const std::int32_t left = build(order, begin, mid, boxes);
  const std::int32_t right = build(order, mid, end, boxes);
  _nodes[index].left = left;
  _nodes[index].right = right;
  return index;
}

void
BoundingBoxTree::overlapping(std::span<const double, 6> box,
                             std::vector<std::int32_t>& hits) const
{
  if (_nodes.empty())
    return;
  std::vector<std::int32_t> stack = { 0 };
  while (!stack.empty())
  {
    const Node& node = _nodes[stack.back()];
    stack.pop_back();
    if (!overlap(box, node.box))
      continue;
    if (node.left < 0)
      hits.push_back(node.right);
    else
    {
      stack.push_back(node.left);
      stack.push_back(node.right);
    }
  }
}

std::vector<std::int32_t>
overlapping_box_pairs(std::span<const double> a, std::span<const double> b)
{
  if (a.size() % 6 != 0)
    throw std::invalid_argument("boxes must have shape (n, 6)");
  BoundingBoxTree tree(b);
  std::vector<std::int32_t> pairs, hits;
  for (std::size_t i = 0; i < a.size() / 6; ++i)
  {
    hits.clear();
    tree.overlapping(std::span<const double, 6>(a.data() + 6 * i, 6), hits);
    std::sort(hits.begin(), hits.end());
    for (std::int32_t j : hits)
    {
      pairs.push_back(static_cast<std::int32_t>(i));
      pairs.push_back(j);
    }
  }
  return pairs;
}

} // namespace dolfinx_mortar
