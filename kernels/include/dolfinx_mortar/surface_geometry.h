// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

#include "facet_element.h"
#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace dolfinx_mortar
{

/// A facet surface as plain arrays. Node ordering within a cell is Basix's,
/// oriented so that the natural normal points out of the body:
/// 2D n = (t_y, -t_x) with t = dx/dX; 3D n = ∂x/∂X₀ × ∂x/∂X₁.
struct FacetSurface
{
  FacetType type;
  int gdim;                            ///< 2 or 3
  std::span<const double> x;           ///< node coordinates (nodes, gdim)
  std::span<const std::int32_t> cells; ///< (cells, nodes per cell)

  std::size_t num_cells() const { return cells.size() / facet_num_nodes(type); }
  /// Throws std::invalid_argument if the arrays do not fit together or a
  /// coordinate is NaN or infinite (naming the node).
  void check() const;
};

using Point3 = std::array<double, 3>;

/// Copy the node coordinates of cell @p c, (nodes, gdim), into @p out.
void
gather_cell_nodes(const FacetSurface& s, std::size_t c, std::span<double> out);

/// Position x(X) and tangents ∂x/∂X_k (2D: z = 0) of cell @p c.
void
facet_geometry(const FacetSurface& s,
               std::size_t c,
               std::span<const double> X,
               std::span<double> N,
               std::span<double> dN,
               Point3& x,
               std::array<Point3, 2>& tangents);

/// Unit normal from tangents (2D: only tangents[0] is used), or the zero
/// vector where the tangents span no plane: the tangent's length (2D) or the
/// tangents' parallelogram height (3D) at most @p zero (zero_length()).
Point3
normal_from_tangents(int gdim,
                     const std::array<Point3, 2>& tangents,
                     double zero);

/// Reference coordinates of the nodes, row-major (nodes, tdim).
std::vector<double>
facet_reference_nodes(FacetType type);

/// Normal of each cell at each of its nodes, (cells, nodes, gdim): unit, or
/// with @p size_weighted of length |J| at the node (the facet's length or
/// twice its area on P1 cells). Summing the size-weighted ones per node and
/// normalizing gives the averaged nodal normals (docs/DESIGN.md, §Penalty
/// contact), which a facet of vanishing size cannot tilt (unit normals gave a
/// 1e-6 h facet at 45° the same say as its neighbour: 22° of tilt).
std::vector<double>
element_node_normals(const FacetSurface& s, bool size_weighted = false);

/// Bounding box of each cell's nodes enlarged by @p margin, (cells, 6).
std::vector<double>
facet_bounding_boxes(const FacetSurface& s, double margin);

/// Result of projecting a point along a direction onto a facet.
struct Projection
{
  std::array<double, 2> X; ///< reference coordinates
  double t;                ///< x(X) = p + t·direction
  bool converged;
};

/// Solve x(X) = p + t·direction for (X, t) by Newton's method from @p X0.
Projection
project_along(const FacetSurface& s,
              std::size_t c,
              const Point3& p,
              const Point3& direction,
              std::array<double, 2> X0);

/// project_along on a cell given by its node coordinates (nodes, gdim).
Projection
project_along(FacetType type,
              int gdim,
              std::span<const double> cell_nodes,
              const Point3& p,
              const Point3& direction,
              std::array<double, 2> X0);

} // namespace dolfinx_mortar
