// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

// The overlap of a slave and a master piece in the slave piece's plane: an
// interval in 2D, a clipped polygon fanned into triangles in 3D.

#include "clipping.h"
#include "pair_segmentation.h"

#include <algorithm>
#include <array>
#include <vector>

namespace dolfinx_mortar
{

/// Whether the bounding boxes of two plane polygons are more than @p margin
/// apart along an axis (on the values).
template<typename Point>
bool
boxes_apart(const std::vector<Point>& a,
            const std::vector<Point>& b,
            double margin)
{
  for (int k = 0; k < 2; ++k)
  {
    double lo_a = value(a[0][k]), hi_a = lo_a, lo_b = value(b[0][k]),
           hi_b = lo_b;
    for (const Point& p : a)
      lo_a = std::min(lo_a, value(p[k])), hi_a = std::max(hi_a, value(p[k]));
    for (const Point& p : b)
      lo_b = std::min(lo_b, value(p[k])), hi_b = std::max(hi_b, value(p[k]));
    if (lo_b > hi_a + margin or lo_a > hi_b + margin)
      return true;
  }
  return false;
}

/// An integration cell of the overlap of two pieces, in plane coordinates:
/// origin, edge a, edge b (none in 2D) and measure factor, with its
/// vertices' indices in Overlap::vertices (2D: no third vertex).
template<Scalar G>
struct OverlapCell
{
  std::array<G, 2> origin, a, b;
  G measure;
  std::array<int, 3> vertex;
};

/// The overlap of a slave and a master piece projected on the slave piece's
/// plane, fanned into integration cells (none: they do not overlap by more
/// than the zero length).
template<Scalar G>
struct Overlap
{
  std::vector<OverlapCell<G>> cells;
  std::vector<std::array<G, 2>> vertices;
};

/// The overlap of two polygons in the slave piece's plane coordinates: an
/// interval in 2D, a clipped convex polygon fanned from its centroid in 3D.
/// @param[in] master_polygon Taken by value: it may be turned around
/// @param[in] zero The zero length of the geometric decisions
/// @param[in] keep_slivers Keep an overlap of any positive width, not only
/// one wider than @p zero (the current configuration: a sliver's integral is
/// round-off, but its derivative is the integrand at its ends, as large as a
/// whole segment's; dropped, the gradient jumped by that much where a node
/// of one side came within @p zero of a node of the other)
template<Scalar G>
Overlap<G>
overlap_of(int gdim,
           const std::vector<std::array<G, 2>>& slave_polygon,
           std::vector<std::array<G, 2>> master_polygon,
           double zero,
           bool keep_slivers = false)
{
  using P2 = std::array<G, 2>;
  Overlap<G> out;
  if (gdim == 2)
  {
    const G lo = larger(slave_polygon[0][0],
                        smaller(master_polygon[0][0], master_polygon[1][0]));
    const G hi = smaller(slave_polygon[1][0],
                         larger(master_polygon[0][0], master_polygon[1][0]));
    const G length = hi - lo;
    if (value(length) > (keep_slivers ? 0.0 : zero))
    {
      out.vertices = { { lo, 0.0 }, { hi, 0.0 } };
      out.cells.push_back(
        { { lo, 0.0 }, { length, 0.0 }, { 0.0, 0.0 }, length, { 0, 1, 0 } });
    }
    return out;
  }
  // The slave polygon is counter-clockwise about its own normal by
  // construction; the master one is usually clockwise (it faces the slave)
  // and must be turned for clipping. It is not degenerate, so the sign of
  // its area is not round-off. Boxes more than twice the zero length apart
  // cannot overlap by more than the clipping's tolerance: the rejection the
  // clipping would reach, at a fraction of its cost (most candidates end
  // here). Keeping slivers, every decision is exact: with the tolerance, a
  // vertex within the zero length outside a clip edge is kept as on it, and
  // the overlap then follows that vertex instead of the crossing point, so
  // its derivative jumped where a vertex entered the band.
  const double tolerance = keep_slivers ? 0.0 : zero;
  if (boxes_apart(slave_polygon, master_polygon, 2 * tolerance))
    return out;
  if (value(signed_area(master_polygon)) < 0)
    std::reverse(master_polygon.begin(), master_polygon.end());
  const auto clipped = clip_polygon(slave_polygon, master_polygon, tolerance);
  // an overlap no wider than the zero length is a segment or a point
  // (touching edges, a shared vertex)
  if (clipped.size() < 3 or
      !(2 * value(signed_area(clipped)) >
        (keep_slivers ? 0.0 : zero * longest_edge(clipped))))
    return out;
  const double m = static_cast<double>(clipped.size());
  P2 g = { 0.0, 0.0 };
  for (const P2& q : clipped)
    g = { g[0] + q[0] / m, g[1] + q[1] / m };
  out.vertices = clipped;
  out.vertices.push_back(g);
  const int centre = static_cast<int>(clipped.size());
  for (int i = 0; i < centre; ++i)
  {
    const int next = (i + 1) % centre;
    const P2 a = { clipped[i][0] - g[0], clipped[i][1] - g[1] };
    const P2 b = { clipped[next][0] - g[0], clipped[next][1] - g[1] };
    const G twice_area = a[0] * b[1] - a[1] * b[0];
    // Exact sign test: the polygon is convex, wider than the zero length,
    // and fanned from its centroid, so its fan triangles are positive up to
    // round-off; a round-off one carries a round-off weight whichever way it
    // is decided, while a length-based threshold would drop the fan of a
    // thin overlap.
    if (value(twice_area) > 0)
      out.cells.push_back({ g, a, b, twice_area, { centre, i, next } });
  }
  return out;
}

} // namespace dolfinx_mortar
