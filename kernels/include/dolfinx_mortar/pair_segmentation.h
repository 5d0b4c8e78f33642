// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

// The geometry of the segmentation of a slave–master cell pair, written once
// for any Scalar: a cell's position and tangents, its flat pieces, and the
// projection onto it along a direction. double gives the values
// (mortar_integrals), a Jet the same values with their exact first and second
// derivatives (current_pair_gaps). Every branch is decided on values, so that
// both instantiations take the same branches. The quadrature over the pieces'
// overlaps is piece_quadrature.h.

#include "clipping.h"
#include "facet_element.h"
#include "geometric_tolerance.h"
#include "surface_geometry.h"
#include "vec3.h"

#include <algorithm>
#include <cstdint>
#include <numbers>
#include <optional>
#include <span>
#include <type_traits>
#include <vector>

namespace dolfinx_mortar
{

/// Position x(X) and tangents ∂x/∂X_k of a cell given by its node
/// coordinates @p nodes (nodes, gdim); 2D: z = 0.
template<Scalar T>
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
template<Scalar T>
Vec3<T>
size_weighted_normal(int gdim, const std::array<Vec3<T>, 2>& t)
{
  if (gdim == 2)
    return { t[0][1], -t[0][0], 0.0 };
  return vec3::cross(t[0], t[1]);
}

/// A flat piece of a facet: its reference polygon's centre, its physical
/// polygon, and the plane (line in 2D) through its centre.
template<Scalar T>
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
template<Scalar T>
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
template<Scalar T>
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
template<Scalar T>
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

/// The non-degenerate flat pieces of a cell (facet_subfacets, make_subfacet).
template<Scalar T>
std::vector<SubFacet<T>>
cell_pieces(FacetType type, int gdim, std::span<const T> nodes, double zero)
{
  std::vector<SubFacet<T>> pieces;
  for (const auto& piece : facet_subfacets(type))
    if (auto f = make_subfacet<T>(type, gdim, nodes, piece, zero))
      pieces.push_back(std::move(*f));
  return pieces;
}

} // namespace dolfinx_mortar
