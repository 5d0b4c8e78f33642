// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#include <dolfinx_mortar/current_surface.h>

#include <algorithm>
#include <cmath>
#include <gtest/gtest.h>
#include <numbers>
#include <vector>

using namespace dolfinx_mortar;

namespace
{
/// A cell, its rule and a rigid ball (circle in 2D) it presses into.
struct Scene
{
  int gdim, tdim, nodes;
  std::vector<double> x, N, dN, w, phi;
  std::array<double, 3> centre;
  double radius;
  bool axisymmetric = false;

  SurfaceCells cells(const std::vector<double>& at) const
  {
    return { gdim, tdim, nodes, at, N, dN, w, phi, axisymmetric };
  }
  /// d = R − |x_q − c| at the points of the cell at @p at, with its
  /// derivatives.
  void obstacle(const std::vector<double>& at,
                std::vector<double>& d,
                std::vector<double>& g,
                std::vector<double>& h) const
  {
    const std::size_t nq = w.size();
    d.assign(nq, 0);
    g.assign(nq * gdim, 0);
    h.assign(nq * gdim * gdim, 0);
    for (std::size_t q = 0; q < nq; ++q)
    {
      std::array<double, 3> r{};
      for (int b = 0; b < nodes; ++b)
        for (int i = 0; i < gdim; ++i)
          r[i] += N[q * nodes + b] * at[b * gdim + i];
      double s = 0;
      for (int i = 0; i < gdim; ++i)
      {
        r[i] -= centre[i];
        s += r[i] * r[i];
      }
      s = std::sqrt(s);
      d[q] = radius - s;
      for (int i = 0; i < gdim; ++i)
      {
        g[q * gdim + i] = -r[i] / s;
        for (int j = 0; j < gdim; ++j)
          h[(q * gdim + i) * gdim + j] =
            -((i == j) - r[i] * r[j] / (s * s)) / s;
      }
    }
  }
};

/// A curved P2 line (nodes at s = 0, 1, 1/2) with a 4-point Gauss rule.
Scene
p2_line(bool axisymmetric)
{
  Scene s{ 2,
           1,
           3,
           { 0.3, 0.1, 1.4, 0.25, 0.9, 0.02 },
           {},
           {},
           {},
           {},
           { 0.8, -1.5, 0 },
           1.6,
           axisymmetric };
  const double a = std::sqrt(3.0 / 7 - 2.0 / 7 * std::sqrt(6.0 / 5)),
               b = std::sqrt(3.0 / 7 + 2.0 / 7 * std::sqrt(6.0 / 5));
  const double wa = (18 + std::sqrt(30.0)) / 36,
               wb = (18 - std::sqrt(30.0)) / 36;
  for (auto [t, wt] : { std::pair{ -b, wb }, { -a, wa }, { a, wa }, { b, wb } })
  {
    const double u = 0.5 * (1 + t);
    s.N.insert(s.N.end(),
               { (1 - u) * (1 - 2 * u), u * (2 * u - 1), 4 * u * (1 - u) });
    s.dN.insert(s.dN.end(), { 4 * u - 3, 4 * u - 1, 4 - 8 * u });
    s.w.push_back(0.5 * wt);
  }
  s.phi = s.N;
  return s;
}

/// A P1 triangle in 3D with a 3-point rule and the dual-like φ = N C.
Scene
p1_triangle()
{
  Scene s{ 3,
           2,
           3,
           { 0.1, 0.0, 0.05, 1.2, 0.1, -0.02, 0.2, 0.9, 0.1 },
           {},
           {},
           {},
           {},
           { 0.4, 0.3, -1.8 },
           1.88 };
  for (auto [u, v] : { std::pair{ 1.0 / 6, 1.0 / 6 },
                       { 2.0 / 3, 1.0 / 6 },
                       { 1.0 / 6, 2.0 / 3 } })
  {
    const std::vector<double> n = { 1 - u - v, u, v };
    s.N.insert(s.N.end(), n.begin(), n.end());
    s.dN.insert(s.dN.end(), { -1, 1, 0, -1, 0, 1 });
    s.w.push_back(1.0 / 6);
    s.phi.insert(s.phi.end(),
                 { 3 * n[0] - n[1] - n[2],
                   3 * n[1] - n[0] - n[2],
                   3 * n[2] - n[0] - n[1] });
  }
  return s;
}

SurfaceCellDerivatives
evaluate(const Scene& s,
         const std::vector<double>& at,
         bool positive_part = false)
{
  std::vector<double> d, g, h;
  s.obstacle(at, d, g, h);
  const ObstacleAtPoints ob{ d, g, h, positive_part };
  return current_surface_cells(s.cells(at), &ob);
}

/// Gradients against central differences of the values, and the weighted
/// Hessian against central differences of the gradients.
void
check_derivatives(const Scene& s)
{
  const SurfaceCellDerivatives r = evaluate(s, s.x);
  const int nv = s.nodes * s.gdim;
  const std::vector<double> wW = { 0.7, -1.3, 2.1 }, wg = { 1.1, 0.4, -0.6 };
  std::vector<double> d, g, h;
  s.obstacle(s.x, d, g, h);
  const ObstacleAtPoints ob{ d, g, h, false };
  const std::vector<double> hessian =
    current_surface_hessians(s.cells(s.x), &ob, wW, wg);
  const double step = 1e-6;
  double gradient_error = 0, hessian_error = 0;
  for (int k = 0; k < nv; ++k)
  {
    std::vector<double> plus = s.x, minus = s.x;
    plus[k] += step;
    minus[k] -= step;
    const SurfaceCellDerivatives p = evaluate(s, plus), m = evaluate(s, minus);
    for (int a = 0; a < s.nodes; ++a)
    {
      gradient_error = std::max(
        { gradient_error,
          std::abs((p.W[a] - m.W[a]) / (2 * step) - r.W_gradient[a * nv + k]),
          std::abs((p.gap[a] - m.gap[a]) / (2 * step) -
                   r.gap_gradient[a * nv + k]) });
    }
    for (int j = 0; j < nv; ++j)
    {
      double difference = 0;
      for (int a = 0; a < s.nodes; ++a)
        difference +=
          (wW[a] * (p.W_gradient[a * nv + j] - m.W_gradient[a * nv + j]) +
           wg[a] * (p.gap_gradient[a * nv + j] - m.gap_gradient[a * nv + j])) /
          (2 * step);
      hessian_error =
        std::max(hessian_error, std::abs(difference - hessian[k * nv + j]));
    }
  }
  EXPECT_LT(gradient_error, 1e-8);
  EXPECT_LT(hessian_error, 1e-7);
}
} // namespace

