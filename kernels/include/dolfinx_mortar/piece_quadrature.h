// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

// The quadrature of one slave–master cell pair over the overlaps of their
// flat pieces (pair_segmentation.h), written once for any Scalar: the
// overlap of two pieces, its flat path (both cells affine: everything is
// affine in the slave plane coordinates and interpolated from the overlap's
// vertices) and its general path (every point projected onto both cells).

#include "flat_pieces.h"
#include "pair_segmentation.h"
#include "piece_overlap.h"

#include <algorithm>
#include <cstdint>
#include <numbers>
#include <span>
#include <type_traits>
#include <vector>

namespace dolfinx_mortar
{

/// What one segment quadrature point gives its callback.
template<Scalar T>
struct SegmentPoint
{
  T weight;                    ///< quadrature weight × measure
  std::span<const T> slave_N;  ///< N_A at the slave point
  std::span<const T> master_N; ///< N^m_C at the master point (if asked for)
  T gap;                       ///< d = (x_s − x_m)·n/|n|
  Vec3<T> normal;              ///< interpolated nodal normal n (not unit)
  T normal_norm;               ///< |n|
  bool normal_defined;         ///< |n| above the geometric tolerance
};

/// The quadrature of one slave–master cell pair's overlaps (see
/// integrate_pieces): what every overlap of the pair shares, and the two
/// ways of integrating one.
template<Scalar T, Scalar G, typename Lift, typename OnPoint>
class PieceIntegrator
{
public:
  PieceIntegrator(FacetType slave_type,
                  FacetType master_type,
                  int gdim,
                  std::span<const G> slave_nodes,
                  std::span<const T> slave_normals,
                  std::span<const G> master_nodes,
                  std::span<const double> points,
                  std::span<const double> weights,
                  bool axisymmetric,
                  bool with_master_N,
                  Lift& lift,
                  OnPoint& on_point)
    : slave_type(slave_type)
    , master_type(master_type)
    , gdim(gdim)
    , tdim(gdim - 1)
    , ns(facet_num_nodes(slave_type))
    , nm(facet_num_nodes(master_type))
    , nm_out(with_master_N ? nm : 0)
    , slave_nodes(slave_nodes)
    , slave_normals(slave_normals)
    , master_nodes(master_nodes)
    , points(points)
    , weights(weights)
    , axisymmetric(axisymmetric)
    , lift(lift)
    , on_point(on_point)
    , NsG(ns)
    , dNs(tdim * ns)
    , NmG(nm)
    , dNm(tdim * nm)
    , Ns(ns)
    , Nm(nm)
  {
  }

  /// Both cells affine: the reference coordinates, the distance t to the
  /// master plane along the projection direction m and the interpolated
  /// normal are affine in the plane coordinates. They are found at the
  /// overlap's vertices and interpolated at the quadrature points, where only
  /// |n| and the gap's products remain: for a Jet, a tenth of the
  /// projections' products per point. The slave point is x itself (the slave
  /// plane holds the slave cell), so x_s − x_m = −t·m.
  /// @param[in] slave_map The slave piece's reference coordinates (affine)
  /// @param[in] direction The projection direction m, lifted
  void flat(const SubFacet<G>& sf,
            const std::array<PlaneAffine<G>, 2>& slave_map,
            const Vec3<T>& direction,
            const SubFacet<G>& mf,
            const Overlap<G>& overlap)
  {
    using namespace vec3;
    const bool with_master_N = nm_out > 0;
    const std::array<PlaneAffine<G>, 3> master_map =
      master_from_plane(sf, mf.polygon, tdim);
    std::vector<FlatPoint<T>> at(overlap.vertices.size());
    for (std::size_t i = 0; i < overlap.vertices.size(); ++i)
    {
      const std::array<G, 2>& p = overlap.vertices[i];
      FlatPoint<T>& f = at[i];
      std::array<G, 2> Xs, Xm;
      for (int k = 0; k < tdim; ++k)
        Xs[k] = slave_map[k].at(p);
      f.t = lift(master_map[tdim].at(p));
      shape_functions<G>(
        slave_type, std::span<const G>(Xs.data(), tdim), NsG, dNs);
      for (int a = 0; a < ns; ++a)
        f.Ns[a] = lift(NsG[a]);
      if (with_master_N)
      {
        for (int k = 0; k < tdim; ++k)
          Xm[k] = master_map[k].at(p);
        shape_functions<G>(
          master_type, std::span<const G>(Xm.data(), tdim), NmG, dNm);
        for (int c = 0; c < nm; ++c)
          f.Nm[c] = lift(NmG[c]);
      }
      for (int a = 0; a < ns; ++a)
        for (int k = 0; k < gdim; ++k)
          f.n[k] += f.Ns[a] * slave_normals[a * gdim + k];
      f.s = dot(direction, f.n);
      if (axisymmetric)
        f.r = lift(sf.centre[0] + p[0] * sf.e1[0] + p[1] * sf.e2[0]);
    }
    for (const OverlapCell<G>& cell : overlap.cells)
    {
      const T measure = lift(cell.measure);
      for (std::size_t q = 0; q < weights.size(); ++q)
      {
        const double X0 = points[q * tdim];
        const double X1 = tdim == 2 ? points[q * tdim + 1] : 0.0;
        const FlatPoint<T> f = interpolate<T>(
          { &at[cell.vertex[0]], &at[cell.vertex[1]], &at[cell.vertex[2]] },
          { 1 - X0 - X1, X0, X1 },
          tdim + 1,
          ns,
          nm_out,
          axisymmetric);
        const T n_norm = norm(f.n);
        const bool n_defined = value(n_norm) > geometric_tolerance;
        const T d = n_defined ? T(-(f.t * f.s) / n_norm) : T(0.0);
        T w = weights[q] * measure;
        if (axisymmetric)
          w = w * (2 * std::numbers::pi * larger(f.r, T(0.0)));
        on_point(SegmentPoint<T>{ w,
                                  std::span<const T>(f.Ns.data(), ns),
                                  std::span<const T>(f.Nm.data(), nm_out),
                                  d,
                                  f.n,
                                  n_norm,
                                  n_defined });
      }
    }
  }

