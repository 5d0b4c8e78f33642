// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

#include "basis_kind.h"
#include <cstddef>
#include <span>
#include <vector>

namespace dolfinx_mortar
{

/// Check that no slave element is degenerate: its measure |e| = Σ_i W^e_i
/// (the slave basis is a partition of unity) must exceed zero_length ×
/// d_e^(tdim−1), with d_e the extent (bounding-box diagonal) of the element's
/// quadrature points and zero_length = geometric_tolerance × @p length_scale:
/// a zero-length line, or a triangle whose height is below the zero length.
/// A computed measure is never compared with 0: a zero-length facet measures
/// 0, 5.5e-17 or 1.1e-16 at |x| = 1 depending on the CPU's BLAS kernels, and
/// 1.8e-12 at |x| = 1e4.
///
/// @param[in] element_weights W^e, shape (cells, functions)
/// @param[in] num_functions Local functions per cell
/// @param[in] points Physical quadrature points, shape (cells, points, gdim)
/// @param[in] gdim Geometric dimension of @p points
/// @param[in] tdim Dimension of the elements (1 lines, 2 surfaces)
/// @param[in] length_scale The surface's length_scale() (over every rank)
/// @throws std::domain_error naming the first degenerate cell
void
check_element_measures(std::span<const double> element_weights,
                       std::size_t num_functions,
                       std::span<const double> points,
                       int gdim,
                       int tdim,
                       double length_scale);

/// Check that the lumped weights allow @p kind, relative to the element
/// measure |e| = Σ_i W^e_i (the slave basis is a partition of unity).
///
/// The dual kinds (LcLS*, LcLS) need W^e_A > 0 on every element; the kinds
/// that divide by or scale with the global W (LmLS, LcLS, GLS*) need W_A > 0.
/// Quadratic triangles (∫N_vertex = 0) and 8-node quads (∫N_vertex < 0) fail
/// this unless their basis is transformed first.
///
/// @param[in] kind The basis kind
/// @param[in] element_weights W^e, shape (cells, functions)
/// @param[in] nodal_weights Global W_A gathered at each cell's functions,
/// shape (cells, functions)
/// @param[in] num_functions Local functions per cell
/// A weight at most geometric_tolerance·|e| counts as zero: the ratio of two
/// integrals over the same element is scale-free, and its round-off is
/// relative to |e| (a vertex weight of a quadratic triangle is 0 up to it).
/// @throws std::domain_error naming the first offending cell and function
void
check_lumped_weights(BasisKind kind,
                     std::span<const double> element_weights,
                     std::span<const double> nodal_weights,
                     std::size_t num_functions);

/// Per-element coefficients of a local mortar basis in the slave basis,
/// M_A|_e = Σ_B C^e_BA N_B:
///   LmLS*: C^e = I;  LmLS: C^e = diag(1/W);
///   LcLS*: C^e = (L^e)⁻¹ diag(W^e);  LcLS: C^e = (L^e)⁻¹ diag(W^e) diag(1/W).
///
/// @param[in] kind A local kind (not GLS/GLS*, which have global support)
/// @param[in] element_mass L^e, shape (cells, functions, functions); only
/// read for the dual kinds (LcLS*, LcLS), may be empty for the others
/// @param[in] element_weights W^e, shape (cells, functions)
/// @param[in] nodal_weights Global W_A gathered at each cell's functions,
/// shape (cells, functions)
/// @param[in] num_functions Local functions per cell
/// @return C^e, row-major, shape (cells, functions, functions)
/// @throws std::invalid_argument for a global kind or inconsistent sizes
/// @throws std::domain_error for non-positive weights or a singular L^e
/// (degenerate element)
std::vector<double>
basis_coefficients(BasisKind kind,
                   std::span<const double> element_mass,
                   std::span<const double> element_weights,
                   std::span<const double> nodal_weights,
                   std::size_t num_functions);

} // namespace dolfinx_mortar
