// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#include <dolfinx_mortar/clipping.h>
#include <dolfinx_mortar/jet.h>

#include <cmath>
#include <gtest/gtest.h>

using namespace dolfinx_mortar;

namespace
{
// f(x, y) = sqrt(x y) / (x + 2 − y) + 3 x² y, with every operator a Jet has
template<typename T>
T
f(const T& x, const T& y)
{
  return sqrt(x * y) / (x + 2 - y) + 3.0 * x * x * y - 1.0 / x;
}
} // namespace

TEST(Jet, GradientAndHessianAreExact)
{
  const double x0 = 0.7, y0 = 1.3;
  const auto x = Jet<2>::variable(x0, 0), y = Jet<2>::variable(y0, 1);
  const Jet<2> v = f(x, y);
  EXPECT_DOUBLE_EQ(v.v, f(x0, y0));
  // central differences of f and of the Jet's own gradient
  const double h = 1e-5;
  const double gx = (f(x0 + h, y0) - f(x0 - h, y0)) / (2 * h);
  const double gy = (f(x0, y0 + h) - f(x0, y0 - h)) / (2 * h);
  EXPECT_NEAR(v.g[0], gx, 1e-8);
  EXPECT_NEAR(v.g[1], gy, 1e-8);
  auto gradient_at = [](double a, double b)
  { return f(Jet<2>::variable(a, 0), Jet<2>::variable(b, 1)).g; };
  const auto px = gradient_at(x0 + h, y0), mx = gradient_at(x0 - h, y0);
  const auto py = gradient_at(x0, y0 + h), my = gradient_at(x0, y0 - h);
  EXPECT_NEAR(v.hessian(0, 0), (px[0] - mx[0]) / (2 * h), 1e-8);
  EXPECT_NEAR(v.hessian(0, 1), (px[1] - mx[1]) / (2 * h), 1e-8);
  EXPECT_NEAR(v.hessian(1, 0), (py[0] - my[0]) / (2 * h), 1e-8);
  EXPECT_NEAR(v.hessian(1, 1), (py[1] - my[1]) / (2 * h), 1e-8);
}

TEST(Jet, ClippingTakesTheDoubleBranchesAndCarriesTheArea)
{
  // A triangle clipped by a square: the Jet area equals the double one, and
  // its gradient moves with a clip vertex as the area does
  const std::vector<Point2> tri = { { 0, 0 }, { 1, 0 }, { 0.2, 1 } };
  const std::vector<Point2> sq = {
    { 0.1, -1 }, { 0.8, -1 }, { 0.8, 0.6 }, { 0.1, 0.6 }
  };
  using J = Jet<16>;
  std::vector<std::array<J, 2>> tj, sj;
  int n = 0;
  for (const auto& p : tri)
    tj.push_back({ J::variable(p[0], n++), J::variable(p[1], n++) });
  for (const auto& p : sq)
    sj.push_back({ J::variable(p[0], n++), J::variable(p[1], n++) });
  const J area = signed_area(clip_polygon(tj, sj, 1e-12));
  // to round-off: a Jet measures edge lengths by sqrt(a² + b²), double by hypot
  EXPECT_NEAR(area.v, signed_area(clip_polygon(tri, sq, 1e-12)), 1e-15);
  const double h = 1e-6;
  for (int v = 0; v < 14; ++v)
  {
    auto moved = [&](double step)
    {
      std::vector<Point2> t = tri, s = sq;
      if (v < 6)
        t[v / 2][v % 2] += step;
      else
        s[(v - 6) / 2][v % 2] += step;
      return signed_area(clip_polygon(t, s, 1e-12));
    };
    EXPECT_NEAR(area.g[v], (moved(h) - moved(-h)) / (2 * h), 1e-8) << v;
  }
}

TEST(Jet, AddScaledIsTheSumWithAProduct)
{
  // every combination of constant and variable operands, against y + c·x
  const auto x = Jet<2>::variable(0.7, 0), y = Jet<2>::variable(1.3, 1);
  const Jet<2> fx = f(x, y), fy = f(y, x), constant(2.5);
  for (const Jet<2>* a : { &fx, &constant })
    for (const Jet<2>* b : { &fy, &constant })
    {
      Jet<2> sum = *a;
      sum.add_scaled(-0.3, *b);
      const Jet<2> expected = *a + (-0.3) * *b;
      EXPECT_EQ(sum.constant, expected.constant);
      EXPECT_DOUBLE_EQ(sum.v, expected.v);
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j)
          EXPECT_DOUBLE_EQ(sum.hessian(i, j), expected.hessian(i, j));
      EXPECT_DOUBLE_EQ(sum.g[0], expected.g[0]);
      EXPECT_DOUBLE_EQ(sum.g[1], expected.g[1]);
    }
}

TEST(Jet, WidenedEqualsTheComputationOverMoreVariables)
{
  // f over (x, y) widened to four variables with y moved to the last: the
  // same as f computed over four variables directly
  const Jet<2> narrow = f(Jet<2>::variable(0.7, 0), Jet<2>::variable(1.3, 1));
  const Jet<4> wide = widen<4>(narrow, 1, 2);
  const Jet<4> direct = f(Jet<4>::variable(0.7, 0), Jet<4>::variable(1.3, 3));
  EXPECT_DOUBLE_EQ(wide.v, direct.v);
  for (int i = 0; i < 4; ++i)
  {
    EXPECT_DOUBLE_EQ(wide.g[i], direct.g[i]) << i;
    for (int j = 0; j < 4; ++j)
      EXPECT_DOUBLE_EQ(wide.hessian(i, j), direct.hessian(i, j)) << i << j;
  }
  EXPECT_TRUE(widen<4>(Jet<2>(3.0), 1, 2).constant);
}
