// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

// Vectors of three scalars (2D points have z = 0) and their algebra, for any
// Scalar: the segmentation and the current surface's geometry share them.

#include "scalar.h"

#include <array>

namespace dolfinx_mortar
{

/// A point or vector of three scalars.
template<Scalar T>
using Vec3 = std::array<T, 3>;

namespace vec3
{
/// a·b
template<Scalar T>
T
dot(const Vec3<T>& a, const Vec3<T>& b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
/// a + b
template<Scalar T>
Vec3<T>
add(const Vec3<T>& a, const Vec3<T>& b)
{
  return { a[0] + b[0], a[1] + b[1], a[2] + b[2] };
}
/// a − b
template<Scalar T>
Vec3<T>
sub(const Vec3<T>& a, const Vec3<T>& b)
{
  return { a[0] - b[0], a[1] - b[1], a[2] - b[2] };
}
/// a × b
template<Scalar T>
Vec3<T>
cross(const Vec3<T>& a, const Vec3<T>& b)
{
  return { a[1] * b[2] - a[2] * b[1],
           a[2] * b[0] - a[0] * b[2],
           a[0] * b[1] - a[1] * b[0] };
}
/// |a|
template<Scalar T>
T
norm(const Vec3<T>& a)
{
  return sqrt(dot(a, a));
}
/// The values of the components.
template<Scalar T>
std::array<double, 3>
values(const Vec3<T>& a)
{
  return { value(a[0]), value(a[1]), value(a[2]) };
}
} // namespace vec3

} // namespace dolfinx_mortar
