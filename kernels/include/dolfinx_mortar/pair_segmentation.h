// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

// The segmentation and integration of one slave–master cell pair, written
// once for any scalar type: double gives the values (mortar_integrals), a
// Jet gives the same values with their exact first and second derivatives
// with respect to the pair's node coordinates and nodal normals
// (current_pair_gaps). Every branch is decided on values, so that both
// instantiations take the same branches.

#include "clipping.h"
#include "facet_element.h"
#include "geometric_tolerance.h"
#include "jet.h"
#include "surface_geometry.h"

#include <algorithm>
#include <cstdint>
#include <numbers>
#include <optional>
#include <span>
#include <type_traits>
#include <vector>

namespace dolfinx_mortar
{

template<typename T>
using Vec3 = std::array<T, 3>;

namespace vec3
{
template<typename T>
T
dot(const Vec3<T>& a, const Vec3<T>& b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
template<typename T>
Vec3<T>
sub(const Vec3<T>& a, const Vec3<T>& b)
{
  return { a[0] - b[0], a[1] - b[1], a[2] - b[2] };
}
template<typename T>
Vec3<T>
cross(const Vec3<T>& a, const Vec3<T>& b)
{
  return { a[1] * b[2] - a[2] * b[1],
           a[2] * b[0] - a[0] * b[2],
           a[0] * b[1] - a[1] * b[0] };
}
template<typename T>
T
norm(const Vec3<T>& a)
{
  return sqrt(dot(a, a));
}
template<typename T>
Point3
values(const Vec3<T>& a)
{
  return { value(a[0]), value(a[1]), value(a[2]) };
}
} // namespace vec3

/// |a|, with the sign decided on the value.
template<typename T>
T
absolute(const T& a)
{
  return value(a) < 0 ? T(-a) : a;
}

/// y += c·x without a temporary (a Jet's copy costs as much as its scaling).
inline void
add_scaled(double& y, double c, double x)
{
  y += c * x;
}
template<int N, int Order>
void
add_scaled(Jet<N, Order>& y, double c, const Jet<N, Order>& x)
{
  y.add_scaled(c, x);
}

/// Position x(X) and tangents ∂x/∂X_k of a cell given by its node
/// coordinates @p nodes (nodes, gdim); 2D: z = 0.
template<typename T>
void
cell_geometry(FacetType type,
              int gdim,
              std::span<const T> nodes,
              std::span<const T> X,
              std::span<T> N,
              std::span<T> dN,
              Vec3<T>& x,
              std::array<Vec3<T>, 2>& tangents)
{
  const int nn = facet_num_nodes(type), tdim = facet_tdim(type);
  shape_functions<T>(type, X, N, dN);
  x = { 0.0, 0.0, 0.0 };
  tangents = { Vec3<T>{ 0.0, 0.0, 0.0 }, Vec3<T>{ 0.0, 0.0, 0.0 } };
  for (int i = 0; i < nn; ++i)
  {
    const T* xi = nodes.data() + i * gdim;
    for (int k = 0; k < gdim; ++k)
    {
      x[k] += N[i] * xi[k];
      for (int j = 0; j < tdim; ++j)
        tangents[j][k] += dN[j * nn + i] * xi[k];
    }
  }
}

/// Normal from tangents with length |J| (2D: (t_y, -t_x), 3D: t0 × t1; only
/// tangents[0] is used in 2D).
template<typename T>
Vec3<T>
size_weighted_normal(int gdim, const std::array<Vec3<T>, 2>& t)
{
  if (gdim == 2)
    return { t[0][1], -t[0][0], 0.0 };
  return vec3::cross(t[0], t[1]);
}

/// A flat piece of a facet: its reference polygon's centre, its physical
/// polygon, and the plane (line in 2D) through its centre.
template<typename T>
struct SubFacet
{
  std::array<double, 2> reference_centre;
  std::vector<Vec3<T>> polygon;
  Vec3<T> centre, normal, e1, e2;
  T size; ///< length (2D) or area (3D)
  /// The direction master points are projected along onto the piece's
  /// plane: its normal, unless set_projection_direction tilted it.
  Vec3<T> direction;
  bool oblique = false; ///< direction is not the normal

