// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#include <dolfinx_mortar/clipping.h>

#include <cmath>

namespace dolfinx_mortar
{

double
signed_area(const std::vector<Point2>& polygon)
{
  double a = 0;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i)
  {
    const Point2& p = polygon[i];
    const Point2& q = polygon[(i + 1) % n];
    a += p[0] * q[1] - q[0] * p[1];
  }
  return 0.5 * a;
}

std::vector<Point2>
clip_polygon(const std::vector<Point2>& subject,
             const std::vector<Point2>& clip,
             double tolerance)
{
  std::vector<Point2> output = subject, input;
  const std::size_t nc = clip.size();
  for (std::size_t e = 0; e < nc and !output.empty(); ++e)
  {
    const Point2& a = clip[e];
    const Point2& b = clip[(e + 1) % nc];
    const double ex = b[0] - a[0], ey = b[1] - a[1];
    const double length = std::hypot(ex, ey);
    if (length <= tolerance)
      continue; // a degenerate clip edge cuts nothing
    // Signed distance to the edge's line, positive inside (left of a→b).
    auto side = [&](const Point2& p)
    { return (ex * (p[1] - a[1]) - ey * (p[0] - a[0])) / length; };
    input.swap(output);
    output.clear();
    // Points within the tolerance of the line are on it: kept, and never
    // the end of a crossing. A crossing is computed only between points
    // strictly on opposite sides beyond the tolerance, so t lies in (0, 1)
    // and the crossing point on the edge p–q. (Classifying with the
    // tolerance but intersecting without it put t outside [0, 1] for a
    // point "inside" by tolerance yet outside in fact: crossing points
    // extrapolated off the edge, and near-coincident facets covered up to
    // 80 times the slave's area.)
    auto classify = [tolerance](double s)
    { return s > tolerance ? 1 : (s < -tolerance ? -1 : 0); };
    const std::size_t n = input.size();
    for (std::size_t i = 0; i < n; ++i)
    {
      const Point2& p = input[i];
      const Point2& q = input[(i + 1) % n];
      const double sp = side(p), sq = side(q);
      const int cp = classify(sp), cq = classify(sq);
      if (cp >= 0)
        output.push_back(p);
      if (cp * cq < 0)
      {
        const double t = sp / (sp - sq);
        output.push_back(
          { p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]) });
      }
    }
  }
  // Merge points that coincide within the tolerance.
  std::vector<Point2> merged;
  for (const Point2& p : output)
    if (merged.empty() or std::hypot(p[0] - merged.back()[0],
                                     p[1] - merged.back()[1]) > tolerance)
      merged.push_back(p);
  while (merged.size() > 1 and
         std::hypot(merged.front()[0] - merged.back()[0],
                    merged.front()[1] - merged.back()[1]) <= tolerance)
    merged.pop_back();
  return merged;
}

} // namespace dolfinx_mortar
