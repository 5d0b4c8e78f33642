// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <vector>

namespace dolfinx_mortar
{

/// Shape of tabulated slave basis values: (cells, quadrature points, local
/// functions). Arrays using it are row-major.
using TabulationShape = std::array<std::size_t, 3>;

/// Element integrals ∫_e N_i f dA of every local function.
///
/// @param[in] phi Basis values N_i(x_q), shape (cells, points, functions)
/// @param[in] weights Quadrature weight × |J| × f(x_q), shape (cells, points)
/// @param[in] shape The shape of @p phi
/// @return Row-major array of shape (cells, functions)
std::vector<double>
element_integrals(std::span<const double> phi,
                  std::span<const double> weights,
                  TabulationShape shape);

/// Element mass matrices L^e_ij = ∫_e N_i N_j dA.
///
/// @param[in] phi Basis values, shape (cells, points, functions)
/// @param[in] weights Quadrature weight × |J|, shape (cells, points)
/// @param[in] shape The shape of @p phi
/// @return Row-major array of shape (cells, functions, functions)
std::vector<double>
element_mass_matrices(std::span<const double> phi,
                      std::span<const double> weights,
                      TabulationShape shape);

} // namespace dolfinx_mortar