  /// Plane coordinates (along e1, e2) of the point x projected on the plane
  /// along the direction.
  std::array<T, 2> plane_coordinates(const Vec3<T>& x) const
  {
    Vec3<T> r = vec3::sub(x, centre);
    if (oblique)
    {
      const T along = vec3::dot(r, normal) / vec3::dot(direction, normal);
      for (int k = 0; k < 3; ++k)
        r[k] -= along * direction[k];
    }
    return { vec3::dot(r, e1), vec3::dot(r, e2) };
  }
};

/// Project master points onto the piece along the unit vector @p m instead
/// of its normal (kept when m is within @p min_cosine of the plane: the
/// projection would stretch the master without bound).
template<typename T>
void
set_projection_direction(SubFacet<T>& f, const Vec3<T>& m, double min_cosine)
{
  if (!(value(vec3::dot(m, f.normal)) > min_cosine))
    return;
  f.direction = m;
  f.oblique = true;
}

/// The longest edge of a polygon, on the values (it only takes decisions).
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
      d += (value(q[k]) - value(p[k])) * (value(q[k]) - value(p[k]));
    longest = std::max(longest, std::sqrt(d));
  }
  return longest;
}

/// The flat piece of a cell (node coordinates @p nodes) over the reference
/// polygon, or nothing when it is degenerate: its length (2D) or its height,
/// twice its area over its longest edge (3D), at most @p zero. Judged
/// against the geometry's zero length, not against the piece's own extent:
/// a collinear triangle has a round-off area that grows with |x|, and a
/// sliver 1e-8 of its length is real input.
template<typename T>
std::optional<SubFacet<T>>
make_subfacet(FacetType type,
              int gdim,
              std::span<const T> nodes,
              const std::vector<std::array<double, 2>>& reference,
              double zero)
{
  using namespace vec3;
  const int tdim = facet_tdim(type), nn = facet_num_nodes(type);
  // the reference points are numbers: their shape functions are too, and
  // the tangents are not needed
  std::array<double, 9> N;   // at most 9 nodes
  std::array<double, 18> dN; // tdim × nodes
  SubFacet<T> f;
  f.reference_centre = { 0, 0 };
  f.centre = { 0.0, 0.0, 0.0 };
  f.polygon.reserve(reference.size());
  for (const auto& X : reference)
  {
    facet_shape_functions(type,
                          std::span(X.data(), tdim),
                          std::span(N.data(), nn),
                          std::span(dN.data(), tdim * nn));
    Vec3<T> x = { 0.0, 0.0, 0.0 };
    for (int i = 0; i < nn; ++i)
      for (int k = 0; k < gdim; ++k)
        add_scaled(x[k], N[i], nodes[i * gdim + k]);
    f.polygon.push_back(x);
    for (int k = 0; k < 3; ++k)
      f.centre[k] += x[k] / static_cast<double>(reference.size());
    for (int k = 0; k < 2; ++k)
      f.reference_centre[k] += X[k] / reference.size();
  }
  const auto& P = f.polygon;
  // !(a > b) rather than a <= b: NaN is degenerate too
  if (gdim == 2)
  {
    const Vec3<T> t = sub(P[1], P[0]);
    f.size = norm(t);
    if (!(value(f.size) > zero))
      return std::nullopt;
    f.e1 = { t[0] / f.size, t[1] / f.size, 0.0 };
    f.normal = { f.e1[1], -f.e1[0], 0.0 };
    f.e2 = { 0.0, 0.0, 0.0 };
    f.direction = f.normal;
    return f;
  }
  // |n| is twice the area of a triangle, and of a quadrilateral's projection
  // on the plane normal to n (the cross product of its diagonals)
  Vec3<T> n = P.size() == 3 ? cross(sub(P[1], P[0]), sub(P[2], P[0]))
                            : cross(sub(P[2], P[0]), sub(P[3], P[1]));
  const T n_norm = norm(n);
  if (!(value(n_norm) > zero * longest_edge(P)))
    return std::nullopt;
  for (T& v : n)
    v /= n_norm;
  f.normal = n;
  Vec3<T> e1 = sub(P[1], P[0]);
  const T along = dot(e1, n);
  for (int k = 0; k < 3; ++k)
    e1[k] -= along * n[k];
  const T e1_norm = norm(e1);
  if (!(value(e1_norm) > zero)) // a quadrilateral with a collapsed first edge
    return std::nullopt;
  for (T& v : e1)
    v /= e1_norm;
  f.e1 = e1;
  f.e2 = cross(n, e1);
  // area of the polygon projected on its own plane: |n|/2 up to round-off,
  // so positive after the height test
  std::vector<std::array<T, 2>> flat;
  for (const Vec3<T>& p : P)
    flat.push_back(
      { dot(sub(p, f.centre), f.e1), dot(sub(p, f.centre), f.e2) });
  f.size = absolute(signed_area(flat));
  f.direction = f.normal;
  return f;
}

