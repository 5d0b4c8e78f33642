// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <vector>

namespace dolfinx_mortar
{

using Point2 = std::array<double, 2>;

/// Signed area of a polygon (positive when counter-clockwise).
double
signed_area(const std::vector<Point2>& polygon);

/// Intersection of a polygon with a convex, counter-clockwise clip polygon
/// (Sutherland–Hodgman). Points within @p tolerance of a clip edge's line are
/// on it: kept, and never the end of a crossing, so touching edges, shared
/// vertices and parallel edges need no special case and every crossing point
/// lies on its edge; consecutive points closer than @p tolerance are merged.
/// The area is then exact up to @p tolerance times the perimeter.
/// @param[in] tolerance A length: geometric_tolerance × length scale
/// Written here because no library on the stack clips polygons (Eigen and
/// Basix do not; CGAL would be a heavy dependency for 40 lines).
std::vector<Point2>
clip_polygon(const std::vector<Point2>& subject,
             const std::vector<Point2>& clip,
             double tolerance);

} // namespace dolfinx_mortar
