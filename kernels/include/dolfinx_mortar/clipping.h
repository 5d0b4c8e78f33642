// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

#include "jet.h"
#include <array>
#include <cmath>
#include <vector>

namespace dolfinx_mortar
{

using Point2 = std::array<double, 2>;

/// Signed area of a polygon (positive when counter-clockwise); T is double
/// or a Jet.
template<typename T>
T
signed_area(const std::vector<std::array<T, 2>>& polygon)
{
  T a = 0.0;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i)
  {
    const auto& p = polygon[i];
    const auto& q = polygon[(i + 1) % n];
    a += p[0] * q[1] - q[0] * p[1];
  }
  return 0.5 * a;
}

/// Intersection of a polygon with a convex, counter-clockwise clip polygon
/// (Sutherland–Hodgman). Points within @p tolerance of a clip edge's line are
/// on it: kept, so touching edges, shared vertices and parallel edges need no
/// special case. A crossing is computed only between points on opposite sides
/// (by value) of which at least one lies beyond the tolerance, so every
/// crossing point lies on its edge and is well conditioned; consecutive
/// points closer than @p tolerance are merged. The area is then exact up to
/// @p tolerance times the perimeter, and only where an edge lies within the
/// tolerance of the line along its whole length.
///
/// T is double or a Jet: every decision is taken on the values, so both
/// take the same branches and the Jet's vertices carry the derivatives of
/// the double ones.
/// @param[in] tolerance A length: geometric_tolerance × length scale
/// Written here because no library on the stack clips polygons (Eigen and
/// Basix do not; CGAL would be a heavy dependency for 40 lines).
template<typename T>
std::vector<std::array<T, 2>>
clip_polygon(const std::vector<std::array<T, 2>>& subject,
             const std::vector<std::array<T, 2>>& clip,
             double tolerance)
{
  using P = std::array<T, 2>;
  auto distance = [](const P& p, const P& q)
  { return std::hypot(value(p[0]) - value(q[0]), value(p[1]) - value(q[1])); };
  std::vector<P> output = subject, input;
  const std::size_t nc = clip.size();
  for (std::size_t e = 0; e < nc and !output.empty(); ++e)
  {
    const P& a = clip[e];
    const P& b = clip[(e + 1) % nc];
    const T ex = b[0] - a[0], ey = b[1] - a[1];
    const T length = hypot(ex, ey);
    if (value(length) <= tolerance)
      continue; // a degenerate clip edge cuts nothing
    // Signed distance to the edge's line, positive inside (left of a→b).
    auto side = [&](const P& p)
    { return (ex * (p[1] - a[1]) - ey * (p[0] - a[0])) / length; };
    input.swap(output);
    output.clear();
    // Points within the tolerance of the line are on it: kept. A crossing
    // is computed only between points on opposite sides, at least one beyond
    // the tolerance, so t lies in (0, 1) and the crossing point on the edge
    // p–q. (Classifying with the tolerance but intersecting without it put
    // t outside [0, 1] for a point "inside" by tolerance yet outside in
    // fact: crossing points extrapolated off the edge, and near-coincident
    // facets covered up to 80 times the slave's area.)
    auto classify = [tolerance](double s)
    { return s > tolerance ? 1 : (s < -tolerance ? -1 : 0); };
    const std::size_t n = input.size();
    for (std::size_t i = 0; i < n; ++i)
    {
      const P& p = input[i];
      const P& q = input[(i + 1) % n];
      const T sp = side(p), sq = side(q);
      const int cp = classify(value(sp)), cq = classify(value(sq));
      if (cp >= 0)
        output.push_back(p);
      // A crossing also from a point on the line (within the tolerance) to
      // one beyond it on the other side: along a nearly parallel edge it
      // may lie far from the point on the line, and leaving it out dropped
      // (or kept) a band up to the tolerance wide and the edge long. The
      // ends differ by more than the tolerance, so t is well conditioned.
      if ((cp * cq < 0) or (cp == 0 and cq < 0 and value(sp) > 0) or
          (cq == 0 and cp < 0 and value(sq) > 0))
      {
        const T t = sp / (sp - sq);
        output.push_back(
          { p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]) });
      }
    }
  }
  // Merge points that coincide within the tolerance.
  std::vector<P> merged;
  for (const P& p : output)
    if (merged.empty() or distance(p, merged.back()) > tolerance)
      merged.push_back(p);
  while (merged.size() > 1 and
         distance(merged.front(), merged.back()) <= tolerance)
    merged.pop_back();
  return merged;
}

} // namespace dolfinx_mortar
