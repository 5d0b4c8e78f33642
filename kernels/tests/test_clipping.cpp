// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#include <dolfinx_mortar/bounding_box_tree.h>
#include <dolfinx_mortar/clipping.h>
#include <gtest/gtest.h>

#include <algorithm>
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
