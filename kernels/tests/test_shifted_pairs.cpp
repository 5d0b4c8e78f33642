// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
//
// The segmentation does not depend on where a scene lies: random 3D pairs of
// size 1e-3 near the origin and the same pairs shifted by 1e6 and 1e8 give
// the same covered areas, integrals and gaps to round-off of their own size.
// Before the decisions were taken in local coordinates with a length scale
// from the extent (docs/DESIGN.md, §Tolerances), the zero length grew with
// |x|: 1e-4 at 1e6, a tenth of the facets.
#include <dolfinx_mortar/geometric_tolerance.h>
#include <dolfinx_mortar/mortar_integrals.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

using namespace dolfinx_mortar;

namespace
{
/// Integrals of one slave triangle against one master triangle: nodes (6, 3)
/// (slave first), the slave's unit normal at its nodes.
MortarIntegrals
pair_integrals(const std::vector<double>& x, double length_scale)
{
  const std::array<std::int32_t, 3> slave_cells = { 0, 1, 2 },
                                    master_cells = { 0, 1, 2 };
  const std::span<const double> xs(x.data(), 9), xm(x.data() + 9, 9);
  const std::array<double, 3> a = { xs[3] - xs[0], xs[4] - xs[1],
                                    xs[5] - xs[2] },
                              b = { xs[6] - xs[0], xs[7] - xs[1],
                                    xs[8] - xs[2] };
  std::array<double, 3> n = { a[1] * b[2] - a[2] * b[1],
                              a[2] * b[0] - a[0] * b[2],
                              a[0] * b[1] - a[1] * b[0] };
  const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  std::vector<double> normals;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k)
      normals.push_back(n[k] / length);
  const std::array<std::int32_t, 2> candidates = { 0, 0 };
  // a 3-point rule on the reference triangle
  const std::array<double, 6> points = { 1.0 / 6, 1.0 / 6, 2.0 / 3,
                                         1.0 / 6, 1.0 / 6, 2.0 / 3 };
  const std::array<double, 3> weights = { 1.0 / 6, 1.0 / 6, 1.0 / 6 };
  SegmentationOptions options;
  options.opposing_normals_only = false;
  options.length_scale = length_scale;
  return mortar_integrals({ FacetType::P1_triangle, 3, xs, slave_cells },
                          normals,
                          { FacetType::P1_triangle, 3, xm, master_cells },
                          candidates,
                          points,
                          weights,
                          options);
}
} // namespace

TEST(ShiftedPairs, SameIntegralsFarFromTheOrigin)
{
  // Coordinates on a grid of 2^-26 (1.5e-8), exactly representable at 1e8 as
  // well: the shifted scenes are the same scene, not a rounded copy of it.
  std::mt19937_64 rng(11);
  const double grid = std::ldexp(1.0, -26), size = 1e-3;
  std::uniform_real_distribution<double> unit(0, 1);
  auto on_grid = [&](double v) { return std::round(v / grid) * grid; };
  int compared = 0;
  double worst_area = 0, worst_integral = 0;
  for (int trial = 0; trial < 400; ++trial)
  {
    std::vector<double> x(18);
    for (int i = 0; i < 9; ++i) // slave in the plane z = 0, master above
      x[i] = i % 3 == 2 ? 0.0 : on_grid(size * unit(rng));
    for (int i = 9; i < 18; ++i)
      x[i] = on_grid(i % 3 == 2 ? 0.1 * size * unit(rng) : size * unit(rng));
    // master triangles facing the slave's normal the other way round
    const double scale = length_scale(x, 3);
    const MortarIntegrals at_origin = pair_integrals(x, scale);
    if (!at_origin.degenerate_slave_facets.empty() or
        !at_origin.degenerate_master_facets.empty())
      continue;
    const double slave_area =
      0.5 * std::abs((x[3] - x[0]) * (x[7] - x[1]) -
                     (x[4] - x[1]) * (x[6] - x[0]));
    for (double shift : { 1e6, 1e8 })
    {
      std::vector<double> moved(x);
      for (std::size_t i = 0; i < moved.size(); ++i)
        moved[i] += shift * (i % 3 == 1 ? -0.5 : 1.0);
      const MortarIntegrals far = pair_integrals(moved, length_scale(moved, 3));
      ASSERT_EQ(far.area.size(), at_origin.area.size()) << "trial " << trial;
      ASSERT_TRUE(far.degenerate_slave_facets.empty());
      if (far.area.empty())
        continue;
      ++compared;
      worst_area = std::max(worst_area,
                            std::abs(far.area[0] - at_origin.area[0]) /
                              slave_area);
      for (std::size_t i = 0; i < far.D.size(); ++i)
        worst_integral = std::max(
          worst_integral, std::abs(far.D[i] - at_origin.D[i]) / slave_area);
      for (std::size_t i = 0; i < far.M.size(); ++i)
        worst_integral = std::max(
          worst_integral, std::abs(far.M[i] - at_origin.M[i]) / slave_area);
      for (std::size_t i = 0; i < far.gap.size(); ++i)
        worst_integral =
          std::max(worst_integral,
                   std::abs(far.gap[i] - at_origin.gap[i]) /
                     (slave_area * size));
    }
  }
  EXPECT_GT(compared, 200);
  EXPECT_LT(worst_area, 1e-12);
  EXPECT_LT(worst_integral, 1e-12);
}