/// Two Newton steps for x(X) = p + t·direction from a projection converged
/// on the values: the first makes the first derivatives of (X, t) exact,
/// the second the second derivatives (the implicit function theorem; Newton's
/// map has zero slope at its root). The 2×2 or 3×3 systems are solved by
/// Cramer's rule, which any scalar type can carry.
template<typename T>
std::pair<std::array<T, 2>, T>
refine_projection(FacetType type,
                  int gdim,
                  std::span<const T> nodes,
                  const Vec3<T>& p,
                  const Vec3<T>& direction,
                  const Projection& start)
{
  const int tdim = facet_tdim(type), nn = facet_num_nodes(type);
  std::array<T, 2> X = { start.X[0], start.X[1] };
  T t = start.t;
  std::vector<T> N(nn), dN(tdim * nn);
  // On an affine cell the system is linear in (X, t): one step solves it
  // exactly, derivatives of every order included.
  for (int step = 0; step < (facet_is_affine(type) ? 1 : 2); ++step)
  {
    Vec3<T> x;
    std::array<Vec3<T>, 2> tangents;
    cell_geometry<T>(type,
                     gdim,
                     nodes,
                     std::span<const T>(X.data(), tdim),
                     N,
                     dN,
                     x,
                     tangents);
    Vec3<T> F;
    for (int k = 0; k < gdim; ++k)
      F[k] = x[k] - p[k] - t * direction[k];
    const auto& a = tangents[0];
    if (gdim == 2)
    {
      // columns (a, −direction)
      const T det = a[0] * (-direction[1]) + a[1] * direction[0];
      const T d0 = (F[0] * (-direction[1]) + F[1] * direction[0]) / det;
      const T d1 = (a[0] * F[1] - F[0] * a[1]) / det;
      X[0] -= d0;
      t -= d1;
      continue;
    }
    const auto& b = tangents[1];
    const Vec3<T> c = { -direction[0], -direction[1], -direction[2] };
    // Cramer: δ_j = det(J with column j replaced by F) / det J
    const T det = vec3::dot(a, vec3::cross(b, c));
    const T d0 = vec3::dot(F, vec3::cross(b, c)) / det;
    const T d1 = vec3::dot(a, vec3::cross(F, c)) / det;
    const T d2 = vec3::dot(a, vec3::cross(b, F)) / det;
    X[0] -= d0;
    X[1] -= d1;
    t -= d2;
  }
  return { X, t };
}

/// a + a_u·u + a_v·v: a field affine in the slave plane coordinates (u, v).
template<typename T>
struct PlaneAffine
{
  T a, a_u, a_v;
  T at(const std::array<T, 2>& p) const { return a + a_u * p[0] + a_v * p[1]; }
};

