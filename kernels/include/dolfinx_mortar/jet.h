// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

namespace dolfinx_mortar
{

/// A scalar with its exact gradient and (Order 2) Hessian with respect to N
/// variables (forward mode), so that one templated algorithm gives values
/// (instantiated for double) and exact derivatives (for Jet). Order 1 carries
/// the gradient alone, for evaluations that need no Hessian.
///
/// Written here because the fixed stack has no second-order automatic
/// differentiation: Eigen's AutoDiffScalar carries first derivatives, and
/// nesting it for the Hessian allocates a dynamic vector per operation.
/// The Hessian is stored as its upper triangle, row by row.
template<int N, int Order = 2>
struct Jet
{
  static_assert(Order == 1 or Order == 2);
  static constexpr int size = N;
  static constexpr int packed = Order == 2 ? N * (N + 1) / 2 : 0;

  double v = 0;                   ///< value
  std::array<double, N> g{};      ///< gradient
  std::array<double, packed> h{}; ///< Hessian, upper triangle row-major
  /// Known to have zero derivatives (built from a double): products and
  /// sums with it skip the derivative arrays. Shape functions of affine
  /// cells and reference points make many such operands; skipping them
  /// halved the cost of a 3D pair.
  bool constant = true;

  Jet() = default;
  /// A constant (implicit, so that literals and doubles mix with Jets).
  Jet(double value)
    : v(value)
  {
  }
  /// The variable number @p i with value @p value.
  static Jet variable(double value, int i)
  {
    Jet x(value);
    x.g[i] = 1;
    x.constant = false;
    return x;
  }
  /// Entry (i, j) of the Hessian.
  double hessian(int i, int j) const
  {
    if (i > j)
      std::swap(i, j);
    return h[i * N - i * (i - 1) / 2 + (j - i)];
  }

  /// The chain rule for f(x) with f'(x) = d1 and f''(x) = d2.
  Jet apply(double f, double d1, double d2) const
  {
    Jet y(f);
    if (constant)
      return y;
    y.constant = false;
    for (int i = 0; i < N; ++i)
      y.g[i] = d1 * g[i];
    if constexpr (Order == 2)
    {
      int k = 0;
      for (int i = 0; i < N; ++i)
      {
        const double gi = d2 * g[i];
        for (int j = i; j < N; ++j, ++k)
          y.h[k] = d1 * h[k] + gi * g[j];
      }
    }
    return y;
  }

  Jet& operator+=(const Jet& b)
  {
    v += b.v;
    if (b.constant)
      return *this;
    if (constant)
    {
      const double value = v;
      *this = b;
      v = value;
      return *this;
    }
    for (int i = 0; i < N; ++i)
      g[i] += b.g[i];
    for (int k = 0; k < packed; ++k)
      h[k] += b.h[k];
    return *this;
  }
  Jet& operator-=(const Jet& b)
  {
    v -= b.v;
    if (b.constant)
      return *this;
    if (constant)
    {
      const double value = v;
      *this = b;
      *this *= -1.0;
      v = value;
      return *this;
    }
    for (int i = 0; i < N; ++i)
      g[i] -= b.g[i];
    for (int k = 0; k < packed; ++k)
      h[k] -= b.h[k];
    return *this;
  }
  /// *this += c·b, without the temporary of `*this += c * b`.
  void add_scaled(double c, const Jet& b)
  {
    v += c * b.v;
    if (b.constant)
      return;
    if (constant)
    {
      const double value = v;
      *this = b;
      *this *= c;
      v = value;
      return;
    }
    for (int i = 0; i < N; ++i)
      g[i] += c * b.g[i];
    for (int k = 0; k < packed; ++k)
      h[k] += c * b.h[k];
  }
  Jet& operator*=(double c)
  {
    v *= c;
    if (constant)
      return *this;
    for (int i = 0; i < N; ++i)
      g[i] *= c;
    for (int k = 0; k < packed; ++k)
      h[k] *= c;
    return *this;
  }
  Jet& operator+=(double c)
  {
    v += c;
    return *this;
  }

