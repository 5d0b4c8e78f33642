// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

// The cell quantities of a slave surface in the current configuration,
// written once for any Scalar: the area element J, the lumped weights
// W_a = ∫ N_a J and the obstacle gaps ĝ_a = ∫ φ_a J d. Instantiated for a
// Jet over the cell's node coordinates, they come with their exact gradients
// and Hessians, as the pair segmentation does for the mortar gaps.

#include "scalar.h"
#include "vec3.h"

#include <cstddef>
#include <numbers>
#include <span>
#include <vector>

namespace dolfinx_mortar
{

/// The cells of a slave surface and the rule they are integrated with.
struct SurfaceCells
{
  int gdim = 2;               ///< geometric dimension
  int tdim = 1;               ///< cell dimension (gdim − 1)
  int nodes = 2;              ///< nodes per cell
  std::span<const double> x;  ///< (cells, nodes, gdim) current coordinates
  std::span<const double> N;  ///< (points, nodes) shape functions
  std::span<const double> dN; ///< (points, tdim, nodes) reference gradients
  std::span<const double> weights; ///< (points) reference rule
  std::span<const double> phi;     ///< (points, nodes) the gap basis φ = N C
  /// the cells are (r, z) meridians: every weight carries 2πr
  bool axisymmetric = false;

  std::size_t num_cells() const { return x.size() / (nodes * gdim); }
  std::size_t num_points() const { return weights.size(); }
  int num_variables() const { return nodes * gdim; }
  /// @throws std::invalid_argument if the arrays' sizes disagree
  void check() const;
};

/// A rigid obstacle's gap d = −φ(x) at every quadrature point of every cell,
/// with its first and second derivatives with respect to the point.
struct ObstacleAtPoints
{
  std::span<const double> d;        ///< (cells, points)
  std::span<const double> gradient; ///< (cells, points, gdim)
  std::span<const double> hessian;  ///< (cells, points, gdim, gdim)
  /// also ĝ⁺_a = ∫ φ_a J ⟨d⟩ (the pointwise active set; not split at d = 0)
  bool positive_part = false;
};

/// Values and gradients of the cell quantities; the gradients are with
/// respect to the cell's node coordinates, (node, component) row-major.
struct SurfaceCellDerivatives
{
  std::size_t num_cells = 0;
  int nodes = 0;
  int num_variables = 0;
  std::vector<double> W;          ///< (cells, nodes): ∫ N_a J
  std::vector<double> W_gradient; ///< (cells, nodes, variables)
  std::vector<double>
    gap; ///< (cells, nodes): ∫ φ_a J d (empty without obstacle)
  std::vector<double> gap_gradient; ///< (cells, nodes, variables)
  std::vector<double> gap_plus; ///< (cells, nodes): ∫ φ_a J ⟨d⟩ (if asked for)
  std::vector<double> gap_plus_gradient; ///< (cells, nodes, variables)
};

/// The area element at one point of a cell with node coordinates @p x
/// (nodes, gdim): J = sqrt(det FᵀF), F = Σ_b x_b ⊗ ∇N_b (gdim × tdim), times
/// 2πr (r = Σ_b N_b x_b,r clamped at 0) on a meridian.
/// @param[in] N Shape functions at the point (nodes)
/// @param[in] dN Reference gradients at the point (tdim, nodes)
template<Scalar T>
T
area_element(std::span<const T> x,
             std::span<const double> N,
             std::span<const double> dN,
             int gdim,
             int tdim,
             bool axisymmetric)
{
  const auto nodes = N.size();
  std::array<Vec3<T>, 2> F{};
  for (int t = 0; t < tdim; ++t)
    for (std::size_t b = 0; b < nodes; ++b)
      for (int i = 0; i < gdim; ++i)
        add_scaled(F[t][i], dN[t * nodes + b], x[b * gdim + i]);
  T J;
  if (tdim == 1)
    J = vec3::norm(F[0]);
  else
  {
    const T a = vec3::dot(F[0], F[0]), b = vec3::dot(F[0], F[1]),
            c = vec3::dot(F[1], F[1]);
    J = sqrt(a * c - b * b);
  }
  if (axisymmetric)
  {
    T r(0.0);
    for (std::size_t b = 0; b < nodes; ++b)
      add_scaled(r, N[b], x[b * gdim]);
    // an axis node may sit at −1e-17: the radius is clamped at 0
    J = J * (2 * std::numbers::pi * larger(r, T(0.0)));
  }
  return J;
}

/// W, and against an obstacle ĝ (and ĝ⁺), of every cell with their
/// gradients.
/// @param[in] obstacle Null: W only
/// @throws std::invalid_argument for array sizes that disagree, or a cell
/// type without an instantiation
SurfaceCellDerivatives
current_surface_cells(const SurfaceCells& cells,
                      const ObstacleAtPoints* obstacle);

/// The Hessian of Σ_a (w^W_a W_a + w^g_a ĝ_a) of every cell, (cells,
/// variables, variables): what a Newton matrix needs of the cell quantities'
/// second derivatives, as one weighted sum.
/// @param[in] W_weights (cells, nodes)
/// @param[in] gap_weights (cells, nodes), used with an obstacle only
std::vector<double>
current_surface_hessians(const SurfaceCells& cells,
                         const ObstacleAtPoints* obstacle,
                         std::span<const double> W_weights,
                         std::span<const double> gap_weights);

} // namespace dolfinx_mortar
