// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
//
// Overlaps narrower than the zero length, kept or dropped (overlap_of's
// keep_slivers). Two slave pieces against two master pieces whose shared
// node (3D: edge) sits at x = δ next to the slave's at x = 0: the slave
// pieces' overlaps with master 1 measure 1 + δ, those with master 2 1 − δ.
// With an integrand of 1 on master 1 and 2 on master 2, the sum over the
// four pairs has the derivative −1 in δ. Within the zero length of δ = 0 a
// dropped sliver (2D) or a vertex kept on an edge it misses (3D) gave −2
// or 0: the gradient jump the current surface's Newton crept on. (At δ = 0
// exactly, both overlaps end at the slave's node, which is right for an
// integrand continuous across the nodes, as the mortar integrands are, but
// not for this one: it is left out.)
#include <dolfinx_mortar/jet.h>
#include <dolfinx_mortar/piece_overlap.h>

#include <gtest/gtest.h>

#include <functional>
#include <vector>

using namespace dolfinx_mortar;

namespace
{
using J = Jet<1, 1>;
using P = std::array<J, 2>;
using Polygon = std::vector<P>;
constexpr double zero = 1e-10;

// d/dδ Σ_pairs c_m |overlap|, the masters made with their shared side at δ
double
derivative(int gdim,
           double delta,
           bool keep,
           const std::function<Polygon(J, J)>& piece)
{
  const J d = J::variable(delta, 0);
  const std::vector<Polygon> slave = { piece(J(-1.0), J(0.0)),
                                       piece(J(0.0), J(1.0)) };
  const std::vector<Polygon> master = { piece(J(-1.0), d), piece(d, J(1.0)) };
  J sum = 0.0;
  for (const Polygon& s : slave)
    for (int m = 0; m < 2; ++m)
      for (const auto& cell :
           overlap_of<J>(gdim, s, master[m], zero, keep).cells)
        sum += (m + 1.0) * (gdim == 2 ? cell.measure : 0.5 * cell.measure);
  return sum.g[0];
}

Polygon
interval(J x0, J x1)
{
  return { P{ x0, J(0.0) }, P{ x1, J(0.0) } };
}

Polygon
square(J x0, J x1)
{
  return { P{ x0, J(0.0) }, P{ x1, J(0.0) }, P{ x1, J(1.0) }, P{ x0, J(1.0) } };
}
} // namespace

TEST(Slivers, KeptTheOverlapsFollowTheNodesIn2D)
{
  for (double delta : { 0.3, -0.3, 3e-11, -3e-11, 1e-14, -1e-14 })
    EXPECT_NEAR(derivative(2, delta, true, interval), -1.0, 1e-12) << delta;
  EXPECT_NEAR(derivative(2, 3e-11, false, interval), -2.0, 1e-12);
}

TEST(Slivers, KeptTheOverlapsFollowTheNodesIn3D)
{
  for (double delta : { 0.3, -0.3, 3e-11, -3e-11, 1e-14, -1e-14 })
    EXPECT_NEAR(derivative(3, delta, true, square), -1.0, 1e-12) << delta;
  EXPECT_NEAR(derivative(3, 3e-11, false, square), 0.0, 1e-12);
}
