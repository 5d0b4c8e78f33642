// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#include <dolfinx_mortar/clipping.h>
#include <dolfinx_mortar/geometric_tolerance.h>
#include <dolfinx_mortar/mortar_integrals.h>

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
double
dot(const Point3& a, const Point3& b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
Point3
sub(const Point3& a, const Point3& b)
{
  return { a[0] - b[0], a[1] - b[1], a[2] - b[2] };
}
Point3
cross(const Point3& a, const Point3& b)
{
  return { a[1] * b[2] - a[2] * b[1],
           a[2] * b[0] - a[0] * b[2],
           a[0] * b[1] - a[1] * b[0] };
}
double
norm(const Point3& a)
{
  return std::sqrt(dot(a, a));
}

/// A flat piece of a facet: its reference polygon, physical polygon, and the
/// plane (line in 2D) through its centre.
struct SubFacet
{
  std::array<double, 2> reference_centre;
  std::vector<Point3> polygon;
  Point3 centre, normal, e1, e2;
  double size; // length (2D) or area (3D)
};

template<typename Point>
double
longest_edge(const std::vector<Point>& polygon)
{
  double longest = 0;
  for (std::size_t i = 0; i < polygon.size(); ++i)
  {
    const Point& p = polygon[i];
    const Point& q = polygon[(i + 1) % polygon.size()];
    double d = 0;
    for (std::size_t k = 0; k < p.size(); ++k)
      d += (q[k] - p[k]) * (q[k] - p[k]);
    longest = std::max(longest, std::sqrt(d));
  }
  return longest;
}

/// The flat piece of cell @p c over the reference polygon, or nothing when
/// it is degenerate: its length (2D) or its height, twice its area over its
/// longest edge (3D), at most @p zero. Judged against the geometry's zero
/// length, not against the piece's own extent: a collinear triangle has a
/// round-off area that grows with |x|, and a sliver 1e-8 of its length is
/// real input.
std::optional<SubFacet>
make_subfacet(const FacetSurface& s,
              std::size_t c,
              const std::vector<std::array<double, 2>>& reference,
              std::span<double> N,
              std::span<double> dN,
              double zero)
{
  const int tdim = facet_tdim(s.type);
  SubFacet f;
  f.reference_centre = { 0, 0 };
  f.centre = { 0, 0, 0 };
  std::array<Point3, 2> tangents;
  for (const auto& X : reference)
  {
    Point3 x;
    facet_geometry(s, c, std::span(X.data(), tdim), N, dN, x, tangents);
    f.polygon.push_back(x);
    for (int k = 0; k < 3; ++k)
      f.centre[k] += x[k] / reference.size();
    for (int k = 0; k < 2; ++k)
      f.reference_centre[k] += X[k] / reference.size();
  }
  const auto& P = f.polygon;
  // !(a > b) rather than a <= b: NaN is degenerate too
  if (s.gdim == 2)
  {
    const Point3 t = sub(P[1], P[0]);
    f.size = norm(t);
    if (!(f.size > zero))
      return std::nullopt;
    f.e1 = { t[0] / f.size, t[1] / f.size, 0 };
    f.normal = { f.e1[1], -f.e1[0], 0 };
    f.e2 = { 0, 0, 0 };
    return f;
  }
  // |n| is twice the area of a triangle, and of a quadrilateral's projection
  // on the plane normal to n (the cross product of its diagonals)
  Point3 n = P.size() == 3 ? cross(sub(P[1], P[0]), sub(P[2], P[0]))
                           : cross(sub(P[2], P[0]), sub(P[3], P[1]));
  const double n_norm = norm(n);
  if (!(n_norm > zero * longest_edge(P)))
    return std::nullopt;
  for (double& v : n)
    v /= n_norm;
  f.normal = n;
  Point3 e1 = sub(P[1], P[0]);
  const double along = dot(e1, n);
  for (int k = 0; k < 3; ++k)
    e1[k] -= along * n[k];
  const double e1_norm = norm(e1);
  if (!(e1_norm > zero)) // a quadrilateral with a collapsed first edge
    return std::nullopt;
  for (double& v : e1)
    v /= e1_norm;
  f.e1 = e1;
  f.e2 = cross(n, e1);
  // area of the polygon projected on its own plane: |n|/2 up to round-off,
  // so positive after the height test
  std::vector<Point2> flat;
  for (const Point3& p : P)
    flat.push_back(
      { dot(sub(p, f.centre), f.e1), dot(sub(p, f.centre), f.e2) });
  f.size = std::abs(signed_area(flat));
  return f;
}

/// Cells of @p s with a degenerate piece (make_subfacet), in order.
std::vector<std::int32_t>
degenerate_cells(const FacetSurface& s, double zero)
{
  const int nn = facet_num_nodes(s.type), tdim = facet_tdim(s.type);
  std::vector<double> N(nn), dN(tdim * nn);
  std::vector<std::int32_t> out;
  for (std::size_t c = 0; c < s.num_cells(); ++c)
    for (const auto& piece : facet_subfacets(s.type))
      if (!make_subfacet(s, c, piece, N, dN, zero))
      {
        out.push_back(static_cast<std::int32_t>(c));
        break;
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
  const auto& slave_pieces = facet_subfacets(slave.type);
  const auto& master_pieces = facet_subfacets(master.type);
  const std::size_t nq = weights.size();

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
  std::vector<double> Ns(ns), dNs(tdim * ns), Nm(nm), dNm(tdim * nm);
  std::array<Point3, 2> tangents;
  std::vector<SubFacet> master_subfacets;

  for (std::size_t p = 0; p < candidates.size() / 2; ++p)
  {
    const auto cs = static_cast<std::size_t>(candidates[2 * p]);
    const auto cm = static_cast<std::size_t>(candidates[2 * p + 1]);
    if (cs >= slave.num_cells() or cm >= master.num_cells())
      throw std::invalid_argument("candidate pair refers to a missing cell");
    if (skip_slave[cs] or skip_master[cm])
      continue;
    acc.reset();
    master_subfacets.clear();
    for (const auto& piece : master_pieces)
      if (auto f = make_subfacet(master, cm, piece, Nm, dNm, zero))
        master_subfacets.push_back(std::move(*f));

    for (const auto& piece : slave_pieces)
    {
      const auto sf = make_subfacet(slave, cs, piece, Ns, dNs, zero);
      if (!sf)
        continue; // not reached: degenerate cells are skipped above
      auto plane_coords = [&](const Point3& x) -> Point2
      {
        const Point3 r = sub(x, sf->centre);
        return { dot(r, sf->e1), dot(r, sf->e2) };
      };
      std::vector<Point2> slave_polygon;
      for (const Point3& x : sf->polygon)
        slave_polygon.push_back(plane_coords(x));

      for (const SubFacet& mf : master_subfacets)
      {
        // unit normals of non-degenerate pieces: a perpendicular master
        // projects to a segment and covers nothing on either side of 0
        if (options.opposing_normals_only and dot(mf.normal, sf->normal) >= 0)
          continue;
        std::vector<Point2> master_polygon;
        for (const Point3& x : mf.polygon)
          master_polygon.push_back(plane_coords(x));

        // Integration cells in plane coordinates: (origin, edge a, edge b)
        // with measure factor; 2D cells have no edge b.
        struct Cell
        {
          Point2 origin, a, b;
          double measure;
        };
        std::vector<Cell> cells;
        if (gdim == 2)
        {
          const double lo =
            std::max(slave_polygon[0][0],
                     std::min(master_polygon[0][0], master_polygon[1][0]));
          const double hi =
            std::min(slave_polygon[1][0],
                     std::max(master_polygon[0][0], master_polygon[1][0]));
          if (hi - lo > zero)
            cells.push_back({ { lo, 0 }, { hi - lo, 0 }, { 0, 0 }, hi - lo });
        }
        else
        {
          // The slave polygon is counter-clockwise about its own normal by
          // construction; the master one is usually clockwise (it faces the
          // slave) and must be turned for clipping. It is not degenerate, so
          // the sign of its area is not round-off.
          if (signed_area(master_polygon) < 0)
            std::reverse(master_polygon.begin(), master_polygon.end());
          const auto clipped =
            clip_polygon(slave_polygon, master_polygon, zero);
          // an overlap no wider than the zero length is a segment or a
          // point (touching edges, a shared vertex)
          if (clipped.size() < 3 or
              !(2 * signed_area(clipped) > zero * longest_edge(clipped)))
            continue;
          Point2 g = { 0, 0 };
          for (const Point2& q : clipped)
            g = { g[0] + q[0] / clipped.size(), g[1] + q[1] / clipped.size() };
          for (std::size_t i = 0; i < clipped.size(); ++i)
          {
            const Point2& q0 = clipped[i];
            const Point2& q1 = clipped[(i + 1) % clipped.size()];
            const Point2 a = { q0[0] - g[0], q0[1] - g[1] };
            const Point2 b = { q1[0] - g[0], q1[1] - g[1] };
            const double twice_area = a[0] * b[1] - a[1] * b[0];
            // Exact sign test: the polygon is convex, wider than the zero
            // length, and fanned from its centroid, so its fan triangles
            // are positive up to round-off; a round-off one carries a
            // round-off weight whichever way it is decided, while a
            // length-based threshold would drop the fan of a thin overlap.
            if (twice_area > 0)
              cells.push_back({ g, a, b, twice_area });
          }
        }

        for (const Cell& cell : cells)
          for (std::size_t q = 0; q < nq; ++q)
          {
            const double X0 = points[q * tdim];
            const double X1 = tdim == 2 ? points[q * tdim + 1] : 0.0;
            const double u = cell.origin[0] + X0 * cell.a[0] + X1 * cell.b[0];
            const double v = cell.origin[1] + X0 * cell.a[1] + X1 * cell.b[1];
            Point3 x;
            for (int k = 0; k < 3; ++k)
              x[k] = sf->centre[k] + u * sf->e1[k] + v * sf->e2[k];
            const Projection ps =
              project_along(slave, cs, x, sf->normal, sf->reference_centre);
            const Projection pm =
              project_along(master, cm, x, sf->normal, mf.reference_centre);
            if (!ps.converged or !pm.converged)
            {
              ++out.failed_projections;
              continue;
            }
            Point3 xs, xm;
            facet_geometry(
              slave, cs, std::span(ps.X.data(), tdim), Ns, dNs, xs, tangents);
            facet_geometry(
              master, cm, std::span(pm.X.data(), tdim), Nm, dNm, xm, tangents);
            Point3 n = { 0, 0, 0 };
            for (int a = 0; a < ns; ++a)
            {
              const double* na =
                slave_normals.data() + slave.cells[cs * ns + a] * gdim;
              for (int k = 0; k < gdim; ++k)
                n[k] += Ns[a] * na[k];
            }
            // n interpolates unit vectors: its length is dimensionless and
            // of order 1 unless the nodal normals cancel
            const double n_norm = norm(n);
            const bool n_defined = n_norm > geometric_tolerance;
            const Point3 gap_vector = sub(xs, xm);
            const double d = n_defined ? dot(gap_vector, n) / n_norm : 0.0;
            // the surface of revolution's measure 2πr ds: r is the slave
            // point's radius (clamped: a node on the axis may sit at −1e-17)
            const double w
              = weights[q] * cell.measure
                * (options.axisymmetric ? 2 * std::numbers::pi * std::max(xs[0], 0.0) : 1.0);
            acc.add(w, Ns, Nm, d);
            if (options.keep_points)
            {
              // the pair index is the number of pairs stored so far
              out.point_pairs.push_back(
                static_cast<std::int32_t>(out.area.size()));
              out.point_weights.push_back(w);
              out.point_gap.push_back(d);
              for (int k = 0; k < gdim; ++k)
                out.point_normals.push_back(n_defined ? n[k] / n_norm : 0.0);
              out.point_slave_N.insert(
                out.point_slave_N.end(), Ns.begin(), Ns.end());
              out.point_master_N.insert(
                out.point_master_N.end(), Nm.begin(), Nm.end());
            }
          }
      }
    }
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
