// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

#include <span>

namespace dolfinx_mortar
{

/// The one relative tolerance of every geometric decision (degenerate facet,
/// point on an edge, zero-area overlap). A length is zero when it is below
/// geometric_tolerance times the geometry's length scale (length_scale()).
/// Decisions are taken in coordinates relative to a local origin (a cell's
/// first node), where round-off in a computed length is a few 1e-16 of the
/// cells' size, whatever their distance from the origin; facets a
/// millionth of their neighbours' size are real input. 1e-10 sits between
/// the two with margin on both sides, so no decision depends on where
/// round-off lands.
inline constexpr double geometric_tolerance = 1e-10;

/// A facet edge this much shorter than the largest facet around its nodes
/// is a meshing artifact, not a feature: its nodes share one averaged normal
/// (normal_clusters). A facet a millionth of its neighbours' size at a
/// corner (as mesh generators leave) otherwise gives a node whose only
/// facet it is that facet's direction, which the penalty turns into a
/// pressure 8-40% off at that node. Well above round-off, far below any
/// grading of a real mesh (neighbouring facets differ by a factor of a few).
inline constexpr double negligible_facet_ratio = 1e-3;

/// The length scale of a set of points (x: (points, gdim), row-major): the
/// bounding box diagonal, the geometry's extent. Not its distance from the
/// origin: a scene shifted by 1e8 has the tolerance of the scene at the
/// origin (the kernels compute in local coordinates, so round-off does not
/// grow with |x| either).
double
length_scale(std::span<const double> x, int gdim);

/// The length below which a length is judged zero: geometric_tolerance *
/// length_scale(x, gdim), never below the smallest normal double.
double
zero_length(std::span<const double> x, int gdim);

} // namespace dolfinx_mortar
