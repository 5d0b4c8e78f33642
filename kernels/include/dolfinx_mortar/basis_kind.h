// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <string>
#include <string_view>

namespace dolfinx_mortar
{

/// The six mortar shape-function kinds for the contact pressure (Duong, De
/// Lorenzis, Sauer). A starred kind is a partition of unity; its unstarred
/// partner is the same basis divided column-wise by the lumped weights W.
enum class BasisKind
{
  GLS,       ///< M = N L⁻¹ (global least squares)
  GLS_star,  ///< M = N L⁻¹ W (global biorthogonality)
  LmLS,      ///< M = N W⁻¹ (weighted standard)
  LmLS_star, ///< M = N (standard)
  LcLS_star, ///< M|_e = N (L^e)⁻¹ W^e (dual, element-wise biorthogonal)
  LcLS       ///< M|_e = N (L^e)⁻¹ W^e W⁻¹
};

/// All kinds, in the order used by the paper's tables.
inline constexpr std::array<BasisKind, 6> all_basis_kinds = {
  BasisKind::GLS,       BasisKind::GLS_star,  BasisKind::LmLS,
  BasisKind::LmLS_star, BasisKind::LcLS_star, BasisKind::LcLS
};

/// Canonical name ("GLS", "GLS*", ...).
std::string
to_string(BasisKind kind);

/// Parse a canonical name or one of the aliases "standard" (LmLS*),
/// "weighted" (LmLS) and "dual" (LcLS*).
/// @throws std::invalid_argument naming the unknown kind and the valid ones.
BasisKind
basis_kind_from_string(std::string_view name);

/// True for the kinds whose functions sum to one (the starred kinds).
bool
is_partition_of_unity(BasisKind kind);

/// The kind with ∫M_A = 1 that a starred kind is a column scaling of (a
/// non-starred kind is its own partner).
BasisKind
unstarred_partner(BasisKind kind);

/// True for GLS and GLS*, whose functions have global support.
bool
is_global(BasisKind kind);

/// True for the kinds that are undefined when some ∫_e N_A ≤ 0 (every kind
/// that uses W or W^e).
bool
needs_positive_weights(BasisKind kind);

} // namespace dolfinx_mortar
