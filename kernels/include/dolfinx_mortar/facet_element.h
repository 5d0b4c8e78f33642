// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <stdexcept>
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

/// Whether x(X) is affine in X (P1 lines and triangles): the facet is its
/// own single flat piece, and a projection onto it is linear in the point.
inline bool
facet_is_affine(FacetType type)
{
  return type == FacetType::P1_line or type == FacetType::P1_triangle;
}

/// Flat sub-facets used for segmentation, as polygons of reference points
/// of the parent (counter-clockwise in the reference cell; 2 points for
/// lines). Linear facets have one sub-facet, the facet itself; quadratic
/// facets are split at their mid-edge points into 2 (lines) or 4 pieces.
const std::vector<std::vector<std::array<double, 2>>>&
facet_subfacets(FacetType type);

/// 1D quadratic Lagrange functions on [0, 1] at nodes 0, 1, 1/2, and their
/// derivatives.
template<typename T>
struct Quadratic1D
{
  T v[3], d[3];
  explicit Quadratic1D(const T& s)
    : v{ (1 - s) * (1 - 2 * s), s * (2 * s - 1), 4 * s * (1 - s) }
    , d{ 4 * s - 3, 4 * s - 1, 4 - 8 * s }
  {
  }
};

/// facet_shape_functions for any scalar type (double, or a Jet when the
/// reference point carries derivatives).
template<typename T>
void
shape_functions(FacetType type,
                std::span<const T> X,
                std::span<T> N,
                std::span<T> dN)
{
  const T x = X[0];
  const T y = facet_tdim(type) == 2 ? X[1] : T(0.0);
  switch (type)
  {
    case FacetType::P1_line:
      N[0] = 1 - x;
      N[1] = x;
      dN[0] = -1;
      dN[1] = 1;
      return;
    case FacetType::P2_line:
    {
      Quadratic1D<T> q(x);
      for (int i = 0; i < 3; ++i)
      {
        N[i] = q.v[i];
        dN[i] = q.d[i];
      }
      return;
    }
    case FacetType::P1_triangle:
      N[0] = 1 - x - y;
      N[1] = x;
      N[2] = y;
      dN[0] = -1, dN[1] = 1, dN[2] = 0;
      dN[3] = -1, dN[4] = 0, dN[5] = 1;
      return;
    case FacetType::P2_triangle:
    {
      const T l0 = 1 - x - y, l1 = x, l2 = y;
      N[0] = l0 * (2 * l0 - 1);
      N[1] = l1 * (2 * l1 - 1);
      N[2] = l2 * (2 * l2 - 1);
      N[3] = 4 * l1 * l2;
      N[4] = 4 * l0 * l2;
      N[5] = 4 * l0 * l1;
      // d/dx: dl0 = -1, dl1 = 1, dl2 = 0; d/dy: dl0 = -1, dl1 = 0, dl2 = 1
      dN[0] = -(4 * l0 - 1), dN[1] = 4 * l1 - 1, dN[2] = 0;
      dN[3] = 4 * l2, dN[4] = -4 * l2, dN[5] = 4 * (l0 - l1);
      dN[6] = -(4 * l0 - 1), dN[7] = 0, dN[8] = 4 * l2 - 1;
      dN[9] = 4 * l1, dN[10] = 4 * (l0 - l2), dN[11] = -4 * l1;
      return;
    }
    case FacetType::Q1_quadrilateral:
      N[0] = (1 - x) * (1 - y);
      N[1] = x * (1 - y);
      N[2] = (1 - x) * y;
      N[3] = x * y;
      dN[0] = -(1 - y), dN[1] = 1 - y, dN[2] = -y, dN[3] = y;
      dN[4] = -(1 - x), dN[5] = -x, dN[6] = 1 - x, dN[7] = x;
      return;
    case FacetType::Q2_quadrilateral:
    {
      // Basix order: vertices (0,0) (1,0) (0,1) (1,1); edges (0,1) (0,2)
      // (1,3) (2,3); interior. Index into Quadratic1D: 0 at 0, 1 at 1, 2 at ½.
      static constexpr int ix[9] = { 0, 1, 0, 1, 2, 0, 1, 2, 2 };
      static constexpr int iy[9] = { 0, 0, 1, 1, 0, 2, 2, 1, 2 };
      Quadratic1D<T> qx(x), qy(y);
      for (int i = 0; i < 9; ++i)
      {
        N[i] = qx.v[ix[i]] * qy.v[iy[i]];
        dN[i] = qx.d[ix[i]] * qy.v[iy[i]];
        dN[9 + i] = qx.v[ix[i]] * qy.d[iy[i]];
      }
      return;
    }
    case FacetType::Q8_quadrilateral:
    {
      // Serendipity on [-1, 1]², mapped to [0, 1]² (d/dx = 2 d/dξ).
      const T xi = 2 * x - 1, eta = 2 * y - 1;
      static constexpr double cx[8] = { -1, 1, -1, 1, 0, -1, 1, 0 };
      static constexpr double cy[8] = { -1, -1, 1, 1, -1, 0, 0, 1 };
      for (int i = 0; i < 8; ++i)
      {
        const double a = cx[i], b = cy[i];
        if (i < 4)
        {
          N[i] = 0.25 * (1 + a * xi) * (1 + b * eta) * (a * xi + b * eta - 1);
          dN[i] = 2 * 0.25 * a * (1 + b * eta) * (2 * a * xi + b * eta);
          dN[8 + i] = 2 * 0.25 * b * (1 + a * xi) * (a * xi + 2 * b * eta);
        }
        else if (a == 0)
        {
          N[i] = 0.5 * (1 - xi * xi) * (1 + b * eta);
          dN[i] = 2 * 0.5 * (-2 * xi) * (1 + b * eta);
          dN[8 + i] = 2 * 0.5 * (1 - xi * xi) * b;
        }
        else
        {
          N[i] = 0.5 * (1 + a * xi) * (1 - eta * eta);
          dN[i] = 2 * 0.5 * a * (1 - eta * eta);
          dN[8 + i] = 2 * 0.5 * (1 + a * xi) * (-2 * eta);
        }
      }
      return;
    }
  }
  throw std::logic_error("corrupt FacetType");
}

} // namespace dolfinx_mortar
