// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
//
// The averaged nodal normals of a surface with their exact first and second
// derivatives, and the chain rule that carries derivatives through them
// (current_pair_gaps composes a pair's gaps with them).
#include "averaged_normals.h"

#include <dolfinx_mortar/jet.h>
#include <dolfinx_mortar/pair_segmentation.h>

#include <dolfinx_mortar/geometric_tolerance.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace dolfinx_mortar
{
namespace detail
{
// The coordinate rows are unit rows of J, and are applied as such (a third of
// the dense product's cost on a 3D pair).
void
compose(int m,
        int K,
        std::span<const double> gf,
        std::span<const double> Hf,
        std::span<const int> column,
        std::span<const double> J,
        const std::vector<const double*>& Hy,
        std::span<double> g,
        std::span<double> H)
{
  std::fill(g.begin(), g.end(), 0.0);
  std::fill(H.begin(), H.end(), 0.0);
  std::vector<double> HJ(K);
  for (int i = 0; i < m; ++i)
  {
    // row i of Hf J
    std::fill(HJ.begin(), HJ.end(), 0.0);
    for (int j = 0; j < m; ++j)
    {
      const double hij = Hf[i * m + j];
      if (column[j] >= 0)
        HJ[column[j]] += hij;
      else
        for (int z = 0; z < K; ++z)
          HJ[z] += hij * J[j * K + z];
    }
    if (column[i] >= 0)
    {
      g[column[i]] += gf[i];
      double* row = H.data() + column[i] * K;
      for (int z = 0; z < K; ++z)
        row[z] += HJ[z];
    }
    else
    {
      for (int a = 0; a < K; ++a)
      {
        const double Jia = J[i * K + a];
        g[a] += gf[i] * Jia;
        double* row = H.data() + a * K;
        for (int z = 0; z < K; ++z)
          row[z] += Jia * HJ[z];
      }
    }
    if (Hy[i])
      for (int ab = 0; ab < K * K; ++ab)
        H[ab] += gf[i] * Hy[i][ab];
  }
}

/// The size-weighted normal of a cell at its node @p position, with its
/// derivatives with respect to the cell's M = nodes·gdim coordinates (the
/// second ones with Order 2 only; @p hess untouched otherwise).
template<int M, int Order>
void
cell_normal_jet(FacetType type,
                int gdim,
                std::span<const double> nodes,
                int position,
                double* value_out,
                double* grad,
                double* hess)
{
  using J = Jet<M, Order>;
  const int nn = facet_num_nodes(type), tdim = facet_tdim(type);
  std::vector<J> x(M), N(nn), dN(tdim * nn);
  for (int i = 0; i < M; ++i)
    x[i] = J::variable(nodes[i], i);
  const std::vector<double> reference = facet_reference_nodes(type);
  const std::array<J, 2> X = { reference[position * tdim],
                               tdim == 2 ? reference[position * tdim + 1]
                                         : 0.0 };
  Vec3<J> p;
  std::array<Vec3<J>, 2> t;
  cell_geometry<J>(
    type, gdim, x, std::span<const J>(X.data(), tdim), N, dN, p, t);
  const Vec3<J> n = size_weighted_normal(gdim, t);
  for (int k = 0; k < gdim; ++k)
  {
    if constexpr (Order == 2)
      unpack(n[k], value_out[k], grad + k * M, hess + k * M * M);
    else
    {
      value_out[k] = n[k].v;
      std::copy(n[k].g.begin(), n[k].g.end(), grad + k * M);
    }
  }
}

template<int Order>
void
cell_normal_derivatives(FacetType type,
                        int gdim,
                        std::span<const double> nodes,
                        int position,
                        double* v,
                        double* g,
                        double* h)
{
  switch (facet_num_nodes(type) * gdim)
  {
    case 4:
      return cell_normal_jet<4, Order>(type, gdim, nodes, position, v, g, h);
    case 6:
      return cell_normal_jet<6, Order>(type, gdim, nodes, position, v, g, h);
    case 9:
      return cell_normal_jet<9, Order>(type, gdim, nodes, position, v, g, h);
    case 12:
      return cell_normal_jet<12, Order>(type, gdim, nodes, position, v, g, h);
    case 18:
      return cell_normal_jet<18, Order>(type, gdim, nodes, position, v, g, h);
    case 24:
      return cell_normal_jet<24, Order>(type, gdim, nodes, position, v, g, h);
    case 27:
      return cell_normal_jet<27, Order>(type, gdim, nodes, position, v, g, h);
  }
  throw std::logic_error("no cell normal instantiation for " + to_string(type));
}

Adjacency
node_cells(const FacetSurface& s, std::span<const std::int64_t> ids)
{
  const int nn = facet_num_nodes(s.type);
  Adjacency own;
  for (std::size_t c = 0; c < s.num_cells(); ++c)
    for (int i = 0; i < nn; ++i)
      own[ids[s.cells[c * nn + i]]].emplace_back(static_cast<std::int32_t>(c),
                                                 i);
  // a cluster's nodes share the cells around all of them
  const std::vector<std::int64_t> cluster = normal_clusters(s, ids);
  std::unordered_map<std::int64_t, std::vector<std::int64_t>> members;
  for (std::size_t a = 0; a < cluster.size(); ++a)
    if (cluster[a] != ids[a])
      members[cluster[a]].push_back(ids[a]);
  Adjacency around = own;
  for (auto& [root, others] : members)
  {
    std::sort(others.begin(), others.end());
    others.erase(std::unique(others.begin(), others.end()), others.end());
    std::vector<std::pair<std::int32_t, int>> shared = own[root];
    for (const std::int64_t id : others)
      shared.insert(shared.end(), own[id].begin(), own[id].end());
    around[root] = shared;
    for (const std::int64_t id : others)
      around[id] = shared;
  }
  return around;
}

/// averaged_normal_derivatives; without @p with_hessian the Hessian is
/// left empty (and its cells' second derivatives are not computed).
NormalDerivatives
normal_derivatives(const FacetSurface& s,
                   std::span<const std::int64_t> ids,
                   const Adjacency& around,
                   std::int64_t node,
                   bool with_hessian)
{
  const auto it = around.find(node);
  if (it == around.end())
    throw std::invalid_argument("node " + std::to_string(node) +
                                " is on no cell of the surface");
  const int nn = facet_num_nodes(s.type), gdim = s.gdim, M = nn * gdim;
  NormalDerivatives out;
  out.gdim = gdim;
  std::unordered_map<std::int64_t, int> position;
  for (const auto& [c, i] : it->second)
    for (int j = 0; j < nn; ++j)
    {
      const std::int64_t id = ids[s.cells[c * nn + j]];
      if (position.emplace(id, static_cast<int>(out.star.size())).second)
        out.star.push_back(id);
    }
  const int K = static_cast<int>(out.star.size()) * gdim;
  std::vector<double> sv(3, 0.0), ds(gdim * K, 0.0),
    d2s(with_hessian ? gdim * K * K : 0, 0.0);
  std::vector<double> nodes(M), v(gdim), g(gdim * M),
    h(with_hessian ? gdim * M * M : 0);
  std::vector<int> column(M);
  double largest = 0; // the largest cell normal: a length (2D) or an area
  for (const auto& [c, i] : it->second)
  {
    gather_cell_nodes(s, c, nodes);
    if (with_hessian)
      cell_normal_derivatives<2>(
        s.type, gdim, nodes, i, v.data(), g.data(), h.data());
    else
      cell_normal_derivatives<1>(
        s.type, gdim, nodes, i, v.data(), g.data(), h.data());
    for (int j = 0; j < nn; ++j)
      for (int k = 0; k < gdim; ++k)
        column[j * gdim + k] = position[ids[s.cells[c * nn + j]]] * gdim + k;
    double length = 0;
    for (int k = 0; k < gdim; ++k)
    {
      sv[k] += v[k];
      length += v[k] * v[k];
      for (int a = 0; a < M; ++a)
      {
        ds[k * K + column[a]] += g[k * M + a];
        if (with_hessian)
          for (int b = 0; b < M; ++b)
            d2s[(k * K + column[a]) * K + column[b]] += h[(k * M + a) * M + b];
      }
    }
    largest = std::max(largest, std::sqrt(length));
  }
  // n = s/|s| as a Jet in s, then chained to the nodes
  std::array<Jet<3>, 3> sj;
  for (int k = 0; k < 3; ++k)
    sj[k] = k < gdim ? Jet<3>::variable(sv[k], k) : Jet<3>(0.0);
  const Jet<3> length = sqrt(sj[0] * sj[0] + sj[1] * sj[1] + sj[2] * sj[2]);
  // cancelling normals (a folded surface): judged against the cells' own
  // normals, a dimensionless ratio
  if (!(length.v > geometric_tolerance * largest))
    throw std::invalid_argument("the normals around surface node " +
                                std::to_string(node) + " cancel");
  out.gradient.assign(gdim * K, 0.0);
  // without the Hessian, compose's is computed into scratch and dropped
  std::vector<double> hessian(gdim * K * K, 0.0);
  std::vector<const double*> Hy(gdim, nullptr);
  if (with_hessian)
    for (int k = 0; k < gdim; ++k)
      Hy[k] = d2s.data() + k * K * K;
  const std::vector<int> dense_rows(gdim, -1);
  for (int k = 0; k < gdim; ++k)
  {
    const Jet<3> nk = sj[k] / length;
    out.value[k] = nk.v;
    std::vector<double> Hf(gdim * gdim);
    for (int a = 0; a < gdim; ++a)
      for (int b = 0; b < gdim; ++b)
        Hf[a * gdim + b] = nk.hessian(a, b);
    compose(gdim,
            K,
            std::span<const double>(nk.g.data(), gdim),
            Hf,
            dense_rows,
            ds,
            Hy,
            std::span<double>(out.gradient.data() + k * K, K),
            std::span<double>(hessian.data() + k * K * K, K * K));
  }
  if (with_hessian)
    out.hessian = std::move(hessian);
  return out;
}

} // namespace detail

std::vector<std::int64_t>
normal_clusters(const FacetSurface& s, std::span<const std::int64_t> ids)
{
  s.check();
  if (ids.size() != s.x.size() / s.gdim)
    throw std::invalid_argument("one id per surface node expected");
  const int nn = facet_num_nodes(s.type), gdim = s.gdim;
  const std::size_t nc = s.num_cells();
  // the distance of every two nodes of a cell, in coordinates relative to
  // the cell's first node; the largest is the cell's diameter
  std::vector<double> nodes(nn * gdim), distance(nc * nn * nn, 0.0);
  std::unordered_map<std::int64_t, double> largest; // around each id
  for (std::size_t c = 0; c < nc; ++c)
  {
    gather_cell_nodes(s, c, nodes);
    double diameter = 0;
    for (int i = 0; i < nn; ++i)
      for (int j = i + 1; j < nn; ++j)
      {
        double d2 = 0;
        for (int k = 0; k < gdim; ++k)
        {
          const double dk = (nodes[j * gdim + k] - nodes[0 * gdim + k]) -
                            (nodes[i * gdim + k] - nodes[0 * gdim + k]);
          d2 += dk * dk;
        }
        distance[(c * nn + i) * nn + j] = std::sqrt(d2);
        diameter = std::max(diameter, std::sqrt(d2));
      }
    for (int i = 0; i < nn; ++i)
    {
      double& h = largest[ids[s.cells[c * nn + i]]];
      h = std::max(h, diameter);
    }
  }
  // union-find on ids, the smallest id the root (independent of the order
  // of the cells: the same clusters on every rank of a gathered surface)
  std::unordered_map<std::int64_t, std::int64_t> parent;
  auto find = [&](std::int64_t a)
  {
    auto it = parent.find(a);
    while (it != parent.end() && it->second != a)
    {
      a = it->second;
      it = parent.find(a);
    }
    return a;
  };
  for (std::size_t c = 0; c < nc; ++c)
    for (int i = 0; i < nn; ++i)
      for (int j = i + 1; j < nn; ++j)
      {
        const std::int64_t a = ids[s.cells[c * nn + i]],
                           b = ids[s.cells[c * nn + j]];
        const double h = std::max(largest[a], largest[b]);
        if (a == b || !(distance[(c * nn + i) * nn + j] <
                        negligible_facet_ratio * h))
          continue;
        const std::int64_t ra = find(a), rb = find(b);
        if (ra == rb)
          continue;
        parent.emplace(ra, ra);
        parent.emplace(rb, rb);
        parent[std::max(ra, rb)] = std::min(ra, rb);
      }
  std::vector<std::int64_t> root(ids.size());
  for (std::size_t a = 0; a < ids.size(); ++a)
    root[a] = find(ids[a]);
  return root;
}

NormalDerivatives
averaged_normal_derivatives(const FacetSurface& s,
                            std::span<const std::int64_t> ids,
                            std::int64_t node)
{
  s.check();
  if (ids.size() != s.x.size() / s.gdim)
    throw std::invalid_argument("one id per surface node expected");
  return detail::normal_derivatives(s, ids, detail::node_cells(s, ids), node);
}

} // namespace dolfinx_mortar
