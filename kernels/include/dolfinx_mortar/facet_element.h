// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace dolfinx_mortar
{

/// Lagrange facet elements of contact surfaces, in Basix's node ordering.
enum class FacetType
{
  P1_line,
  P2_line,
  P1_triangle,
  P2_triangle,
  Q1_quadrilateral,
  Q2_quadrilateral, ///< 9 nodes
  Q8_quadrilateral  ///< 8-node serendipity
};

/// Topological dimension (1 for lines, 2 for triangles/quadrilaterals).
int
facet_tdim(FacetType type);

/// Number of nodes.
int
facet_num_nodes(FacetType type);

/// Readable name for error messages.
std::string
to_string(FacetType type);

/// Shape functions and their reference gradients at one reference point.
///
/// Hand-written rather than tabulated by Basix: segmentation evaluates them at
/// single points inside Newton loops, where Basix's array-based tabulation
/// would allocate per call. The Python tests check them against Basix.
///
/// @param[in] type The element
/// @param[in] X Reference point, size tdim
/// @param[out] N Values, size num_nodes
/// @param[out] dN Reference gradients, row-major (tdim, num_nodes)
void
facet_shape_functions(FacetType type,
                      std::span<const double> X,
                      std::span<double> N,
                      std::span<double> dN);

/// Flat sub-facets used for segmentation, as polygons of reference points
/// of the parent (counter-clockwise in the reference cell; 2 points for
/// lines). Linear facets have one sub-facet, the facet itself; quadratic
/// facets are split at their mid-edge points into 2 (lines) or 4 pieces.
const std::vector<std::vector<std::array<double, 2>>>&
facet_subfacets(FacetType type);

} // namespace dolfinx_mortar
