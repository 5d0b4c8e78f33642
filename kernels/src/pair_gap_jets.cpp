// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
//
// The Jet instantiations of one pair's segmentation (the most costly part to
// compile and to run: each pair type's variable count is a template
// argument).
#include "pair_gap_jets.h"

#include <dolfinx_mortar/jet.h>
#include <dolfinx_mortar/piece_quadrature.h>

#include <algorithm>

namespace dolfinx_mortar::detail
{
namespace
{
/// c_A of one pair as Jets over its slave coordinates, nodal normals and
/// master coordinates (in that order); returns failed projections. Order 1:
/// no Hessian (@p hess untouched). Non-empty @p value_plus: also c⁺_A =
/// ∫ N_A ⟨d⟩ and its gradient (@p grad_plus). @p with_mass: also the covered
/// mass L_AB = ∫ N_A N_B, ns² functions after the ns c_A (row-major).
/// Non-empty @p node_weights (ns, or ns + ns² with the mass): the one
/// function Σ_A w_A c_A (+ Σ_AB w_AB L_AB) instead. The geometry
/// runs on Jets over the NG = N − ns·gdim coordinates only (integrate_pieces).
template<int N, int NG, int Order>
std::int64_t
inner_pair_derivatives(FacetType slave_type,
                       FacetType master_type,
                       int gdim,
                       std::span<const double> slave_nodes,
                       std::span<const double> normals,
                       std::span<const double> master_nodes,
                       std::span<const double> points,
                       std::span<const double> weights,
                       double zero,
                       bool keep_slivers,
                       bool opposing_normals_only,
                       bool axisymmetric,
                       bool with_mass,
                       std::span<const double> node_weights,
                       std::span<double> value,
                       std::span<double> grad,
                       std::span<double> hess,
                       std::span<double> value_plus,
                       std::span<double> grad_plus)
{
  using J = Jet<N, Order>;
  using G = Jet<NG, Order>;
  static_assert(NG < N);
  // J's variables: slave coordinates, normals, master coordinates; G's: the
  // coordinates alone
  const int split = static_cast<int>(slave_nodes.size());
  std::vector<G> s(slave_nodes.size()), m(master_nodes.size());
  std::vector<J> n(normals.size());
  for (std::size_t i = 0; i < s.size(); ++i)
    s[i] = G::variable(slave_nodes[i], i);
  for (std::size_t i = 0; i < n.size(); ++i)
    n[i] = J::variable(normals[i], split + i);
  for (std::size_t i = 0; i < m.size(); ++i)
    m[i] = G::variable(master_nodes[i], split + i);
  const int shift = static_cast<int>(normals.size());
  auto lift = [split, shift](const G& x) { return widen<N>(x, split, shift); };
  const int ns = facet_num_nodes(slave_type);
  const bool weighted = !node_weights.empty();
  const int nf = ns + (with_mass ? ns * ns : 0);
  std::vector<J> c(weighted ? 1 : nf, J(0.0)),
    cp(value_plus.empty() ? 0 : ns, J(0.0));
  auto accumulate = [&](const SegmentPoint<J>& q)
  {
    const J wd = q.weight * q.gap;
    if (weighted)
    {
      // one product per point instead of ns
      J combination(0.0);
      for (int a = 0; a < ns; ++a)
        combination.add_scaled(node_weights[a], q.slave_N[a]);
      c[0] += wd * combination;
      if (with_mass)
      {
        // Σ_AB w_AB N_A N_B = Σ_A N_A (Σ_B w_AB N_B)
        J mass(0.0);
        for (int a = 0; a < ns; ++a)
        {
          J row(0.0);
          for (int b = 0; b < ns; ++b)
            row.add_scaled(node_weights[ns + a * ns + b], q.slave_N[b]);
          mass += q.slave_N[a] * row;
        }
        c[0] += q.weight * mass;
      }
    }
    else
    {
      for (int a = 0; a < ns; ++a)
        c[a] += wd * q.slave_N[a];
      if (with_mass)
        for (int a = 0; a < ns; ++a)
        {
          const J wa = q.weight * q.slave_N[a];
          for (int b = a; b < ns; ++b)
            c[ns + a * ns + b] += wa * q.slave_N[b];
        }
    }
    if (cp.empty())
      return;
    // ⟨d⟩, decided on the value (as the double segmentation's points are)
    const J wp = q.weight * larger(q.gap, J(0.0));
    for (int a = 0; a < ns; ++a)
      cp[a] += wp * q.slave_N[a];
  };
  const std::int64_t failed = integrate_pieces<J, G>(
    slave_type,
    master_type,
    gdim,
    std::span<const G>(s),
    std::span<const J>(n),
    std::span<const G>(m),
    cell_pieces<G>(slave_type, gdim, std::span<const G>(s), zero),
    cell_pieces<G>(master_type, gdim, std::span<const G>(m), zero),
    points,
    weights,
    zero,
    keep_slivers,
    opposing_normals_only,
    axisymmetric,
    false, // c_A needs no master shape functions
    lift,
    accumulate);
  if (with_mass and !weighted) // the mass is symmetric: its lower triangle
    for (int a = 0; a < ns; ++a)
      for (int b = 0; b < a; ++b)
        c[ns + a * ns + b] = c[ns + b * ns + a];
  for (std::size_t a = 0; a < c.size(); ++a)
  {
    value[a] = c[a].v;
    std::copy(c[a].g.begin(), c[a].g.end(), grad.data() + a * N);
    if constexpr (Order == 2)
      unpack(c[a], value[a], grad.data() + a * N, hess.data() + a * N * N);
  }
  for (std::size_t a = 0; a < cp.size(); ++a)
  {
    value_plus[a] = cp[a].v;
    std::copy(cp[a].g.begin(), cp[a].g.end(), grad_plus.data() + a * N);
  }
  return failed;
}

} // namespace

/// The instantiation for N variables of which NG are coordinates: 2D lines
/// of degree 1 or 2 (12–18), 3D P1 triangles and Q1 quadrilaterals (27–36).
template<int Order>
InnerFunction
inner_for(int N, int NG)
{
  // NG is fixed by N for every instantiated pair type; the check guards it
  auto checked = [NG](int ng, InnerFunction f)
  { return NG == ng ? f : nullptr; };
  switch (N)
  {
    case 12:
      return checked(8, &inner_pair_derivatives<12, 8, Order>);
    case 14:
      return checked(10, &inner_pair_derivatives<14, 10, Order>);
    case 16:
      return checked(10, &inner_pair_derivatives<16, 10, Order>);
    case 18:
      return checked(12, &inner_pair_derivatives<18, 12, Order>);
    case 27:
      return checked(18, &inner_pair_derivatives<27, 18, Order>);
    case 30:
      return checked(21, &inner_pair_derivatives<30, 21, Order>);
    case 33:
      return checked(21, &inner_pair_derivatives<33, 21, Order>);
    case 36:
      return checked(24, &inner_pair_derivatives<36, 24, Order>);
  }
  return nullptr;
}

template InnerFunction
inner_for<1>(int, int);
template InnerFunction
inner_for<2>(int, int);

} // namespace dolfinx_mortar::detail