  // Hidden friends: found for Jet arguments only, and an int or double
  // operand picks the cheaper (double, Jet) overloads.
  friend Jet operator+(Jet a, const Jet& b) { return a += b; }
  friend Jet operator+(Jet a, double c) { return a += c; }
  friend Jet operator+(double c, Jet a) { return a += c; }
  friend Jet operator-(Jet a, const Jet& b) { return a -= b; }
  friend Jet operator-(Jet a, double c) { return a += -c; }
  friend Jet operator-(double c, const Jet& a) { return (-a) += c; }
  friend Jet operator-(Jet a) { return a *= -1.0; }
  friend Jet operator*(Jet a, double c) { return a *= c; }
  friend Jet operator*(double c, Jet a) { return a *= c; }
  friend Jet operator/(Jet a, double c) { return a *= 1.0 / c; }
  friend Jet operator*(const Jet& a, const Jet& b)
  {
    if (a.constant)
      return b * a.v;
    if (b.constant)
      return a * b.v;
    Jet y(a.v * b.v);
    y.constant = false;
    for (int i = 0; i < N; ++i)
      y.g[i] = a.v * b.g[i] + b.v * a.g[i];
    if constexpr (Order == 2)
    {
      int k = 0;
      for (int i = 0; i < N; ++i)
      {
        const double ai = a.g[i], bi = b.g[i];
        for (int j = i; j < N; ++j, ++k)
          y.h[k] = a.v * b.h[k] + b.v * a.h[k] + ai * b.g[j] + bi * a.g[j];
      }
    }
    return y;
  }
  friend Jet operator/(const Jet& a, const Jet& b) { return a * reciprocal(b); }
  friend Jet operator/(double c, const Jet& b) { return reciprocal(b) *= c; }
  friend Jet& operator*=(Jet& a, const Jet& b) { return a = a * b; }
  friend Jet& operator/=(Jet& a, const Jet& b) { return a = a / b; }

  friend Jet reciprocal(const Jet& a)
  {
    const double r = 1.0 / a.v;
    return a.apply(r, -r * r, 2 * r * r * r);
  }
  friend Jet sqrt(const Jet& a)
  {
    const double s = std::sqrt(a.v);
    return a.apply(s, 0.5 / s, -0.25 / (s * a.v));
  }
  friend Jet hypot(const Jet& a, const Jet& b) { return sqrt(a * a + b * b); }
};

/// @p x as a Jet over M ≥ N variables, variable i becoming variable
/// i < split ? i : i + shift (order-preserving, so the packed Hessian's
/// upper triangle stays the upper triangle): a result over fewer variables
/// joins a computation over more.
template<int M, int N, int Order>
Jet<M, Order>
widen(const Jet<N, Order>& x, int split, int shift)
{
  static_assert(M >= N);
  Jet<M, Order> y(x.v);
  if (x.constant)
    return y;
  y.constant = false;
  auto to = [split, shift](int i) { return i < split ? i : i + shift; };
  for (int i = 0; i < N; ++i)
    y.g[to(i)] = x.g[i];
  if constexpr (Order == 2)
  {
    int k = 0;
    for (int i = 0; i < N; ++i)
    {
      const int I = to(i);
      double* row = y.h.data() + I * M - I * (I - 1) / 2 - I;
      for (int j = i; j < N; ++j, ++k)
        row[to(j)] = x.h[k];
    }
  }
  return y;
}

/// Value, gradient and full Hessian of a Jet, into flat arrays (@p g: N,
/// @p H: N × N row-major).
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

/// The value of a scalar: itself for double, the value part of a Jet. Every
/// branch of a templated algorithm is decided on values, so that the double
/// and the Jet instantiations take the same branches.
inline double
value(double x)
{
  return x;
}
template<int N, int Order>
double
value(const Jet<N, Order>& x)
{
  return x.v;
}

// The double functions next to the Jet ones, for unqualified calls in
// templates.
using std::hypot;
using std::sqrt;

/// The larger of two scalars, decided on the values (with its derivatives).
template<typename T>
T
larger(const T& a, const T& b)
{
  return value(a) >= value(b) ? a : b;
}
/// The smaller of two scalars, decided on the values.
template<typename T>
T
smaller(const T& a, const T& b)
{
  return value(a) <= value(b) ? a : b;
}

} // namespace dolfinx_mortar
