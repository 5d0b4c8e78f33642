// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#include <dolfinx_mortar/bounding_box_tree.h>
#include <dolfinx_mortar/clipping.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

using namespace dolfinx_mortar;

TEST(Clipping, OverlappingSquares)
{
  std::vector<Point2> a = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } };
  std::vector<Point2> b = {
    { 0.5, 0.25 }, { 1.5, 0.25 }, { 1.5, 1.25 }, { 0.5, 1.25 }
  };
  auto c = clip_polygon(a, b, 1e-14);
  EXPECT_NEAR(signed_area(c), 0.5 * 0.75, 1e-15);
}

TEST(Clipping, IdenticalAndTouchingPolygons)
{
  std::vector<Point2> a = { { 0, 0 }, { 1, 0 }, { 0, 1 } };
  EXPECT_NEAR(signed_area(clip_polygon(a, a, 1e-14)), 0.5, 1e-15);
  std::vector<Point2> right = { { 1, 0 }, { 2, 0 }, { 1, 1 } };
  EXPECT_NEAR(signed_area(clip_polygon(a, right, 1e-14)), 0.0, 1e-15);
  std::vector<Point2> far = { { 5, 5 }, { 6, 5 }, { 5, 6 } };
  EXPECT_TRUE(clip_polygon(a, far, 1e-14).size() < 3);
}

TEST(Clipping, TriangleInsideSquare)
{
  std::vector<Point2> sq = { { -1, -1 }, { 2, -1 }, { 2, 2 }, { -1, 2 } };
  std::vector<Point2> t = { { 0, 0 }, { 1, 0 }, { 0, 1 } };
  EXPECT_NEAR(signed_area(clip_polygon(t, sq, 1e-14)), 0.5, 1e-15);
  EXPECT_NEAR(signed_area(clip_polygon(sq, t, 1e-14)), 0.5, 1e-15);
}

TEST(Clipping, NearCoincidentTrianglesConserveArea)
{
  // Two triangles equal up to vertex moves of 1e-16 … 1e-9 (round-off apart,
  // as separately meshed conforming faces): the overlap is the triangle up to
  // the tolerance times its perimeter. A crossing point computed for a point
  // inside only by the tolerance was extrapolated off its edge: areas up to
  // several times the triangle's.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(-1, 1), exponent(-16, -9);
  const double tolerance = 1e-10;
  double worst = 0;
  for (int trial = 0; trial < 20000; ++trial)
  {
    std::vector<Point2> a = { { unit(rng), unit(rng) },
                              { unit(rng), unit(rng) },
                              { unit(rng), unit(rng) } };
    if (signed_area(a) < 0)
      std::reverse(a.begin(), a.end());
    if (signed_area(a) < 1e-3)
      continue;
    const double move = std::pow(10.0, exponent(rng));
    std::vector<Point2> b = a;
    for (Point2& p : b)
      p = { p[0] + move * unit(rng), p[1] + move * unit(rng) };
    double perimeter = 0;
    for (std::size_t i = 0; i < 3; ++i)
      perimeter +=
        std::hypot(a[(i + 1) % 3][0] - a[i][0], a[(i + 1) % 3][1] - a[i][1]);
    const double error =
      std::abs(signed_area(clip_polygon(a, b, tolerance)) - signed_area(a));
    worst = std::max(worst, error / ((tolerance + move) * perimeter));
  }
  EXPECT_LE(worst, 2.0);
}

TEST(Clipping, CrossingPointsStayOnTheirEdge)
{
  // p is inside by the tolerance only (0.9·tol outside), q just beyond it:
  // the crossing of p–q with the clip line, computed without the tolerance,
  // lay 4.5 edge lengths before p.
  const double tol = 1e-10;
  std::vector<Point2> clip = { { -2, 0 }, { 10, 0 }, { 10, 10 }, { -2, 10 } };
  std::vector<Point2> subject = { { 0, -0.9 * tol },
                                  { 1, -1.1 * tol },
                                  { 0.5, 1 } };
  for (const Point2& p : clip_polygon(subject, clip, tol))
    EXPECT_GE(p[0], -1e-9) << "crossing point off its edge";
  EXPECT_NEAR(signed_area(clip_polygon(subject, clip, tol)), 0.5, 1e-9);
}

TEST(Clipping, CrossingFromAPointOnTheLineAlongANearlyParallelEdge)
{
  // A sliver A(0,0), B(1,0), C(1,h) of height 1e3 tolerances; the clip line
  // v = c + m·u passes A inside by 0.9 tol (on the line) and C outside by
  // 9 tol: it crosses the nearly parallel edge A–C at u = 1/11, 0.09 of the
  // edge away from A, and B–C at Y = (1, c + m). The exact overlap is the
  // sliver less the triangle X C Y. No crossing was computed from a point on
  // the line: the band A X Y (0.9 tol wide, 0.9 long) was covered, 8e-4 of
  // the sliver's area (a sliver and a near-coincident master, seen in the
  // stress harness up to 1e-2).
  const double tol = 1e-10, h = 1e3 * tol, c = 0.9 * tol, m = h - 9.9 * tol;
  const std::vector<Point2> sliver = { { 0, 0 }, { 1, 0 }, { 1, h } };
  const std::vector<Point2> clip = { { -1, c - m }, { 0.5, -1 }, { 2, c + 2 * m } };
  ASSERT_GT(signed_area(clip), 0);
  const double u_x = c / (h - m);
  const double exact = h / 2 - 0.5 * (h - c - m) * (1 - u_x);
  const double area = signed_area(clip_polygon(sliver, clip, tol));
  EXPECT_LE(std::abs(area - exact), 1e-6 * h / 2) << area << " " << exact;
}

TEST(BoundingBoxTree, MatchesBruteForce)
{
  std::vector<double> a, b;
  unsigned s = 1;
  auto next = [&]() { return (s = s * 1103515245u + 12345u) % 1000 / 100.0; };
  for (int i = 0; i < 200; ++i)
  {
    double x = next(), y = next(), z = next();
    a.insert(a.end(), { x, y, z, x + 0.7, y + 0.7, z + 0.7 });
  }
  for (int i = 0; i < 150; ++i)
  {
    double x = next(), y = next(), z = next();
    b.insert(b.end(), { x, y, z, x + 0.5, y + 0.5, z + 0.5 });
  }
  auto pairs = overlapping_box_pairs(a, b);
  std::size_t brute = 0;
  for (int i = 0; i < 200; ++i)
    for (int j = 0; j < 150; ++j)
    {
      bool o = true;
      for (int k = 0; k < 3; ++k)
        o = o and a[6 * i + k] <= b[6 * j + k + 3] and
            b[6 * j + k] <= a[6 * i + k + 3];
      brute += o;
    }
  EXPECT_EQ(pairs.size() / 2, brute);
  EXPECT_GT(brute, 0u);
}
