// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

#include "surface_geometry.h"
#include <cstdint>
#include <span>
#include <vector>

namespace dolfinx_mortar
{

/// The mortar gaps c_A = ∫ N_A d of slave–master cell pairs in the current
/// configuration, with their exact gradients and Hessians with respect to
/// every node they depend on: the slave cell's, the master cell's, and
/// those of the slave cells around each slave node (through the averaged
/// nodal normals).
struct PairGapDerivatives
{
  std::size_t num_pairs = 0; ///< pairs
  int functions = 0; ///< per pair: ns (+ ns² with the mass), or 1 with weights
  int slave_nodes = 0;       ///< ns, nodes of a slave cell
  int gdim = 0;              ///< geometric dimension
  int num_nodes = 0; ///< variable nodes per pair (padded to the largest)
  /// (pairs, num_nodes): global ids of the variable nodes, the slave cell's
  /// first, then the rest of the slave nodes, then the master cell's; −1
  /// pads
  std::vector<std::int64_t> nodes;
  /// (pairs, ns), or (pairs, 1) with node weights (current_pair_gaps)
  std::vector<double> value;
  std::vector<double> gradient; ///< (pairs, ns or 1, num_nodes·gdim)
  /// (pairs, ns or 1, num_nodes·gdim, num_nodes·gdim)
  std::vector<double> hessian;
  /// (pairs, ns): c⁺_A = ∫ N_A ⟨d⟩, the pointwise active set's integrals
  /// (empty unless asked for)
  std::vector<double> value_plus;
  std::vector<double> gradient_plus;   ///< (pairs, ns, num_nodes·gdim)
  std::int64_t failed_projections = 0; ///< quadrature points skipped
};

/// The averaged unit normal at a surface node (the size-weighted normals of
/// the cells around it, summed and normalized: element_node_normals) with
/// its exact first and second derivatives.
struct NormalDerivatives
{
  int gdim = 0;                   ///< geometric dimension
  std::vector<std::int64_t> star; ///< ids of the nodes it depends on
  std::array<double, 3> value{};  ///< unit normal (gdim used)
  std::vector<double> gradient;   ///< (gdim, star·gdim)
  std::vector<double> hessian;    ///< (gdim, star·gdim, star·gdim)
};

/// The averaged normal at node id @p node (that of its normal_clusters
/// cluster: the size-weighted normals of the cells around any of its nodes) of a surface whose nodes carry
/// the global ids @p ids (a gathered surface has one copy of a node per cell;
/// copies share an id).
/// @throws std::invalid_argument if no cell holds the node or the summed
/// normal vanishes
NormalDerivatives
averaged_normal_derivatives(const FacetSurface& s,
                            std::span<const std::int64_t> ids,
                            std::int64_t node);

/// The cluster of every node of a surface whose nodes carry the global ids
/// @p ids (copies share an id): two nodes of one cell closer than
/// negligible_facet_ratio times the largest cell diameter around either are
/// one cluster, and so transitively. Returns, per surface node, the smallest
/// id of its cluster (its own id for a node in no cluster). A cluster's nodes
/// share one averaged normal, that of all the cells around them: a node
/// whose only cell is a vanishing facet (a corner chamfer 1e-6 h long) takes
/// the normal of the surface it belongs to, not of the artifact.
std::vector<std::int64_t>
normal_clusters(const FacetSurface& s, std::span<const std::int64_t> ids);

/// How current_pair_gaps integrates and what it returns.
struct PairGapOptions
{
  std::span<const double> points;  ///< the segment rule (as mortar_integrals)
  std::span<const double> weights; ///< its weights
  /// The zero length of the geometric decisions (the same as the values'
  /// segmentation used)
  double zero = 0;
  bool opposing_normals_only = true; ///< as mortar_integrals
  /// Also the Hessians (else `hessian` is empty and the gradients cost a
  /// fraction: a residual needs no Hessian)
  bool with_hessian = true;
  /// Also c⁺_A = ∫ N_A ⟨d⟩ with its gradient (the pointwise active set), from
  /// the same points
  bool with_positive_part = false;
  /// The surfaces are (r, z) meridians: every weight carries 2πr at the
  /// slave point, and its derivatives with it
  bool axisymmetric = false;
  /// (pairs, ns) or empty: the outputs are then those of the one function
  /// Σ_A w_A c_A per pair (value (pairs, 1), gradient and Hessian likewise):
  /// a Newton matrix needs only this weighted sum of the Hessians, at a
  /// fraction of the cost and memory of the ns apart
  std::span<const double> node_weights;
  /// Also the covered mass L_AB = ∫ N_A N_B of each pair (ns² functions after
  /// the ns c_A, row-major: functions ns + ns²), which a dual basis rebuilt
  /// over the covered part needs; node_weights then has ns + ns² per pair
  bool with_mass = false;
  /// Integrate overlaps of any positive width (SegmentationOptions::
  /// keep_slivers, which the pairs' segmentation must share)
  bool keep_slivers = false;
};

/// c_A and its derivatives for every pair: integrate_pieces instantiated with
/// a Jet over the pair's slave nodes, nodal normals and master nodes, then
/// chained through the normals to the nodes around the slave cell.
///
/// @param[in] slave, master The surfaces in the current configuration
/// @param[in] slave_ids, master_ids Global id of every node
/// @param[in] pairs (pairs, 2): slave cell, master cell
/// @param[in] options The rule and what to compute
/// @throws std::invalid_argument for element combinations without an
/// instantiation (3D quadratic facets), or weights of the wrong shape or
/// with the positive part
PairGapDerivatives
current_pair_gaps(const FacetSurface& slave,
                  std::span<const std::int64_t> slave_ids,
                  const FacetSurface& master,
                  std::span<const std::int64_t> master_ids,
                  std::span<const std::int32_t> pairs,
                  const PairGapOptions& options);

} // namespace dolfinx_mortar
