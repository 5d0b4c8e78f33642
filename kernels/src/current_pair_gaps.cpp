// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#include <dolfinx_mortar/current_pair_gaps.h>
#include <dolfinx_mortar/piece_quadrature.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace dolfinx_mortar
{
namespace
{
/// The chain rule for f(y(z)) with f's gradient @p gf (m) and Hessian @p Hf
/// (m × m) in y, where y_i is either the node coordinate z_{column[i]}
/// (column[i] ≥ 0) or a function of z with gradient row i of @p J (m × K)
/// and Hessian @p Hy[i] (K × K; null if zero):
/// g = Jᵀ gf, H = Jᵀ Hf J + Σ_i gf_i Hy_i. The coordinate rows are unit
/// rows of J, and are applied as such (a third of the dense product's cost
/// on a 3D pair).
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

/// Value, gradient and full Hessian of a Jet, into flat arrays.
template<int N>
void
unpack(const Jet<N>& x, double& v, double* g, double* H)
{
  v = x.v;
  std::copy(x.g.begin(), x.g.end(), g);
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j)
      H[i * N + j] = x.hessian(i, j);
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

/// The cells (cell, position) holding each node id.
using Adjacency =
  std::unordered_map<std::int64_t, std::vector<std::pair<std::int32_t, int>>>;

Adjacency
node_cells(const FacetSurface& s, std::span<const std::int64_t> ids)
{
  const int nn = facet_num_nodes(s.type);
  Adjacency around;
  for (std::size_t c = 0; c < s.num_cells(); ++c)
    for (int i = 0; i < nn; ++i)
      around[ids[s.cells[c * nn + i]]].emplace_back(
        static_cast<std::int32_t>(c), i);
  return around;
}

/// averaged_normal_derivatives; without @p with_hessian the Hessian is
/// left empty (and its cells' second derivatives are not computed).
NormalDerivatives
normal_derivatives(const FacetSurface& s,
                   std::span<const std::int64_t> ids,
                   const Adjacency& around,
                   std::int64_t node,
                   bool with_hessian = true)
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

/// c_A of one pair as Jets over its slave coordinates, nodal normals and
/// master coordinates (in that order); returns failed projections. Order 1:
/// no Hessian (@p hess untouched). Non-empty @p value_plus: also c⁺_A =
/// ∫ N_A ⟨d⟩ and its gradient (@p grad_plus). Non-empty @p node_weights
/// (ns): the one function Σ_A w_A c_A instead of the ns c_A. The geometry
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
                       bool opposing_normals_only,
                       bool axisymmetric,
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
  std::vector<J> c(weighted ? 1 : ns, J(0.0)),
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
    }
    else
      for (int a = 0; a < ns; ++a)
        c[a] += wd * q.slave_N[a];
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
    opposing_normals_only,
    axisymmetric,
    false, // c_A needs no master shape functions
    lift,
    accumulate);
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
                                       std::span<const double>,
                                       std::span<double>,
                                       std::span<double>,
                                       std::span<double>,
                                       std::span<double>,
                                       std::span<double>);

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
  const bool weighted = !options.node_weights.empty();
  if (weighted and options.node_weights.size() != pairs.size() / 2 * ns)
    throw std::invalid_argument("node_weights must have shape (pairs, " +
                                std::to_string(ns) + ")");
  if (weighted and options.with_positive_part)
    throw std::invalid_argument(
      "node_weights combine c_A only, not the positive part's c⁺_A");
}

} // namespace

NormalDerivatives
averaged_normal_derivatives(const FacetSurface& s,
                            std::span<const std::int64_t> ids,
                            std::int64_t node)
{
  s.check();
  if (ids.size() != s.x.size() / s.gdim)
    throw std::invalid_argument("one id per surface node expected");
  return normal_derivatives(s, ids, node_cells(s, ids), node);
}

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
              node_weights] = options;
  check_input(slave, slave_ids, master, master_ids, pairs, options);
  const int gdim = slave.gdim;
  const int ns = facet_num_nodes(slave.type), nm = facet_num_nodes(master.type);
  const int N = (2 * ns + nm) * gdim;
  const bool weighted = !node_weights.empty();
  // functions per pair: the ns c_A, or their one weighted sum
  const int nf = weighted ? 1 : ns;
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
                                    opposing_normals_only,
                                    axisymmetric,
                                    weighted ? node_weights.subspan(p * ns, ns)
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
