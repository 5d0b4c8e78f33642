// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
//
// Property-based stress harness for 3D segmentation (clipping, projection,
// integration) on generated slave–master facet pairs, degenerate ones
// included. For every generated case it checks properties that hold whatever
// the geometry:
//   - no NaN or infinity in any output, no crash, no failed projection;
//   - 0 ≤ covered area ≤ slave area (and ≤ the master's area, coplanar);
//   - a master identical to the slave covers all of it;
//   - additivity: splitting the master in two splits the covered area;
//   - symmetry: swapping slave and master gives the same area (coplanar).
// Usage: stress_segmentation [pairs=1000000] [seed=1]. Exit code 1 on any
// failure, with the first few printed.
#include <dolfinx_mortar/mortar_integrals.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

using namespace dolfinx_mortar;

namespace
{
using Tri = std::array<Point3, 3>;

double
tri_area(const Tri& t)
{
  const Point3 a = { t[1][0] - t[0][0], t[1][1] - t[0][1], t[1][2] - t[0][2] };
  const Point3 b = { t[2][0] - t[0][0], t[2][1] - t[0][1], t[2][2] - t[0][2] };
  const Point3 c = { a[1] * b[2] - a[2] * b[1],
                     a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0] };
  return 0.5 * std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
}

/// Covered area of slave triangle s by master triangle m (P1, one pair).
struct Result
{
  double area;
  bool finite;
  std::int64_t failed;
};

Result
covered_area(const Tri& s, const Tri& m)
{
  std::vector<double> xs, xm, normals;
  for (const auto& p : s)
    xs.insert(xs.end(), p.begin(), p.end());
  for (const auto& p : m)
    xm.insert(xm.end(), p.begin(), p.end());
  const std::vector<std::int32_t> cells = { 0, 1, 2 }, pair = { 0, 0 };
  FacetSurface slave{ FacetType::P1_triangle, 3, xs, cells };
  FacetSurface master{ FacetType::P1_triangle, 3, xm, cells };
  normals = element_node_normals(slave);
  if (!std::isfinite(normals[0]))
    normals.assign(9, 0.0); // degenerate slave: its normal is undefined
  // one-point rule: the weights carry the area exactly
  const std::vector<double> points = { 1.0 / 3, 1.0 / 3 }, weights = { 0.5 };
  SegmentationOptions options;
  options.opposing_normals_only = false;
  const MortarIntegrals r =
    mortar_integrals(slave, normals, master, pair, points, weights, options);
  bool finite = true;
  for (const auto* v : { &r.D, &r.M, &r.gap, &r.area })
    for (double x : *v)
      finite = finite and std::isfinite(x);
  double area = 0;
  for (double a : r.area)
    area += a;
  return { area, finite, r.failed_projections };
}

Tri
reversed(const Tri& t)
{
  return { t[0], t[2], t[1] };
}

struct Generator
{
  std::mt19937_64 rng;
  explicit Generator(std::uint64_t seed)
    : rng(seed)
  {
  }
  double uniform(double a, double b)
  {
    return std::uniform_real_distribution<double>(a, b)(rng);
  }
  int pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng); }
  Point3 point(double z) { return { uniform(-1, 1), uniform(-1, 1), z }; }
  /// A random triangle in the plane z, counter-clockwise seen from +z.
  Tri triangle(double z)
  {
    Tri t = { point(z), point(z), point(z) };
    const double cross = (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) -
                         (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]);
    return cross < 0 ? reversed(t) : t;
  }
  Point3 on_segment(const Point3& a, const Point3& b, double s)
  {
    return { a[0] + s * (b[0] - a[0]),
             a[1] + s * (b[1] - a[1]),
             a[2] + s * (b[2] - a[2]) };
  }
};

/// One generated case: a slave (normal +z) and a master above it (normal −z).
struct Case
{
  Tri slave, master;
  std::string kind;
};

