// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

// The scalar types the geometric algorithms are written for: double gives
// values, a Jet the same values with their exact derivatives. Every branch
// is decided on value(), so that both instantiations take the same branches.

#include "jet.h"

#include <concepts>

namespace dolfinx_mortar
{

/// The contract of a scalar of the templated algorithms: field arithmetic
/// with itself and with doubles, sqrt, and value() (the double every
/// decision is taken on). double and Jet<N, Order> satisfy it.
// clang-format 14 breaks requires-expressions over many lines
// clang-format off
template<typename T>
concept Scalar = std::copy_constructible<T> and requires(T a, const T& b, double c) {
  { value(a) } -> std::convertible_to<double>;
  { a + b } -> std::convertible_to<T>;
  { a - b } -> std::convertible_to<T>;
  { a * b } -> std::convertible_to<T>;
  { a / b } -> std::convertible_to<T>;
  { a * c } -> std::convertible_to<T>;
  { c * a } -> std::convertible_to<T>;
  { a + c } -> std::convertible_to<T>;
  { -a } -> std::convertible_to<T>;
  { sqrt(a) } -> std::convertible_to<T>;
  { T(c) };
};
// clang-format on

static_assert(Scalar<double>);
static_assert(Scalar<Jet<4, 1>> and Scalar<Jet<4, 2>>);

/// |a|, with the sign decided on the value.
template<Scalar T>
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

} // namespace dolfinx_mortar
