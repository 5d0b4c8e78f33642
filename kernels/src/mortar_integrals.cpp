// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#include <dolfinx_mortar/geometric_tolerance.h>
#include <dolfinx_mortar/mortar_integrals.h>
#include <dolfinx_mortar/piece_quadrature.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>

namespace dolfinx_mortar
{
namespace
{
/// Cells of @p s with a degenerate piece (make_subfacet), in order.
std::vector<std::int32_t>
degenerate_cells(const FacetSurface& s, double zero)
{
  const int nn = facet_num_nodes(s.type);
  std::vector<double> nodes(nn * s.gdim);
  std::vector<std::int32_t> out;
  for (std::size_t c = 0; c < s.num_cells(); ++c)
  {
    // relative to the first node: round-off of the cell's size, not of |x|
    gather_cell_nodes(s, c, nodes);
    for (int i = nn * s.gdim - 1; i >= 0; --i)
      nodes[i] -= nodes[i % s.gdim];
    for (const auto& piece : facet_subfacets(s.type))
      if (!make_subfacet<double>(s.type, s.gdim, nodes, piece, zero))
      {
        out.push_back(static_cast<std::int32_t>(c));
        break;
      }
  }
  return out;
}

/// Accumulates the integrals of one slave–master cell pair.
struct PairAccumulator
{
  int ns, nm;
  std::vector<double> D, M, gap;
  double area = 0;
  PairAccumulator(int ns_, int nm_)
    : ns(ns_)
    , nm(nm_)
    , D(ns_ * ns_)
    , M(ns_ * nm_)
    , gap(ns_)
  {
  }
  void reset()
  {
    std::fill(D.begin(), D.end(), 0.0);
    std::fill(M.begin(), M.end(), 0.0);
    std::fill(gap.begin(), gap.end(), 0.0);
    area = 0;
  }
  void add(double w,
           std::span<const double> Ns,
           std::span<const double> Nm,
           double d)
  {
    for (int a = 0; a < ns; ++a)
    {
      const double wa = w * Ns[a];
      for (int b = 0; b < ns; ++b)
        D[a * ns + b] += wa * Ns[b];
      for (int b = 0; b < nm; ++b)
        M[a * nm + b] += wa * Nm[b];
      gap[a] += wa * d;
    }
    area += w;
  }
};
} // namespace

MortarIntegrals
mortar_integrals(const FacetSurface& slave,
                 std::span<const double> slave_normals,
                 const FacetSurface& master,
                 std::span<const std::int32_t> candidates,
                 std::span<const double> points,
                 std::span<const double> weights,
                 const SegmentationOptions& options)
{
  slave.check();
  master.check();
  if (slave.gdim != master.gdim)
    throw std::invalid_argument("slave and master surfaces differ in gdim");
  if (options.axisymmetric and slave.gdim != 2)
    throw std::invalid_argument(
      "axisymmetric integrals need 2D (r, z) surfaces, got gdim " +
      std::to_string(slave.gdim));
  if (slave_normals.size() != slave.x.size())
    throw std::invalid_argument("slave normals must have shape (nodes, gdim)");
  if (candidates.size() % 2 != 0)
    throw std::invalid_argument("candidate pairs must have shape (pairs, 2)");
  const int gdim = slave.gdim, tdim = gdim - 1;
  if (points.size() != weights.size() * tdim)
    throw std::invalid_argument("quadrature points must have shape (points, " +
                                std::to_string(tdim) + ")");
  const int ns = facet_num_nodes(slave.type), nm = facet_num_nodes(master.type);

  // One zero length for every decision of this call: from the caller (the
  // same on every rank) or from both surfaces' coordinates.
  double zero;
  if (options.length_scale > 0)
    zero = std::max(geometric_tolerance * options.length_scale,
                    std::numeric_limits<double>::min());
  else
  {
    std::vector<double> both(slave.x.begin(), slave.x.end());
    both.insert(both.end(), master.x.begin(), master.x.end());
    zero = zero_length(both, gdim);
  }

  MortarIntegrals out;
  out.gdim = slave.gdim;
  out.slave_nodes = facet_num_nodes(slave.type);
  out.master_nodes = facet_num_nodes(master.type);
  out.degenerate_slave_facets = degenerate_cells(slave, zero);
  out.degenerate_master_facets = degenerate_cells(master, zero);
  // a degenerate cell covers nothing and is covered by nothing
  std::vector<char> skip_slave(slave.num_cells(), 0),
    skip_master(master.num_cells(), 0);
  for (std::int32_t c : out.degenerate_slave_facets)
    skip_slave[c] = 1;
  for (std::int32_t c : out.degenerate_master_facets)
    skip_master[c] = 1;
  PairAccumulator acc(ns, nm);
  std::vector<double> slave_nodes(ns * gdim), normals(ns * gdim),
    master_nodes(nm * gdim);
  // Every pair is segmented in coordinates relative to a local origin, its
  // slave cell's first node, so that round-off scales with the cells' size,
  // not with their distance from the origin (docs/DESIGN.md, §Tolerances): a
  // scene shifted by 1e8 gives the pairs and integrals of the scene at the
  // origin. Axisymmetric integrals weigh by the radius, which a shift in r
  // would change: there only z is shifted.
  auto local_origin = [&](const FacetSurface& s, std::size_t c)
  {
    Vec3<double> o = { 0.0, 0.0, 0.0 };
    for (int k = options.axisymmetric ? 1 : 0; k < gdim; ++k)
      o[k] = s.x[s.cells[c * facet_num_nodes(s.type)] * gdim + k];
    return o;
  };
  auto gather_local = [&](const FacetSurface& s,
                          std::size_t c,
                          const Vec3<double>& o,
                          std::span<double> nodes)
  {
    gather_cell_nodes(s, c, nodes);
    for (std::size_t i = 0; i < nodes.size(); ++i)
      nodes[i] -= o[i % gdim];
  };
  // Each cell's flat pieces, built when a candidate first meets it, in the
  // frame of its own local origin: most candidates are rejected, and
  // building the pieces was half their cost. A master cell's pieces are
  // translated into the slave cell's frame for each pair.
  std::vector<std::optional<std::vector<SubFacet<double>>>> slave_pieces(
    slave.num_cells()),
    master_pieces(master.num_cells());
  auto pieces_of =
    [&](auto& cache,
        const FacetSurface& s,
        std::size_t c,
        std::span<const double> nodes) -> const std::vector<SubFacet<double>>&
  {
    if (!cache[c])
      cache[c] = cell_pieces<double>(s.type, gdim, nodes, zero);
    return *cache[c];
  };
  std::vector<double> own_master_nodes(nm * gdim);
  std::vector<SubFacet<double>> moved_master_pieces;
  auto master_pieces_in = [&](std::size_t c, const Vec3<double>& o)
    -> const std::vector<SubFacet<double>>&
  {
    const Vec3<double> own = local_origin(master, c);
    if (!master_pieces[c])
    {
      gather_local(master, c, own, own_master_nodes);
      pieces_of(master_pieces, master, c, own_master_nodes);
    }
    const Vec3<double> shift = vec3::sub(own, o);
    moved_master_pieces = *master_pieces[c];
    for (SubFacet<double>& piece : moved_master_pieces)
    {
      for (Vec3<double>& v : piece.polygon)
        v = vec3::add(v, shift);
      piece.centre = vec3::add(piece.centre, shift);
    }
    return moved_master_pieces;
  };
  // the slave pieces' projection directions: the nodal normals interpolated
  // at each piece's centre
  auto slave_pieces_of =
    [&](std::size_t c,
        std::span<const double> nodes) -> const std::vector<SubFacet<double>>&
  {
    const bool made = slave_pieces[c].has_value();
    auto& pieces = pieces_of(slave_pieces, slave, c, nodes);
    if (made or !options.project_along_normals)
      return pieces;
    std::array<double, 9> N;
    std::array<double, 18> dN;
    for (SubFacet<double>& piece : *slave_pieces[c])
    {
      facet_shape_functions(slave.type,
                            std::span(piece.reference_centre.data(), tdim),
                            std::span(N.data(), ns),
                            std::span(dN.data(), tdim * ns));
      Vec3<double> m = { 0.0, 0.0, 0.0 };
      for (int a = 0; a < ns; ++a)
        for (int k = 0; k < gdim; ++k)
          m[k] += N[a] * slave_normals[slave.cells[c * ns + a] * gdim + k];
      const double length = vec3::norm(m);
      if (length > geometric_tolerance)
      {
        for (double& v : m)
          v /= length;
        set_projection_direction(piece, m, 0.5);
      }
    }
    return *slave_pieces[c];
  };

  for (std::size_t p = 0; p < candidates.size() / 2; ++p)
  {
    const auto cs = static_cast<std::size_t>(candidates[2 * p]);
    const auto cm = static_cast<std::size_t>(candidates[2 * p + 1]);
    if (cs >= slave.num_cells() or cm >= master.num_cells())
      throw std::invalid_argument("candidate pair refers to a missing cell");
    if (skip_slave[cs] or skip_master[cm])
      continue;
    acc.reset();
    const Vec3<double> origin = local_origin(slave, cs);
    gather_local(slave, cs, origin, slave_nodes);
    gather_local(master, cm, origin, master_nodes);
    for (int a = 0; a < ns; ++a)
      std::copy_n(slave_normals.data() + slave.cells[cs * ns + a] * gdim,
                  gdim,
                  normals.begin() + a * gdim);
    out.failed_projections += integrate_pieces<double, double>(
      slave.type,
      master.type,
      gdim,
      std::span<const double>(slave_nodes),
      std::span<const double>(normals),
      std::span<const double>(master_nodes),
      slave_pieces_of(cs, slave_nodes),
      master_pieces_in(cm, origin),
      points,
      weights,
      zero,
      options.keep_slivers,
      options.opposing_normals_only,
      options.axisymmetric,
      true,
      [](double x) { return x; },
      [&](const SegmentPoint<double>& q)
      {
        acc.add(q.weight, q.slave_N, q.master_N, q.gap);
        if (options.keep_points)
        {
          // the pair index is the number of pairs stored so far
          out.point_pairs.push_back(static_cast<std::int32_t>(out.area.size()));
          out.point_weights.push_back(q.weight);
          out.point_gap.push_back(q.gap);
          for (int k = 0; k < gdim; ++k)
            out.point_normals.push_back(
              q.normal_defined ? q.normal[k] / q.normal_norm : 0.0);
          out.point_slave_N.insert(
            out.point_slave_N.end(), q.slave_N.begin(), q.slave_N.end());
          out.point_master_N.insert(
            out.point_master_N.end(), q.master_N.begin(), q.master_N.end());
        }
      });
    // acc.area sums positive weights × positive measures: it is exactly 0
    // when no point was integrated, and only then
    if (acc.area <= 0 and options.keep_points)
    {
      // drop the points of a pair that is not kept
      const auto first = std::find(out.point_pairs.begin(),
                                   out.point_pairs.end(),
                                   static_cast<std::int32_t>(out.area.size()));
      const auto n = static_cast<std::size_t>(out.point_pairs.end() - first);
      out.point_pairs.resize(out.point_pairs.size() - n);
      out.point_weights.resize(out.point_weights.size() - n);
      out.point_gap.resize(out.point_gap.size() - n);
      out.point_normals.resize(out.point_normals.size() - n * gdim);
      out.point_slave_N.resize(out.point_slave_N.size() - n * ns);
      out.point_master_N.resize(out.point_master_N.size() - n * nm);
    }
    if (acc.area > 0)
    {
      out.pairs.push_back(static_cast<std::int32_t>(cs));
      out.pairs.push_back(static_cast<std::int32_t>(cm));
      out.D.insert(out.D.end(), acc.D.begin(), acc.D.end());
      out.M.insert(out.M.end(), acc.M.begin(), acc.M.end());
      out.gap.insert(out.gap.end(), acc.gap.begin(), acc.gap.end());
      out.area.push_back(acc.area);
    }
  }
  return out;
}

} // namespace dolfinx_mortar
