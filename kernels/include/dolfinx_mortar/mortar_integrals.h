// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

#include "surface_geometry.h"
#include <cstdint>
#include <span>
#include <vector>

namespace dolfinx_mortar
{

/// Mortar integrals of slave–master cell pairs, in the slave basis N.
///
/// Every mortar basis is M = N C on a slave cell (C the cell's coefficient
/// matrix), so the integrals of any kind follow from these by Cᵀ·(…):
/// this kernel does the geometry once for all six kinds.
struct MortarIntegrals
{
  int gdim = 0;                        ///< geometric dimension
  int slave_nodes = 0;                 ///< ns, nodes of a slave cell
  int master_nodes = 0;                ///< nm, nodes of a master cell
  std::vector<std::int32_t> pairs;     ///< (pairs, 2): slave cell, master cell
  std::vector<double> D;               ///< (pairs, ns, ns): ∫ N_A N_B
  std::vector<double> M;               ///< (pairs, ns, nm): ∫ N_A N^m_C∘χ
  std::vector<double> gap;             ///< (pairs, ns): ∫ N_A d
  std::vector<double> area;            ///< (pairs): covered area
  std::int64_t failed_projections = 0; ///< Newton failures (points skipped)
  /// Cells whose height (area over longest edge; length in 2D) is below the
  /// zero length: they cover nothing, and the caller must be told.
  std::vector<std::int32_t> degenerate_slave_facets;
  std::vector<std::int32_t> degenerate_master_facets; ///< as the slave's

  /// Per quadrature point, only with SegmentationOptions::keep_points (the
  /// pointwise active set needs ⟨d⟩ at every point, not only ∫N d).
  std::vector<std::int32_t> point_pairs; ///< (points): index into pairs
  std::vector<double> point_weights;     ///< (points): weight × area factor
  std::vector<double> point_gap;         ///< (points): d
  std::vector<double> point_normals;     ///< (points, gdim): unit n
  std::vector<double> point_slave_N;     ///< (points, ns): N_A
  std::vector<double> point_master_N;    ///< (points, nm): N^m_C∘χ
};

/// Options of the segmentation.
struct SegmentationOptions
{
  /// Skip master facets whose normal does not oppose the slave's.
  bool opposing_normals_only = true;
  /// The length scale of every geometric decision (degenerate facet, overlap
  /// of zero area, point on an edge): lengths below geometric_tolerance
  /// times it are zero. 0: the length_scale() of both surfaces' coordinates.
  /// Pass one value on every rank so that decisions do not depend on the
  /// partition.
  double length_scale = 0;
  /// Also return the data of every quadrature point (MortarIntegrals::point_*).
  bool keep_points = false;
  /// Axisymmetric (2D only, coordinates (r, z)): integrate over the surface
  /// of revolution, dμ = 2π r ds with r the slave point's first coordinate.
  bool axisymmetric = false;
  /// Project master points onto each slave piece along the slave normals
  /// interpolated at the piece's centre instead of the piece's own normal,
  /// so that pairing and gap follow one direction field (normals that are
  /// not the slave's own, such as interface normals). A piece whose
  /// interpolated normal is within 60° of its plane keeps its own normal.
  bool project_along_normals = false;
  /// Keep overlaps of any positive width, not only those wider than the
  /// zero length (overlap_of): the current configuration, whose derivatives
  /// need every sliver the Jets of current_pair_gaps integrate
  bool keep_slivers = false;
};

/// Segment candidate slave–master cell pairs and integrate on the segments.
///
/// Per slave sub-facet (the facet itself for linear facets; 2 or 4 flat
/// pieces for quadratic ones): an auxiliary plane (line in 2D) through its
/// centre with its normal n₀; master sub-facets are projected onto it along
/// n₀ (or the interpolated nodal normal, SegmentationOptions::
/// project_along_normals) and clipped with it; the clip polygon is
/// triangulated from its centroid and integrated with the given rule; each
/// point is projected back along the same direction onto the slave and the
/// master cells (Newton). The gap is
/// d = (x_s − x_m)·n with n the interpolated averaged nodal normal.
///
/// @param[in] slave, master The surfaces (current configuration)
/// @param[in] slave_normals Averaged unit nodal normals (slave nodes, gdim)
/// @param[in] candidates Cell pairs to test, row-major (pairs, 2)
/// @param[in] points Quadrature points on the reference interval [0, 1]
/// (2D) or triangle (3D), row-major (points, gdim − 1)
/// @param[in] weights Quadrature weights (sum 1 or ½)
/// @param[in] options Segmentation options
/// @return Integrals of the pairs that overlap, and the degenerate cells of
/// both surfaces (all of them, candidates or not); pairs with a degenerate
/// cell are skipped
/// @throws std::invalid_argument for inconsistent arrays or a NaN or
/// infinite coordinate
MortarIntegrals
mortar_integrals(const FacetSurface& slave,
                 std::span<const double> slave_normals,
                 const FacetSurface& master,
                 std::span<const std::int32_t> candidates,
                 std::span<const double> points,
                 std::span<const double> weights,
                 const SegmentationOptions& options);

} // namespace dolfinx_mortar
