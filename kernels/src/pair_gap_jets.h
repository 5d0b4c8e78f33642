// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

// Internal to the kernels' sources: one pair's gaps c_A on Jets
// (pair_gap_jets.cpp), for current_pair_gaps.

#include <dolfinx_mortar/facet_element.h>

#include <cstdint>
#include <span>

namespace dolfinx_mortar::detail
{

/// c_A of one pair as Jets over its slave coordinates, nodal normals and
/// master coordinates (see pair_gap_jets.cpp); returns failed projections.
using InnerFunction = std::int64_t (*)(FacetType,
                                       FacetType,
                                       int,
                                       std::span<const double>,
                                       std::span<const double>,
                                       std::span<const double>,
                                       std::span<const double>,
                                       std::span<const double>,
                                       double,
                                       bool,
                                       bool,
                                       bool,
                                       bool,
                                       std::span<const double>,
                                       std::span<double>,
                                       std::span<double>,
                                       std::span<double>,
                                       std::span<double>,
                                       std::span<double>);

/// The instantiation for N variables of which NG are coordinates (Order 1:
/// gradients, 2: also Hessians), or null where there is none.
template<int Order>
InnerFunction
inner_for(int N, int NG);

} // namespace dolfinx_mortar::detail
