// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#include "averaged_normals.h"
#include "pair_gap_jets.h"

#include <dolfinx_mortar/current_pair_gaps.h>
#include <dolfinx_mortar/piece_quadrature.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace dolfinx_mortar
{
using namespace detail;
namespace
{
/// One pair's gaps and their derivatives with respect to its own variable
/// nodes (current_pair_gaps).
struct PairResult
{
  std::vector<std::int64_t> nodes;
  std::vector<double> value, gradient, hessian, value_plus, gradient_plus;
};

/// The pairs' results into @p out, every pair padded to the largest variable
/// count (nodes −1, derivatives 0); @p out's shape fields are set.
void
pad_pairs(const std::vector<PairResult>& results,
          bool with_hessian,
          bool with_positive_part,
          PairGapDerivatives& out)
{
  const std::size_t P = results.size();
  const int nf = out.functions, ns = out.slave_nodes, gdim = out.gdim;
  std::size_t width = 0;
  for (const PairResult& r : results)
    width = std::max(width, r.nodes.size());
  out.num_nodes = static_cast<int>(width);
  const std::size_t Kw = width * gdim;
  out.nodes.assign(P * width, -1);
  out.value.assign(P * nf, 0.0);
  out.gradient.assign(P * nf * Kw, 0.0);
  out.hessian.assign(with_hessian ? P * nf * Kw * Kw : 0, 0.0);
  out.value_plus.assign(with_positive_part ? P * ns : 0, 0.0);
  out.gradient_plus.assign(with_positive_part ? P * ns * Kw : 0, 0.0);
  for (std::size_t p = 0; p < P; ++p)
  {
    const PairResult& r = results[p];
    const std::size_t K = r.nodes.size() * gdim;
    std::copy(r.nodes.begin(), r.nodes.end(), out.nodes.begin() + p * width);
    std::copy(r.value.begin(), r.value.end(), out.value.begin() + p * nf);
    std::copy(r.value_plus.begin(),
              r.value_plus.end(),
              out.value_plus.begin() + p * ns);
    if (with_positive_part)
      for (int a = 0; a < ns; ++a)
        std::copy_n(r.gradient_plus.begin() + a * K,
                    K,
                    out.gradient_plus.begin() + (p * ns + a) * Kw);
    for (int a = 0; a < nf; ++a)
    {
      std::copy_n(r.gradient.begin() + a * K,
                  K,
                  out.gradient.begin() + (p * nf + a) * Kw);
      if (!with_hessian)
        continue;
      for (std::size_t i = 0; i < K; ++i)
        std::copy_n(r.hessian.begin() + (a * K + i) * K,
                    K,
                    out.hessian.begin() + ((p * nf + a) * Kw + i) * Kw);
    }
  }
}

/// @throws std::invalid_argument naming what of current_pair_gaps' input is
/// inconsistent
void
check_input(const FacetSurface& slave,
            std::span<const std::int64_t> slave_ids,
            const FacetSurface& master,
            std::span<const std::int64_t> master_ids,
            std::span<const std::int32_t> pairs,
            const PairGapOptions& options)
{
  slave.check();
  master.check();
  if (slave.gdim != master.gdim)
    throw std::invalid_argument("slave and master surfaces differ in gdim");
  const int gdim = slave.gdim;
  if (options.axisymmetric and gdim != 2)
    throw std::invalid_argument(
      "axisymmetric surfaces are (r, z) lines: gdim must be 2");
  if (slave_ids.size() != slave.x.size() / gdim or
      master_ids.size() != master.x.size() / gdim)
    throw std::invalid_argument("one id per surface node expected");
  if (pairs.size() % 2 != 0)
    throw std::invalid_argument("pairs must have shape (pairs, 2)");
  if (options.points.size() != options.weights.size() * (gdim - 1))
    throw std::invalid_argument("quadrature points must have shape (points, " +
                                std::to_string(gdim - 1) + ")");
  const int ns = facet_num_nodes(slave.type);
  const int nw = ns + (options.with_mass ? ns * ns : 0);
  const bool weighted = !options.node_weights.empty();
  if (weighted and options.node_weights.size() != pairs.size() / 2 * nw)
    throw std::invalid_argument("node_weights must have shape (pairs, " +
                                std::to_string(nw) + ")");
  if (weighted and options.with_positive_part)
    throw std::invalid_argument(
      "node_weights combine c_A only, not the positive part's c⁺_A");
}

} // namespace

PairGapDerivatives
current_pair_gaps(const FacetSurface& slave,
                  std::span<const std::int64_t> slave_ids,
                  const FacetSurface& master,
                  std::span<const std::int64_t> master_ids,
                  std::span<const std::int32_t> pairs,
                  const PairGapOptions& options)
{
  const auto [points,
              weights,
              zero,
              opposing_normals_only,
              with_hessian,
              with_positive_part,
              axisymmetric,
              node_weights,
              with_mass,
              keep_slivers] = options;
  check_input(slave, slave_ids, master, master_ids, pairs, options);
  const int gdim = slave.gdim;
  const int ns = facet_num_nodes(slave.type), nm = facet_num_nodes(master.type);
  const int N = (2 * ns + nm) * gdim;
  const bool weighted = !node_weights.empty();
  // functions per pair: the ns c_A (and the ns² L_AB), or one weighted sum
  const int nw = ns + (with_mass ? ns * ns : 0);
  const int nf = weighted ? 1 : nw;
  const int NG = (ns + nm) * gdim;
  const InnerFunction inner =
    with_hessian ? inner_for<2>(N, NG) : inner_for<1>(N, NG);
  if (!inner)
    throw std::invalid_argument(
      "exact derivatives of the current-configuration mortar gap are "
      "instantiated for lines and for P1 triangles and Q1 quadrilaterals, not "
      "for " +
      to_string(slave.type) + " against " + to_string(master.type));

  const Adjacency around = node_cells(slave, slave_ids);
  std::unordered_map<std::int64_t, NormalDerivatives> normal_cache;
  auto normal_of = [&](std::int64_t id) -> const NormalDerivatives&
  {
    auto it = normal_cache.find(id);
    if (it == normal_cache.end())
      it =
        normal_cache
          .emplace(
            id, normal_derivatives(slave, slave_ids, around, id, with_hessian))
          .first;
    return it->second;
  };

  const std::size_t P = pairs.size() / 2;
  std::vector<PairResult> results(P);
  PairGapDerivatives out;
  out.num_pairs = pairs.size() / 2;
  out.functions = nf;
  out.slave_nodes = ns;
  out.gdim = gdim;
  std::vector<double> xs(ns * gdim), xm(nm * gdim), normals(ns * gdim);
  std::vector<double> value(nf), grad(nf * N),
    hess(with_hessian ? nf * N * N : 0),
    value_plus(with_positive_part ? ns : 0),
    grad_plus(with_positive_part ? ns * N : 0);
  for (std::size_t p = 0; p < P; ++p)
  {
    const auto cs = static_cast<std::size_t>(pairs[2 * p]);
    const auto cm = static_cast<std::size_t>(pairs[2 * p + 1]);
    if (cs >= slave.num_cells() or cm >= master.num_cells())
      throw std::invalid_argument("pair refers to a missing cell");
    gather_cell_nodes(slave, cs, xs);
    gather_cell_nodes(master, cm, xm);
    PairResult& r = results[p];
    std::unordered_map<std::int64_t, int> slave_position;
    for (int a = 0; a < ns; ++a)
    {
      const std::int64_t id = slave_ids[slave.cells[cs * ns + a]];
      const NormalDerivatives& nd = normal_of(id);
      std::copy_n(nd.value.begin(), gdim, normals.begin() + a * gdim);
      if (slave_position.emplace(id, static_cast<int>(r.nodes.size())).second)
        r.nodes.push_back(id);
    }
    for (int a = 0; a < ns; ++a)
      for (std::int64_t id :
           normal_of(slave_ids[slave.cells[cs * ns + a]]).star)
        if (slave_position.emplace(id, static_cast<int>(r.nodes.size())).second)
          r.nodes.push_back(id);
    const int num_slave = static_cast<int>(r.nodes.size());
    for (int c = 0; c < nm; ++c)
      r.nodes.push_back(master_ids[master.cells[cm * nm + c]]);
    const int K = static_cast<int>(r.nodes.size()) * gdim;

    out.failed_projections += inner(slave.type,
                                    master.type,
                                    gdim,
                                    xs,
                                    normals,
                                    xm,
                                    points,
                                    weights,
                                    zero,
                                    keep_slivers,
                                    opposing_normals_only,
                                    axisymmetric,
                                    with_mass,
                                    weighted ? node_weights.subspan(p * nw, nw)
                                             : std::span<const double>(),
                                    value,
                                    grad,
                                    hess,
                                    value_plus,
                                    grad_plus);
    // the inner variables as functions of the nodes: identity for the
    // coordinates, the averaged normals' derivatives for the normals (their
    // Hessians are added below, on their stars' columns only)
    std::vector<double> J(N * K, 0.0);
    std::vector<int> column(N, -1);
    std::vector<std::vector<int>> star_columns(ns);
    for (int a = 0; a < ns; ++a)
    {
      const std::int64_t id = slave_ids[slave.cells[cs * ns + a]];
      const int own = slave_position[id];
      const NormalDerivatives& nd = normal_of(id);
      const int Ks = static_cast<int>(nd.star.size()) * gdim;
      std::vector<int>& star_column = star_columns[a];
      star_column.resize(Ks);
      for (std::size_t j = 0; j < nd.star.size(); ++j)
        for (int l = 0; l < gdim; ++l)
          star_column[j * gdim + l] = slave_position[nd.star[j]] * gdim + l;
      for (int k = 0; k < gdim; ++k)
      {
        column[a * gdim + k] = own * gdim + k;
        const int row = (ns + a) * gdim + k;
        for (int i = 0; i < Ks; ++i)
          J[row * K + star_column[i]] += nd.gradient[k * Ks + i];
      }
    }
    for (int c = 0; c < nm; ++c)
      for (int k = 0; k < gdim; ++k)
        column[(2 * ns + c) * gdim + k] = (num_slave + c) * gdim + k;

    // g = Jᵀ gf for each row of @p from
    auto chain_gradient =
      [&](const std::vector<double>& from, std::vector<double>& to)
    {
      const int rows = static_cast<int>(from.size()) / N;
      to.assign(rows * K, 0.0);
      for (int a = 0; a < rows; ++a)
        for (int i = 0; i < N; ++i)
        {
          const double gi = from[a * N + i];
          double* g = to.data() + a * K;
          if (column[i] >= 0)
            g[column[i]] += gi;
          else
            for (int z = 0; z < K; ++z)
              g[z] += gi * J[i * K + z];
        }
    };
    r.value = value;
    r.value_plus = value_plus;
    if (with_positive_part)
      chain_gradient(grad_plus, r.gradient_plus);
    r.gradient.resize(nf * K);
    if (!with_hessian)
    {
      chain_gradient(grad, r.gradient);
      continue;
    }
    r.hessian.resize(nf * K * K);
    const std::vector<const double*> no_second(N, nullptr);
    for (int f = 0; f < nf; ++f)
    {
      std::span<double> H(r.hessian.data() + f * K * K, K * K);
      compose(N,
              K,
              std::span<const double>(grad.data() + f * N, N),
              std::span<const double>(hess.data() + f * N * N, N * N),
              column,
              J,
              no_second,
              std::span<double>(r.gradient.data() + f * K, K),
              H);
      // + Σ (∂f/∂n) ∂²n, each normal on its own star's columns
      for (int a = 0; a < ns; ++a)
      {
        const NormalDerivatives& nd =
          normal_of(slave_ids[slave.cells[cs * ns + a]]);
        const std::vector<int>& star_column = star_columns[a];
        const int Ks = static_cast<int>(star_column.size());
        for (int k = 0; k < gdim; ++k)
        {
          const double gf = grad[f * N + (ns + a) * gdim + k];
          const double* Hn = nd.hessian.data() + k * Ks * Ks;
          for (int i = 0; i < Ks; ++i)
          {
            double* row = H.data() + star_column[i] * K;
            for (int j = 0; j < Ks; ++j)
              row[star_column[j]] += gf * Hn[i * Ks + j];
          }
        }
      }
    }
  }

  pad_pairs(results, with_hessian, with_positive_part, out);
  return out;
}

} // namespace dolfinx_mortar