/// The reference coordinates of an affine slave cell as functions of its
/// plane coordinates, from its vertices there (in reference order); the
/// second is zero on a line.
template<typename T>
std::array<PlaneAffine<T>, 2>
reference_from_plane(const std::vector<std::array<T, 2>>& vertices, int tdim)
{
  const std::array<T, 2>& P0 = vertices[0];
  if (tdim == 1)
  {
    const T inverse = 1.0 / (vertices[1][0] - P0[0]);
    return { PlaneAffine<T>{ -(P0[0] * inverse), inverse, T(0.0) },
             PlaneAffine<T>{ T(0.0), T(0.0), T(0.0) } };
  }
  // X = E⁻¹ (p − P0), E = [P1 − P0, P2 − P0]: not singular, as the piece
  // passed make_subfacet's height test
  const T e00 = vertices[1][0] - P0[0], e01 = vertices[2][0] - P0[0];
  const T e10 = vertices[1][1] - P0[1], e11 = vertices[2][1] - P0[1];
  const T inverse = 1.0 / (e00 * e11 - e01 * e10);
  const T i00 = e11 * inverse, i01 = -(e01 * inverse);
  const T i10 = -(e10 * inverse), i11 = e00 * inverse;
  return { PlaneAffine<T>{ -(i00 * P0[0] + i01 * P0[1]), i00, i01 },
           PlaneAffine<T>{ -(i10 * P0[0] + i11 * P0[1]), i10, i11 } };
}

/// (X_m, t) with x_m(X_m) = x + t·m, x = centre + u·e1 + v·e2, for a flat
/// master piece with vertices @p Q (in reference order) and the slave piece
/// @p sf with projection direction m: the master's reference coordinates
/// then t, as functions of (u, v). The system is linear; its matrix
/// [∂x_m/∂X_m, −m] is not singular when the master's projection on the slave
/// plane has an area, which the clipping has established.
template<typename T>
std::array<PlaneAffine<T>, 3>
master_from_plane(const SubFacet<T>& sf,
                  const std::vector<Vec3<T>>& Q,
                  int tdim)
{
  using namespace vec3;
  const Vec3<T> c = { -sf.direction[0], -sf.direction[1], -sf.direction[2] };
  const Vec3<T> a = sub(Q[1], Q[0]);
  // rows of the inverse matrix times its determinant
  std::array<Vec3<T>, 3> rows;
  T det;
  if (tdim == 1)
  {
    det = a[0] * c[1] - a[1] * c[0];
    rows[0] = { c[1], -c[0], 0.0 };
    rows[1] = { -a[1], a[0], 0.0 };
  }
  else
  {
    const Vec3<T> b = sub(Q[2], Q[0]);
    rows = { cross(b, c), cross(c, a), cross(a, b) };
    det = dot(a, rows[0]);
  }
  const T inverse = 1.0 / det;
  const Vec3<T> d = sub(sf.centre, Q[0]);
  std::array<PlaneAffine<T>, 3> out;
  for (int j = 0; j <= tdim; ++j)
    out[j] = { dot(rows[j], d) * inverse,
               dot(rows[j], sf.e1) * inverse,
               dot(rows[j], sf.e2) * inverse };
  return out;
}

/// What a point of an affine slave–master pair needs, all of it affine in
/// the slave plane coordinates: found at the integration cells' vertices
/// and interpolated at their quadrature points.
template<typename T>
struct FlatPoint
{
  std::array<T, 3> Ns{}, Nm{}; ///< slave and master shape functions
  T t{};                       ///< x_m = x_s + t·m: the gap vector is −t·m
  T s{};       ///< m·n (m: the slave piece's projection direction)
  Vec3<T> n{}; ///< the interpolated nodal normal
  T r{};       ///< x_s[0], the radius (axisymmetric)
};

