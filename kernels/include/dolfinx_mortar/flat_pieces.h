// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

// The flat path of a pair of affine cells: the slave's reference coordinates,
// the master's and the distance to it along the projection direction are
// affine in the slave plane coordinates, found at an overlap's vertices and
// interpolated at its quadrature points.

#include "pair_segmentation.h"

#include <array>
#include <vector>

namespace dolfinx_mortar
{

/// a + a_u·u + a_v·v: a field affine in the slave plane coordinates (u, v).
template<Scalar T>
struct PlaneAffine
{
  T a, a_u, a_v;
  T at(const std::array<T, 2>& p) const { return a + a_u * p[0] + a_v * p[1]; }
};

/// The reference coordinates of an affine slave cell as functions of its
/// plane coordinates, from its vertices there (in reference order); the
/// second is zero on a line.
template<Scalar T>
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
template<Scalar T>
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
template<Scalar T>
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
template<Scalar T>
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

} // namespace dolfinx_mortar