Case
generate(Generator& g)
{
  Tri s = g.triangle(0.0);
  const double z = g.pick(3) == 0 ? 0.0 : g.uniform(-0.1, 0.1);
  auto lift = [&](Tri t)
  {
    for (auto& p : t)
      p[2] = z;
    return reversed(t); // facing down
  };
  switch (g.pick(10))
  {
    case 0:
      return { s, lift(s), "identical" };
    case 1: // shares an edge, lies on the other side
    {
      Point3 p = { s[0][0] + s[1][0] - s[2][0],
                   s[0][1] + s[1][1] - s[2][1],
                   0 };
      Tri t = { s[1], s[0], p };
      return { s, lift(reversed(t)), "shared-edge" };
    }
    case 2: // vertices exactly on the slave's edges and vertices
    {
      Tri t = { g.on_segment(s[0], s[1], 0.5),
                s[1],
                g.on_segment(s[1], s[2], 0.5) };
      return { s, lift(t), "node-on-edge" };
    }
    case 3: // translated along an edge: parallel edges
    {
      const double a = g.uniform(-1, 1);
      Tri t = s;
      for (auto& p : t)
        for (int k = 0; k < 2; ++k)
          p[k] += a * (s[1][k] - s[0][k]);
      return { s, lift(t), "parallel-edges" };
    }
    case 4: // collinear master: zero area
    {
      Tri t = { s[0], g.on_segment(s[0], s[1], g.uniform(0, 1)), s[1] };
      return { s, lift(t), "degenerate-master" };
    }
    case 5: // coincident vertices in the slave
    {
      Tri d = { s[0], s[0], s[1] };
      return { d, lift(g.triangle(0.0)), "degenerate-slave" };
    }
    case 6: // tiny master inside the slave
    {
      const Point3 c = { (s[0][0] + s[1][0] + s[2][0]) / 3,
                         (s[0][1] + s[1][1] + s[2][1]) / 3,
                         0 };
      Tri t;
      for (int i = 0; i < 3; ++i)
        t[i] = g.on_segment(c, s[i], 1e-9);
      return { s, lift(t), "tiny" };
    }
    case 7: // huge master containing the slave
    {
      Tri t = { Point3{ -100, -100, 0 },
                Point3{ 200, -100, 0 },
                Point3{ -100, 200, 0 } };
      return { s, lift(t), "huge" };
    }
    case 8: // nearly touching: master vertex 1e-12 inside an edge
    {
      Tri t = g.triangle(0.0);
      t[0] = g.on_segment(s[0], s[1], 0.5);
      t[0][0] += 1e-12;
      const double cross = (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) -
                           (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]);
      return { s, lift(cross < 0 ? reversed(t) : t), "near-touching" };
    }
    default:
      return { s, lift(g.triangle(0.0)), "random" };
  }
}

} // namespace

int
main(int argc, char** argv)
{
  const long pairs = argc > 1 ? std::atol(argv[1]) : 1000000;
  const std::uint64_t seed = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : 1;
  Generator g(seed);
  long failures = 0, checks = 0;
  auto fail = [&](const Case& c, const std::string& what, double a, double b)
  {
    if (++failures <= 10)
      std::printf(
        "FAIL %s (%s): %.17g vs %.17g\n", what.c_str(), c.kind.c_str(), a, b);
  };
  for (long i = 0; i < pairs; ++i)
  {
    const Case c = generate(g);
    const double as = tri_area(c.slave), am = tri_area(c.master);
    const double tol = 1e-10 * std::max(as, 1e-300) + 1e-14;
    const Result r = covered_area(c.slave, c.master);
    ++checks;
    if (!r.finite or r.failed != 0)
      fail(c, "non-finite output or failed projection", r.area, 0);
    if (r.area < 0 or r.area > as + tol)
      fail(c, "covered area outside [0, slave area]", r.area, as);
    if (c.master[0][2] == 0.0 and r.area > am + tol)
      fail(c, "covered area above master area", r.area, am);
    if (c.kind == "identical" and std::abs(r.area - as) > tol)
      fail(c, "identical master does not cover the slave", r.area, as);
    if (c.kind == "huge" and std::abs(r.area - as) > tol)
      fail(c, "containing master does not cover the slave", r.area, as);
    if (c.kind == "random" or c.kind == "node-on-edge")
    {
      // additivity: split the master at a point of its edge 1-2
      const Tri& m = c.master;
      const Point3 p = g.on_segment(m[1], m[2], g.uniform(0.0, 1.0));
      const Result r1 = covered_area(c.slave, Tri{ m[0], m[1], p });
      const Result r2 = covered_area(c.slave, Tri{ m[0], p, m[2] });
      ++checks;
      if (std::abs(r1.area + r2.area - r.area) > tol)
        fail(c,
             "area not additive over a split master",
             r1.area + r2.area,
             r.area);
      if (c.master[0][2] == 0.0)
      {
        // symmetry on coplanar pairs: swap roles (and orientations)
        const Result rs = covered_area(reversed(c.master), reversed(c.slave));
        ++checks;
        if (std::abs(rs.area - r.area) > 1e-10 * std::max(as, am) + 1e-14)
          fail(c, "area not symmetric", rs.area, r.area);
      }
    }
  }
  std::printf("stress_segmentation: %ld generated pairs, %ld checks, %ld "
              "failures (seed %llu)\n",
              pairs,
              checks,
              failures,
              static_cast<unsigned long long>(seed));
  return failures == 0 ? 0 : 1;
}