/// Σ_i l_i f_i over the first @p count of @p f (@p ns, @p nm shape
/// functions).
template<typename T>
FlatPoint<T>
interpolate(const std::array<const FlatPoint<T>*, 3>& f,
            const std::array<double, 3>& l,
            int count,
            int ns,
            int nm,
            bool radius)
{
  FlatPoint<T> out;
  auto mix = [&](T& y, auto get)
  {
    for (int i = 0; i < count; ++i)
      add_scaled(y, l[i], get(*f[i]));
  };
  for (int a = 0; a < ns; ++a)
    mix(out.Ns[a], [a](const FlatPoint<T>& p) -> const T& { return p.Ns[a]; });
  for (int a = 0; a < nm; ++a)
    mix(out.Nm[a], [a](const FlatPoint<T>& p) -> const T& { return p.Nm[a]; });
  for (int k = 0; k < 3; ++k)
    mix(out.n[k], [k](const FlatPoint<T>& p) -> const T& { return p.n[k]; });
  mix(out.t, [](const FlatPoint<T>& p) -> const T& { return p.t; });
  mix(out.s, [](const FlatPoint<T>& p) -> const T& { return p.s; });
  if (radius)
    mix(out.r, [](const FlatPoint<T>& p) -> const T& { return p.r; });
  return out;
}

/// What one segment quadrature point gives its callback.
template<typename T>
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

/// Whether the bounding boxes of two plane polygons are more than @p margin
/// apart along an axis (on the values).
template<typename Point>
bool
boxes_apart(const std::vector<Point>& a,
            const std::vector<Point>& b,
            double margin)
{
  for (int k = 0; k < 2; ++k)
  {
    double lo_a = value(a[0][k]), hi_a = lo_a, lo_b = value(b[0][k]),
           hi_b = lo_b;
    for (const Point& p : a)
      lo_a = std::min(lo_a, value(p[k])), hi_a = std::max(hi_a, value(p[k]));
    for (const Point& p : b)
      lo_b = std::min(lo_b, value(p[k])), hi_b = std::max(hi_b, value(p[k]));
    if (lo_b > hi_a + margin or lo_a > hi_b + margin)
      return true;
  }
  return false;
}

/// The non-degenerate flat pieces of a cell (facet_subfacets, make_subfacet).
template<typename T>
std::vector<SubFacet<T>>
cell_pieces(FacetType type, int gdim, std::span<const T> nodes, double zero)
{
  std::vector<SubFacet<T>> pieces;
  for (const auto& piece : facet_subfacets(type))
    if (auto f = make_subfacet<T>(type, gdim, nodes, piece, zero))
      pieces.push_back(std::move(*f));
  return pieces;
}