  /// Curved cells: every quadrature point is projected onto both cells
  /// along the slave piece's direction (Newton on the values; Jets then take
  /// the steps that carry the derivatives).
  /// @return The number of points whose projection failed (skipped)
  std::int64_t general(const SubFacet<G>& sf,
                       const SubFacet<G>& mf,
                       const Overlap<G>& overlap)
  {
    using namespace vec3;
    if (slave_values.empty())
    {
      for (const G& v : slave_nodes)
        slave_values.push_back(value(v));
      for (const G& v : master_nodes)
        master_values.push_back(value(v));
    }
    std::int64_t failed = 0;
    const Point3 direction = values(sf.direction);
    std::array<Vec3<G>, 2> tangents;
    for (const OverlapCell<G>& cell : overlap.cells)
      for (std::size_t q = 0; q < weights.size(); ++q)
      {
        const double X0 = points[q * tdim];
        const double X1 = tdim == 2 ? points[q * tdim + 1] : 0.0;
        const G u = cell.origin[0] + X0 * cell.a[0] + X1 * cell.b[0];
        const G v = cell.origin[1] + X0 * cell.a[1] + X1 * cell.b[1];
        Vec3<G> x;
        for (int k = 0; k < 3; ++k)
          x[k] = sf.centre[k] + u * sf.e1[k] + v * sf.e2[k];
        const Point3 xv = values(x);
        const Projection ps = project_along(
          slave_type, gdim, slave_values, xv, direction, sf.reference_centre);
        const Projection pm = project_along(
          master_type, gdim, master_values, xv, direction, mf.reference_centre);
        if (!ps.converged or !pm.converged)
        {
          ++failed;
          continue;
        }
        std::array<G, 2> Xs, Xm;
        if constexpr (std::is_same_v<G, double>)
        {
          Xs = ps.X;
          Xm = pm.X;
        }
        else
        {
          Xs = refine_projection<G>(
                 slave_type, gdim, slave_nodes, x, sf.direction, ps)
                 .first;
          Xm = refine_projection<G>(
                 master_type, gdim, master_nodes, x, sf.direction, pm)
                 .first;
        }
        Vec3<G> xs, xm;
        cell_geometry<G>(slave_type,
                         gdim,
                         slave_nodes,
                         std::span<const G>(Xs.data(), tdim),
                         NsG,
                         dNs,
                         xs,
                         tangents);
        cell_geometry<G>(master_type,
                         gdim,
                         master_nodes,
                         std::span<const G>(Xm.data(), tdim),
                         NmG,
                         dNm,
                         xm,
                         tangents);
        for (int a = 0; a < ns; ++a)
          Ns[a] = lift(NsG[a]);
        for (int c = 0; c < nm_out; ++c)
          Nm[c] = lift(NmG[c]);
        Vec3<T> n = { 0.0, 0.0, 0.0 };
        for (int a = 0; a < ns; ++a)
          for (int k = 0; k < gdim; ++k)
            n[k] += Ns[a] * slave_normals[a * gdim + k];
        // n interpolates unit vectors: its length is dimensionless and of
        // order 1 unless the nodal normals cancel
        const T n_norm = norm(n);
        const bool n_defined = value(n_norm) > geometric_tolerance;
        const Vec3<G> gap = sub(xs, xm);
        const Vec3<T> gap_vector = { lift(gap[0]), lift(gap[1]), lift(gap[2]) };
        const T d = n_defined ? T(dot(gap_vector, n) / n_norm) : T(0.0);
        T w = weights[q] * lift(cell.measure);
        // the surface of revolution's measure 2πr ds: r is the slave point's
        // radius (clamped: a node on the axis may sit at −1e-17)
        if (axisymmetric)
          w = w * (2 * std::numbers::pi * larger(lift(xs[0]), T(0.0)));
        on_point(SegmentPoint<T>{ w,
                                  Ns,
                                  std::span<const T>(Nm.data(), nm_out),
                                  d,
                                  n,
                                  n_norm,
                                  n_defined });
      }
    return failed;
  }

private:
  FacetType slave_type, master_type;
  int gdim, tdim, ns, nm, nm_out;
  std::span<const G> slave_nodes;
  std::span<const T> slave_normals;
  std::span<const G> master_nodes;
  std::span<const double> points, weights;
  bool axisymmetric;
  Lift& lift;
  OnPoint& on_point;
  // scratch of the shape functions, and the nodes' values for the general
  // path's Newton projections (made when it first runs)
  std::vector<G> NsG, dNs, NmG, dNm;
  std::vector<T> Ns, Nm;
  std::vector<double> slave_values, master_values;
};

/// Segment one slave–master cell pair and call @p on_point at every
/// segment quadrature point (see mortar_integrals for the construction).
///
/// @param[in] slave_nodes, master_nodes Node coordinates (nodes, gdim)
/// @param[in] slave_normals Unit nodal normals of the slave cell (nodes,
/// gdim)
/// @param[in] slave_pieces, master_pieces cell_pieces of the same nodes: a
/// caller that meets a cell in many pairs builds them once
/// @param[in] zero The zero length of every geometric decision
/// @param[in] keep_slivers Integrate overlaps of any positive width (see
/// overlap_of)
/// @param[in] with_master_N Give the callback the master's shape
/// functions (else SegmentPoint::master_N is empty)
/// @param[in] lift G → T (the identity for values)
/// @return The number of quadrature points whose projection failed
/// (skipped)
///
/// The geometry (pieces, clipping, projections) is computed in the scalar
/// type @p G of the node coordinates, and only what meets the nodal
/// normals in @p T, through @p lift (G → T). With Jets, G carries the
/// coordinates' derivatives alone: two thirds of the variables of a 3D
/// pair, and under half the cost of each Hessian product. Values: G = T.
template<Scalar T, Scalar G, typename Lift, typename OnPoint>
std::int64_t
integrate_pieces(FacetType slave_type,
                 FacetType master_type,
                 int gdim,
                 std::span<const G> slave_nodes,
                 std::span<const T> slave_normals,
                 std::span<const G> master_nodes,
                 const std::vector<SubFacet<G>>& slave_pieces,
                 const std::vector<SubFacet<G>>& master_pieces,
                 std::span<const double> points,
                 std::span<const double> weights,
                 double zero,
                 bool keep_slivers,
                 bool opposing_normals_only,
                 bool axisymmetric,
                 bool with_master_N,
                 Lift&& lift,
                 OnPoint&& on_point)
{
  using P2 = std::array<G, 2>;
  const int tdim = gdim - 1;
  PieceIntegrator<T,
                  G,
                  std::remove_reference_t<Lift>,
                  std::remove_reference_t<OnPoint>>
    integrator(slave_type,
               master_type,
               gdim,
               slave_nodes,
               slave_normals,
               master_nodes,
               points,
               weights,
               axisymmetric,
               with_master_N,
               lift,
               on_point);
  // affine cells are their own single flat piece (facet_subfacets)
  const bool flat =
    facet_is_affine(slave_type) and facet_is_affine(master_type);
  std::int64_t failed = 0;
  for (const SubFacet<G>& sf : slave_pieces)
  {
    std::vector<P2> slave_polygon;
    for (const Vec3<G>& x : sf.polygon)
      slave_polygon.push_back(sf.plane_coordinates(x));
    // the flat path's slave map and direction, made when a piece pair first
    // overlaps (most candidate pairs do not)
    std::array<PlaneAffine<G>, 2> slave_map;
    Vec3<T> direction{};
    bool slave_map_made = false;
    for (const SubFacet<G>& mf : master_pieces)
    {
      // unit normals of non-degenerate pieces: a perpendicular master
      // projects to a segment and covers nothing on either side of 0
      if (opposing_normals_only and value(vec3::dot(mf.normal, sf.normal)) >= 0)
        continue;
      std::vector<P2> master_polygon;
      for (const Vec3<G>& x : mf.polygon)
        master_polygon.push_back(sf.plane_coordinates(x));
      const Overlap<G> overlap = overlap_of<G>(
        gdim, slave_polygon, std::move(master_polygon), zero, keep_slivers);
      if (overlap.cells.empty())
        continue;
      if (!flat)
      {
        failed += integrator.general(sf, mf, overlap);
        continue;
      }
      if (!slave_map_made)
      {
        slave_map = reference_from_plane(slave_polygon, tdim);
        for (int k = 0; k < 3; ++k)
          direction[k] = lift(sf.direction[k]);
        slave_map_made = true;
      }
      integrator.flat(sf, slave_map, direction, mf, overlap);
    }
  }
  return failed;
}

} // namespace dolfinx_mortar
