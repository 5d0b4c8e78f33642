// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

// Internal to the kernels' sources: the averaged nodal normals' derivatives
// and the chain rule, shared by averaged_normals.cpp and current_pair_gaps.cpp.

#include <dolfinx_mortar/current_pair_gaps.h>
#include <dolfinx_mortar/surface_geometry.h>

#include <cstdint>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

namespace dolfinx_mortar::detail
{

/// The chain rule for f(y(z)) with f's gradient @p gf (m) and Hessian @p Hf
/// (m × m) in y, where y_i is either the node coordinate z_{column[i]}
/// (column[i] ≥ 0) or a function of z with gradient row i of @p J (m × K)
/// and Hessian @p Hy[i] (K × K; null if zero): g = Jᵀ gf, H = Jᵀ Hf J + Σ_i
/// gf_i Hy_i.
void
compose(int m,
        int K,
        std::span<const double> gf,
        std::span<const double> Hf,
        std::span<const int> column,
        std::span<const double> J,
        const std::vector<const double*>& Hy,
        std::span<double> g,
        std::span<double> H);

/// The cells (cell, position) holding each node id.
using Adjacency =
  std::unordered_map<std::int64_t, std::vector<std::pair<std::int32_t, int>>>;

/// The cells around every node id of a surface.
Adjacency
node_cells(const FacetSurface& s, std::span<const std::int64_t> ids);

/// averaged_normal_derivatives; without @p with_hessian the Hessian is
/// left empty (and its cells' second derivatives are not computed).
NormalDerivatives
normal_derivatives(const FacetSurface& s,
                   std::span<const std::int64_t> ids,
                   const Adjacency& around,
                   std::int64_t node,
                   bool with_hessian = true);

} // namespace dolfinx_mortar::detail