/// Segment one slave–master cell pair and call @p on_point at every
/// segment quadrature point (see mortar_integrals for the construction).
///
/// @param[in] slave_nodes, master_nodes Node coordinates (nodes, gdim)
/// @param[in] slave_normals Unit nodal normals of the slave cell (nodes,
/// gdim)
/// @param[in] slave_pieces, master_pieces cell_pieces of the same nodes: a
/// caller that meets a cell in many pairs builds them once
/// @param[in] zero The zero length of every geometric decision
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
template<typename T, typename G, typename Lift, typename OnPoint>
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
                 bool opposing_normals_only,
                 bool axisymmetric,
                 bool with_master_N,
                 Lift&& lift,
                 OnPoint&& on_point)
{
  using namespace vec3;
  using P2 = std::array<G, 2>;
  const int tdim = gdim - 1;
  const int ns = facet_num_nodes(slave_type), nm = facet_num_nodes(master_type);
  const std::size_t nq = weights.size();
  const int nm_out = with_master_N ? nm : 0;
  std::vector<G> NsG(ns), dNs(tdim * ns), NmG(nm), dNm(tdim * nm);
  std::vector<T> Ns(ns), Nm(nm);
  std::array<Vec3<G>, 2> tangents;
  // affine cells are their own single flat piece (facet_subfacets)
  const bool flat =
    facet_is_affine(slave_type) and facet_is_affine(master_type);
  // the general path's Newton projections run on the values
  std::vector<double> slave_values, master_values;
  if (!flat)
  {
    for (const G& v : slave_nodes)
      slave_values.push_back(value(v));
    for (const G& v : master_nodes)
      master_values.push_back(value(v));
  }
  std::int64_t failed = 0;
  for (const SubFacet<G>& slave_piece : slave_pieces)
  {
    const SubFacet<G>* sf = &slave_piece;
    auto plane_coords = [&](const Vec3<G>& x) -> P2
    { return sf->plane_coordinates(x); };
    std::vector<P2> slave_polygon;
    for (const Vec3<G>& x : sf->polygon)
      slave_polygon.push_back(plane_coords(x));
    // the flat path's slave map and normal, made when a piece pair first
    // overlaps (most candidate pairs do not)
    std::array<PlaneAffine<G>, 2> slave_map;
    Vec3<T> projection_direction{};
    bool slave_map_made = false;

    for (const SubFacet<G>& mf : master_pieces)
    {
      // unit normals of non-degenerate pieces: a perpendicular master
      // projects to a segment and covers nothing on either side of 0
      if (opposing_normals_only and value(dot(mf.normal, sf->normal)) >= 0)
        continue;
      std::vector<P2> master_polygon;
      for (const Vec3<G>& x : mf.polygon)
        master_polygon.push_back(plane_coords(x));

      // Integration cells in plane coordinates: (origin, edge a, edge b)
      // with measure factor, and their vertices' indices in `vertices`; 2D
      // cells have no edge b (and no third vertex).
      struct Cell
      {
        P2 origin, a, b;
        G measure;
        std::array<int, 3> vertex;
      };
      std::vector<Cell> cells;
      std::vector<P2> vertices;
      if (gdim == 2)
      {
        const G lo =
          larger(slave_polygon[0][0],
                 smaller(master_polygon[0][0], master_polygon[1][0]));
        const G hi =
          smaller(slave_polygon[1][0],
                  larger(master_polygon[0][0], master_polygon[1][0]));
        const G length = hi - lo;
        if (value(length) > zero)
        {
          vertices = { { lo, 0.0 }, { hi, 0.0 } };
          cells.push_back({ { lo, 0.0 },
                            { length, 0.0 },
                            { 0.0, 0.0 },
                            length,
                            { 0, 1, 0 } });
        }
      }
      else
      {
        // The slave polygon is counter-clockwise about its own normal by
        // construction; the master one is usually clockwise (it faces the
        // slave) and must be turned for clipping. It is not degenerate, so
        // the sign of its area is not round-off.
        // Boxes more than twice the zero length apart cannot overlap by more
        // than the clipping's tolerance: the rejection the clipping would
        // reach, at a fraction of its cost (most candidates end here).
        if (boxes_apart(slave_polygon, master_polygon, 2 * zero))
          continue;
        if (value(signed_area(master_polygon)) < 0)
          std::reverse(master_polygon.begin(), master_polygon.end());
        const auto clipped = clip_polygon(slave_polygon, master_polygon, zero);
        // an overlap no wider than the zero length is a segment or a
        // point (touching edges, a shared vertex)
        if (clipped.size() < 3 or
            !(2 * value(signed_area(clipped)) > zero * longest_edge(clipped)))
          continue;
        const double m = static_cast<double>(clipped.size());
        P2 g = { 0.0, 0.0 };
        for (const P2& q : clipped)
          g = { g[0] + q[0] / m, g[1] + q[1] / m };
        vertices = clipped;
        vertices.push_back(g);
        const int centre = static_cast<int>(clipped.size());
        for (int i = 0; i < centre; ++i)
        {
          const int next = (i + 1) % centre;
          const P2& q0 = clipped[i];
          const P2& q1 = clipped[next];
          const P2 a = { q0[0] - g[0], q0[1] - g[1] };
          const P2 b = { q1[0] - g[0], q1[1] - g[1] };
          const G twice_area = a[0] * b[1] - a[1] * b[0];
          // Exact sign test: the polygon is convex, wider than the zero
          // length, and fanned from its centroid, so its fan triangles
          // are positive up to round-off; a round-off one carries a
          // round-off weight whichever way it is decided, while a
          // length-based threshold would drop the fan of a thin overlap.
          if (value(twice_area) > 0)
            cells.push_back({ g, a, b, twice_area, { centre, i, next } });
        }
      }

      if (flat and !cells.empty())
      {
        // Both cells affine: the reference coordinates, the distance t to
        // the master plane along the projection direction m and the
        // interpolated normal are affine in (u, v). They are found at the
        // cells' vertices and interpolated at the quadrature points, where
        // only |n| and the gap's products remain: for a Jet, a tenth of the
        // projections' products per point. The slave point is x itself (the
        // slave plane holds the slave cell), so x_s − x_m = −t·m.
        if (!slave_map_made)
        {
          slave_map = reference_from_plane(slave_polygon, tdim);
          for (int k = 0; k < 3; ++k)
            projection_direction[k] = lift(sf->direction[k]);
          slave_map_made = true;
        }
        const std::array<PlaneAffine<G>, 3> master_map =
          master_from_plane(*sf, mf.polygon, tdim);
        std::vector<FlatPoint<T>> at(vertices.size());
        for (std::size_t i = 0; i < vertices.size(); ++i)
        {
          const P2& p = vertices[i];
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
          f.s = dot(projection_direction, f.n);
          if (axisymmetric)
            f.r = lift(sf->centre[0] + p[0] * sf->e1[0] + p[1] * sf->e2[0]);
        }
        for (const Cell& cell : cells)
        {
          const T measure = lift(cell.measure);
          for (std::size_t q = 0; q < nq; ++q)
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
        continue;
      }

      const Point3 direction = values(sf->direction);
      for (const Cell& cell : cells)
        for (std::size_t q = 0; q < nq; ++q)
        {
          const double X0 = points[q * tdim];
          const double X1 = tdim == 2 ? points[q * tdim + 1] : 0.0;
          const G u = cell.origin[0] + X0 * cell.a[0] + X1 * cell.b[0];
          const G v = cell.origin[1] + X0 * cell.a[1] + X1 * cell.b[1];
          Vec3<G> x;
          for (int k = 0; k < 3; ++k)
            x[k] = sf->centre[k] + u * sf->e1[k] + v * sf->e2[k];
          // Newton on the values; Jets then take two steps that carry the
          // derivatives
          const Point3 xv = values(x);
          const Projection ps = project_along(slave_type,
                                              gdim,
                                              slave_values,
                                              xv,
                                              direction,
                                              sf->reference_centre);
          const Projection pm = project_along(master_type,
                                              gdim,
                                              master_values,
                                              xv,
                                              direction,
                                              mf.reference_centre);
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
                   slave_type, gdim, slave_nodes, x, sf->direction, ps)
                   .first;
            Xm = refine_projection<G>(
                   master_type, gdim, master_nodes, x, sf->direction, pm)
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
          // n interpolates unit vectors: its length is dimensionless and
          // of order 1 unless the nodal normals cancel
          const T n_norm = norm(n);
          const bool n_defined = value(n_norm) > geometric_tolerance;
          const Vec3<G> gap = sub(xs, xm);
          const Vec3<T> gap_vector = { lift(gap[0]),
                                       lift(gap[1]),
                                       lift(gap[2]) };
          const T d = n_defined ? T(dot(gap_vector, n) / n_norm) : T(0.0);
          T w = weights[q] * lift(cell.measure);
          // the surface of revolution's measure 2πr ds: r is the slave
          // point's radius (clamped: a node on the axis may sit at −1e-17)
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
    }
  }
  return failed;
}

} // namespace dolfinx_mortar
