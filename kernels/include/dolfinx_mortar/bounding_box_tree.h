// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace dolfinx_mortar
{

/// Axis-aligned bounding-box tree over a set of boxes (3D; 2D boxes use z=0).
///
/// DOLFINx has a BoundingBoxTree, but the kernels take plain arrays and never
/// include DOLFINx headers (docs/DESIGN.md, §Layers), and the boxes here are
/// of moving, enlarged surface facets rather than mesh entities; so the tree
/// is our own.
/// Built by median splits along the longest axis: O(n log n) to build,
/// O(log n + k) per query with k hits.
class BoundingBoxTree
{
public:
  /// @param[in] boxes Row-major (n, 6): xmin, ymin, zmin, xmax, ymax, zmax
  explicit BoundingBoxTree(std::span<const double> boxes);

  /// Indices of the boxes that overlap @p box (6 values), appended to @p hits.
  void overlapping(std::span<const double, 6> box,
                   std::vector<std::int32_t>& hits) const;

  /// Number of boxes.
  std::size_t size() const { return _num_boxes; }

private:
  struct Node
  {
    std::array<double, 6> box;
    std::int32_t left, right; // children, or -1 and the leaf's box index
  };
  std::int32_t build(std::vector<std::int32_t>& order,
                     std::size_t begin,
                     std::size_t end,
                     std::span<const double> boxes);
  std::vector<Node> _nodes;
  std::size_t _num_boxes;
};

/// All pairs (i, j) whose boxes overlap, i from @p a and j from @p b, sorted
/// by i then j. Row-major (pairs, 2).
std::vector<std::int32_t>
overlapping_box_pairs(std::span<const double> a, std::span<const double> b);

} // namespace dolfinx_mortar