TEST(CurrentSurface, CurvedLineDerivativesAreExact)
{
  check_derivatives(p2_line(false));
}

TEST(CurrentSurface, MeridianDerivativesAreExact)
{
  check_derivatives(p2_line(true));
}

TEST(CurrentSurface, TriangleDerivativesAreExact)
{
  check_derivatives(p1_triangle());
}

TEST(CurrentSurface, WeightsSumToTheArea)
{
  // a flat unit-length line: W = (1/2, 1/2); a meridian at r = 2: 2π·2·(1/2)
  // each
  Scene s = p2_line(false);
  s.x = { 2, 0, 2, 1, 2, 0.5 };
  const SurfaceCellDerivatives flat =
    current_surface_cells(s.cells(s.x), nullptr);
  EXPECT_NEAR(flat.W[0] + flat.W[1] + flat.W[2], 1.0, 1e-14);
  s.axisymmetric = true;
  const SurfaceCellDerivatives meridian =
    current_surface_cells(s.cells(s.x), nullptr);
  EXPECT_NEAR(
    meridian.W[0] + meridian.W[1] + meridian.W[2], 4 * std::numbers::pi, 1e-13);
  EXPECT_TRUE(meridian.gap.empty());
}

TEST(CurrentSurface, PositivePartIsTheSumOverPenetratingPoints)
{
  // the circle cuts the curved line: some points penetrate, some do not
  const Scene s = p2_line(false);
  const SurfaceCellDerivatives r = evaluate(s, s.x, true);
  std::vector<double> d, g, h;
  s.obstacle(s.x, d, g, h);
  int penetrating = 0;
  std::array<double, 3> expected{};
  for (std::size_t q = 0; q < s.w.size(); ++q)
  {
    const std::span<const double> N(s.N.data() + q * 3, 3),
      dN(s.dN.data() + q * 3, 3);
    const double J = area_element<double>(s.x, N, dN, 2, 1, false);
    if (d[q] > 0)
    {
      ++penetrating;
      for (int a = 0; a < 3; ++a)
        expected[a] += s.w[q] * s.phi[q * 3 + a] * J * d[q];
    }
  }
  ASSERT_GT(penetrating, 0);
  ASSERT_LT(penetrating, 4);
  for (int a = 0; a < 3; ++a)
  {
    EXPECT_NEAR(r.gap_plus[a], expected[a], 1e-14);
    EXPECT_GT(std::abs(r.gap_plus[a] - r.gap[a]), 1e-6);
  }
}

TEST(CurrentSurface, ArraysOfTheWrongSizeAreRefused)
{
  const Scene s = p2_line(false);
  const std::vector<double> short_phi(s.phi.begin(), s.phi.begin() + 3);
  EXPECT_THROW(
    current_surface_cells(
      SurfaceCells{ 2, 1, 3, s.x, s.N, s.dN, s.w, short_phi }, nullptr),
    std::invalid_argument);
}
