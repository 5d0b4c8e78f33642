// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
//
// Fuzz harness for 3D segmentation (clipping, projection, integration) on
// generated slave–master P1 triangle pairs, the hard ones included:
// near-coincident facets (relative perturbations 1e-16 … 1e-8, as two
// separately meshed conforming faces are), slivers (aspect up to 1e8),
// coincident vertices, a node on an edge, parallel edges, zero-area overlaps,
// degenerate facets, and sizes from 1e-6 to 1e2 at coordinates up to 1e6.
//
// Each pair is built in a local frame (u, v, w) — the slave in w = 0 — and
// placed in space by a scale, a rotation and an offset. The covered area is
// checked against an independent computation: the intersection of the two
// triangles in the local (u, v) plane, by half-plane clipping in binary128
// arithmetic without any tolerance. Its classification and its crossing
// points come from the same signed distances, so a wrong sign (|s| ~ 1e-33 L)
// moves the area by at most that distance times the perimeter: no exact
// predicate is needed for the area.
//
// Checks, per case:
//   - no NaN or infinity in any output, no failed projection;
//   - |covered − exact| ≤ 1e-8·A_slave + zero_length·(P_slave + P_master),
//     the second term the area a classification within zero_length of an
//     edge may move (zero_length = geometric_tolerance × length scale);
//   - covered ≤ A_slave + the same tolerance;
//   - a facet degenerate by construction is reported as degenerate, and one
//     whose height is far above zero_length is not.
// Usage: stress_segmentation [pairs=1000000] [seed=1] [category: whose worst
// pair to print]. Prints the failures by
// category and exits with 1 on any.
#include <dolfinx_mortar/geometric_tolerance.h>
#include <dolfinx_mortar/mortar_integrals.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <span>
#include <random>
#include <string>
#include <vector>

using namespace dolfinx_mortar;

namespace
{
using Local = std::array<double, 3>; // (u, v, w) in the pair's frame
using Tri = std::array<Local, 3>;

/// Intersection area of two triangles in the (u, v) plane, independent of
/// the kernels: binary128 half-plane clipping with no tolerance.
using Quad = __float128;
struct QPoint
{
  Quad u, v;
};

Quad
q_area(const std::vector<QPoint>& p)
{
  Quad a = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
  {
    const QPoint& a0 = p[i];
    const QPoint& a1 = p[(i + 1) % p.size()];
    a += a0.u * a1.v - a1.u * a0.v;
  }
  return a / 2;
}

std::vector<QPoint>
q_polygon(const Tri& t)
{
  std::vector<QPoint> p;
  for (const Local& x : t)
    p.push_back({ Quad(x[0]), Quad(x[1]) });
  if (q_area(p) < 0)
    std::reverse(p.begin(), p.end());
  return p;
}

double
exact_overlap(const Tri& s, const Tri& m)
{
  std::vector<QPoint> out = q_polygon(s), in;
  const std::vector<QPoint> clip = q_polygon(m);
  if (q_area(clip) == 0 or q_area(out) == 0)
    return 0.0; // a segment or a point covers no area
  for (std::size_t e = 0; e < clip.size() and !out.empty(); ++e)
  {
    const QPoint a = clip[e], b = clip[(e + 1) % clip.size()];
    // left of a→b is inside; the scale of s does not matter, only its sign
    // and ratios
    auto side = [&](const QPoint& p)
    { return (b.u - a.u) * (p.v - a.v) - (b.v - a.v) * (p.u - a.u); };
    in.swap(out);
    out.clear();
    for (std::size_t i = 0; i < in.size(); ++i)
    {
      const QPoint p = in[i], q = in[(i + 1) % in.size()];
      const Quad sp = side(p), sq = side(q);
      if (sp >= 0)
        out.push_back(p);
      if ((sp > 0 and sq < 0) or (sp < 0 and sq > 0))
      {
        const Quad t = sp / (sp - sq); // in (0, 1): signs strictly differ
        out.push_back({ p.u + t * (q.u - p.u), p.v + t * (q.v - p.v) });
      }
    }
  }
  return out.size() < 3 ? 0.0 : static_cast<double>(q_area(out));
}

double
area_of(const Tri& t)
{
  return std::abs(static_cast<double>(q_area(q_polygon(t))));
}

double
perimeter(const Tri& t)
{
  double p = 0;
  for (int i = 0; i < 3; ++i)
    p += std::hypot(t[(i + 1) % 3][0] - t[i][0], t[(i + 1) % 3][1] - t[i][1]);
  return p;
}

/// Smallest height (twice the area over the longest edge) in (u, v).
double
min_height(const Tri& t)
{
  double longest = 0;
  for (int i = 0; i < 3; ++i)
    longest = std::max(
      longest,
      std::hypot(t[(i + 1) % 3][0] - t[i][0], t[(i + 1) % 3][1] - t[i][1]));
  return longest > 0 ? 2 * area_of(t) / longest : 0.0;
}

/// Smallest height of a triangle placed in space (x: 3 points × 3
/// coordinates), relative to its first vertex: what the kernels measure.
double
placed_min_height(std::span<const double> x)
{
  double e[3][3];
  double longest = 0;
  for (int i = 0; i < 3; ++i)
  {
    const int j = (i + 1) % 3;
    for (int k = 0; k < 3; ++k)
      e[i][k] = x[3 * j + k] - x[3 * i + k];
    longest = std::max(longest, std::hypot(e[i][0], e[i][1], e[i][2]));
  }
  const double c[3] = { e[0][1] * e[1][2] - e[0][2] * e[1][1],
                        e[0][2] * e[1][0] - e[0][0] * e[1][2],
                        e[0][0] * e[1][1] - e[0][1] * e[1][0] };
  return longest > 0 ? std::hypot(c[0], c[1], c[2]) / longest : 0.0;
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
  Local point() { return { uniform(-1, 1), uniform(-1, 1), 0 }; }
  /// A random triangle, counter-clockwise about +w, not too flat.
  Tri triangle()
  {
    for (;;)
    {
      Tri t = { point(), point(), point() };
      if (min_height(t) > 1e-3)
        return area_signed(t) < 0 ? reversed(t) : t;
    }
  }
  static double area_signed(const Tri& t)
  {
    return static_cast<double>(q_area(
      { { t[0][0], t[0][1] }, { t[1][0], t[1][1] }, { t[2][0], t[2][1] } }));
  }
  static Local on_segment(const Local& a, const Local& b, double s)
  {
    return { a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]), 0 };
  }
  /// x moved by relative·size in a random direction
  Local nudge(const Local& x, double size, double relative)
  {
    const double angle = uniform(0, 2 * M_PI);
    return { x[0] + relative * size * std::cos(angle),
             x[1] + relative * size * std::sin(angle),
             x[2] };
  }
  /// A sliver on the base a–b: height 10^-k of the base, k up to 8.
  Tri sliver(double log_aspect)
  {
    const Tri t = triangle();
    const double aspect = std::pow(10.0, -log_aspect);
    const Local m = on_segment(t[0], t[1], uniform(-0.5, 1.5));
    const double ex = t[1][0] - t[0][0], ey = t[1][1] - t[0][1];
    return { t[0], t[1], Local{ m[0] - aspect * ey, m[1] + aspect * ex, 0 } };
  }
};

/// One generated case in the local frame: slave in w = 0 (normal +w), master
/// above or below it facing −w.
struct Case
{
  Tri slave, master; // master counter-clockwise about +w here; flipped later
  std::string kind;
  bool slave_degenerate = false, master_degenerate = false;
};

Case
generate(Generator& g)
{
  const Tri s = g.triangle();
  const double size = 2.0; // the local triangles' scale
  switch (g.pick(17))
  {
    case 0:
      return { s, s, "identical" };
    case 1: // every vertex moved by 1e-16 … 1e-8 of the size
    {
      const double rel = std::pow(10.0, g.uniform(-16, -8));
      Tri m;
      const int shift = g.pick(3); // another first vertex
      for (int i = 0; i < 3; ++i)
        m[i] = g.nudge(s[(i + shift) % 3], size, rel);
      return { s, m, "near-coincident" };
    }
    case 2: // translated by 1e-16 … 1e-8: near-coincident parallel edges
    {
      const double rel = std::pow(10.0, g.uniform(-16, -8));
      const Local d = g.nudge({ 0, 0, 0 }, size, rel);
      Tri m = s;
      for (auto& p : m)
        p = { p[0] + d[0], p[1] + d[1], 0 };
      return { s, m, "near-coincident-shifted" };
    }
    case 3: // the neighbour across an edge, round-off apart: zero-area
    {
      const double rel = std::pow(10.0, g.uniform(-16, -8));
      const Local p = { s[0][0] + s[1][0] - s[2][0],
                        s[0][1] + s[1][1] - s[2][1],
                        0 };
      Tri m = { g.nudge(s[1], size, rel), g.nudge(s[0], size, rel), p };
      return { s, m, "near-coincident-neighbour" };
    }
    case 4: // shares an edge, lies on the other side: zero-area overlap
    {
      const Local p = { s[0][0] + s[1][0] - s[2][0],
                        s[0][1] + s[1][1] - s[2][1],
                        0 };
      return { s, Tri{ s[1], s[0], p }, "shared-edge" };
    }
    case 5: // vertices on the slave's edges and vertices
      return { s,
               Tri{ Generator::on_segment(s[0], s[1], 0.5),
                    s[1],
                    Generator::on_segment(s[1], s[2], 0.5) },
               "node-on-edge" };
    case 6: // translated along an edge: parallel edges
    {
      const double a = g.uniform(-1, 1);
      Tri m = s;
      for (auto& p : m)
        for (int k = 0; k < 2; ++k)
          p[k] += a * (s[1][k] - s[0][k]);
      return { s, m, "parallel-edges" };
    }
    case 7: // collinear master
    {
      Case c{
        s,
        Tri{ s[0], Generator::on_segment(s[0], s[1], g.uniform(0, 1)), s[1] },
        "degenerate-master"
      };
      c.master_degenerate = true;
      return c;
    }
    case 8: // coincident vertices in the slave
    {
      Case c{ Tri{ s[0], s[0], s[1] }, g.triangle(), "degenerate-slave" };
      c.slave_degenerate = true;
      return c;
    }
    case 9: // sliver slave under a random or near-coincident master
    {
      const Tri t = g.sliver(g.uniform(0, 8));
      if (g.pick(2) == 0)
        return { t, g.triangle(), "sliver-slave" };
      const double rel = std::pow(10.0, g.uniform(-16, -8));
      return { t,
               Tri{ g.nudge(t[0], size, rel),
                    g.nudge(t[1], size, rel),
                    g.nudge(t[2], size, rel) },
               "sliver-near-coincident" };
    }
    case 10:
      return { s, g.sliver(g.uniform(0, 8)), "sliver-master" };
    case 11: // tiny master inside the slave
    {
      const Local c = { (s[0][0] + s[1][0] + s[2][0]) / 3,
                        (s[0][1] + s[1][1] + s[2][1]) / 3,
                        0 };
      const double f = std::pow(10.0, g.uniform(-6, -1));
      return { s,
               Tri{ Generator::on_segment(c, s[0], f),
                    Generator::on_segment(c, s[1], f),
                    Generator::on_segment(c, s[2], f) },
               "tiny-master" };
    }
    case 12: // master containing the slave
      return {
        s,
        Tri{ Local{ -10, -10, 0 }, Local{ 20, -10, 0 }, Local{ -10, 20, 0 } },
        "containing-master"
      };
    case 13: // master vertex 1e-12 … 1e-8 off the middle of an edge
    {
      Tri t = g.triangle();
      t[0] = g.nudge(Generator::on_segment(s[0], s[1], 0.5),
                     size,
                     std::pow(10.0, g.uniform(-12, -8)));
      return { s,
               Generator::area_signed(t) < 0 ? reversed(t) : t,
               "near-touching" };
    }
    case 14: // touching at a vertex only: zero-area overlap
    {
      const Local p = s[0];
      const Local a = { 2 * p[0] - s[1][0], 2 * p[1] - s[1][1], 0 };
      const Local b = { 2 * p[0] - s[2][0], 2 * p[1] - s[2][1], 0 };
      return { s, Tri{ p, a, b }, "vertex-touch" };
    }
    case 15: // two vertices shared, the third anywhere
    {
      Tri m = { s[0], s[1], g.point() };
      if (Generator::area_signed(m) < 0)
        m = reversed(m);
      if (min_height(m) < 1e-3)
        m[2] = s[2];
      return { s, m, "coincident-vertices" };
    }
    default:
      return { s, g.triangle(), "random" };
  }
}

/// A random rotation (uniform enough for testing) as rows of a matrix.
std::array<Local, 3>
rotation(Generator& g)
{
  if (g.pick(4) == 0) // axis-aligned: exactly planar coordinates
    return { Local{ 1, 0, 0 }, Local{ 0, 1, 0 }, Local{ 0, 0, 1 } };
  Local a = { g.uniform(-1, 1), g.uniform(-1, 1), g.uniform(-1, 1) };
  Local b = { g.uniform(-1, 1), g.uniform(-1, 1), g.uniform(-1, 1) };
  auto unit = [](Local v)
  {
    const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    return Local{ v[0] / n, v[1] / n, v[2] / n };
  };
  a = unit(a);
  const double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  b = unit({ b[0] - d * a[0], b[1] - d * a[1], b[2] - d * a[2] });
  const Local c = { a[1] * b[2] - a[2] * b[1],
                    a[2] * b[0] - a[0] * b[2],
                    a[0] * b[1] - a[1] * b[0] };
  return { a, b, c };
}

struct Placement
{
  double scale;
  Local offset;
  std::array<Local, 3> axes; // local u, v, w directions in space
  std::vector<double> place(const Tri& t, const std::array<double, 3>& w) const
  {
    std::vector<double> x;
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k)
        x.push_back(offset[k] +
                    scale * (t[i][0] * axes[0][k] + t[i][1] * axes[1][k] +
                             w[i] * axes[2][k]));
    return x;
  }
};

struct Result
{
  double area = 0;
  bool finite = true;
  std::int64_t failed = 0;
  bool slave_reported = false, master_reported = false;
};

Result
covered_area(const std::vector<double>& xs, const std::vector<double>& xm)
{
  const std::vector<std::int32_t> cells = { 0, 1, 2 }, pair = { 0, 0 };
  FacetSurface slave{ FacetType::P1_triangle, 3, xs, cells };
  FacetSurface master{ FacetType::P1_triangle, 3, xm, cells };
  std::vector<double> normals = element_node_normals(slave);
  for (double& v : normals)
    if (!std::isfinite(v))
      v = 0.0; // degenerate slave: its normal is undefined
  // one-point rule: the weights carry the area exactly
  const std::vector<double> points = { 1.0 / 3, 1.0 / 3 }, weights = { 0.5 };
  SegmentationOptions options;
  options.opposing_normals_only = false;
  const MortarIntegrals r =
    mortar_integrals(slave, normals, master, pair, points, weights, options);
  Result out;
  for (const auto* v : { &r.D, &r.M, &r.gap, &r.area })
    for (double x : *v)
      out.finite = out.finite and std::isfinite(x);
  for (double a : r.area)
    out.area += a;
  out.failed = r.failed_projections;
  out.slave_reported = !r.degenerate_slave_facets.empty();
  out.master_reported = !r.degenerate_master_facets.empty();
  return out;
}

} // namespace

int
main(int argc, char** argv)
{
  const long pairs = argc > 1 ? std::atol(argv[1]) : 1000000;
  const std::uint64_t seed = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : 1;
  Generator g(seed);
  // the worst pair printed: of this category only, when given
  const std::string only_kind = argc > 3 ? argv[3] : "";
  std::map<std::string, long> cases;
  std::map<std::string, double> worst_by_kind; // |covered − exact| / A_slave
  std::map<std::string, std::map<std::string, long>> failures;
  double worst_over = 0; // largest (covered − slave area) / slave area
  std::string worst_kind;
  // largest |covered − exact| / slave area, with the pair (hex: exact input
  // for a regression test) and the number of pairs above 1e-6
  double worst_error = 0;
  long above_1e6 = 0;
  std::string worst_error_kind;
  std::vector<double> worst_xs, worst_xm;
  double worst_exact = 0, worst_covered = 0;
  long total_failures = 0;
  const auto start = std::chrono::steady_clock::now();
  for (long i = 0; i < pairs; ++i)
  {
    const Case c = generate(g);
    Placement where{ std::pow(10.0, g.uniform(-6, 2)), {}, rotation(g) };
    // Offsets up to 1e6, at most 1e6 times the size: smaller facets at that
    // distance are below the shared tolerance and degenerate by definition.
    const double e = std::log10(where.scale);
    double reach =
      std::pow(10.0, g.uniform(std::min(-3.0, e), std::min(6.0, e + 6)));
    const double heights = std::min(min_height(c.slave), min_height(c.master));
    if (!c.slave_degenerate and !c.master_degenerate and heights > 0)
      // a sliver keeps its height 1e3 × above the zero length
      reach =
        std::min(reach, where.scale * heights / (1e3 * geometric_tolerance));
    where.offset = { reach * g.uniform(-1, 1),
                     reach * g.uniform(-1, 1),
                     reach * g.uniform(-1, 1) };
    // the master above, below or in the slave's plane, sometimes tilted
    std::array<double, 3> w = { 0, 0, 0 };
    const int height = g.pick(3);
    if (height > 0)
    {
      const double z = g.uniform(-0.1, 0.1);
      for (int k = 0; k < 3; ++k)
        w[k] = z + (height == 2 ? g.uniform(-0.05, 0.05) : 0.0);
    }
    const std::vector<double> xs = where.place(c.slave, { 0, 0, 0 });
    // facing the slave: clockwise about +w
    const std::vector<double> xm =
      where.place(reversed(c.master), { w[0], w[2], w[1] });

    std::vector<double> all = xs;
    all.insert(all.end(), xm.begin(), xm.end());
    const double zero = zero_length(all, 3);
    const double S2 = where.scale * where.scale;
    const double as = area_of(c.slave) * S2;
    const double exact = exact_overlap(c.slave, c.master) * S2;
    // The slave's normal is known to round-off over its height: a master at
    // distance w is projected off by w·ε·L/h_slave, which moves the overlap
    // by that times the slave's perimeter (the conditioning of a sliver's
    // normal, not an error of the clipping).
    const double w_max =
      where.scale *
      std::max({ std::abs(w[0]), std::abs(w[1]), std::abs(w[2]) });
    const double h_slave = min_height(c.slave) * where.scale;
    const double tilt =
      h_slave > 0 ? 8 * 2.2e-16 * (zero / geometric_tolerance) / h_slave : 0.0;
    const double tol =
      1e-8 * as +
      zero * where.scale * (perimeter(c.slave) + perimeter(c.master)) +
      tilt * w_max * where.scale * perimeter(c.slave);

    const Result r = covered_area(xs, xm);
    const double slave_h = min_height(c.slave) * where.scale;
    const double master_h = min_height(c.master) * where.scale;
    ++cases[c.kind];
    auto fail = [&](const char* what, double a, double b)
    {
      ++total_failures;
      if (++failures[c.kind][what] <= 2)
        std::printf("FAIL %-24s %-40s got %.10g expected %.10g (tol %.3g, "
                    "size %.3g, offset %.3g)\n",
                    c.kind.c_str(),
                    what,
                    a,
                    b,
                    tol,
                    where.scale,
                    reach);
    };
    const bool regular = slave_h > 100 * zero and master_h > 100 * zero;
    if (!r.finite or (regular and r.failed != 0))
      fail("non-finite output or failed projection",
           static_cast<double>(r.failed),
           r.finite ? 1.0 : 0.0);
    if (std::abs(r.area - exact) > tol)
      fail("covered area differs from the exact one", r.area, exact);
    if (r.area > as + tol)
      fail("covered area above the slave area", r.area, as);
    // The area error relative to the slave's, where the slave's normal is
    // known well enough for 1e-6 (its conditioning, the tilt term above, is
    // not the clipping's)
    if (as > 0 and tilt * w_max * where.scale * perimeter(c.slave) < 1e-7 * as)
    {
      const double error = std::abs(r.area - exact) / as;
      above_1e6 += error > 1e-6;
      worst_by_kind[c.kind] = std::max(worst_by_kind[c.kind], error);
      if (error > worst_error and (only_kind.empty() or c.kind == only_kind))
      {
        worst_error = error;
        worst_error_kind = c.kind;
        worst_xs = xs;
        worst_xm = xm;
        worst_exact = exact;
        worst_covered = r.area;
      }
    }
    if (as > 0 and (r.area - as) / as > worst_over)
    {
      worst_over = (r.area - as) / as;
      worst_kind = c.kind;
    }
    if (c.slave_degenerate and !r.slave_reported)
      fail("degenerate slave not reported", 0, 1);
    // (a tilted collinear master is a facet seen edge-on, not degenerate;
    // placed far from the origin, a collinear master is only as collinear as
    // its rounded coordinates: with the extent as the length scale, a height
    // above the zero length is a real, if thin, facet)
    if (c.master_degenerate and height < 2 and !c.slave_degenerate and
        placed_min_height(xm) <= zero and !r.master_reported)
      fail("degenerate master not reported", 0, 1);
    if (slave_h > 100 * zero and r.slave_reported)
      fail("regular slave reported degenerate", slave_h, zero);
    if (master_h > 100 * zero and r.master_reported)
      fail("regular master reported degenerate", master_h, zero);
  }
  const double seconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
      .count();
  std::printf("%-26s %9s %9s %12s\n",
              "category",
              "cases",
              "failures",
              "worst err/A");
  for (const auto& [kind, n] : cases)
  {
    long f = 0;
    for (const auto& [what, count] : failures[kind])
      f += count;
    std::printf(
      "%-26s %9ld %9ld %12.3g\n", kind.c_str(), n, f, worst_by_kind[kind]);
    for (const auto& [what, count] : failures[kind])
      std::printf("    %-46s %9ld\n", what.c_str(), count);
  }
  std::printf("largest covered/slave area excess: %.3g (%s)\n",
              worst_over,
              worst_kind.c_str());
  std::printf("largest |covered − exact|/slave area: %.3g (%s), %ld pairs "
              "above 1e-6\n",
              worst_error,
              worst_error_kind.c_str(),
              above_1e6);
  if (!worst_xs.empty())
  {
    std::printf("  covered %a exact %a\n", worst_covered, worst_exact);
    for (const auto* x : { &worst_xs, &worst_xm })
    {
      std::printf("  %s", x == &worst_xs ? "slave " : "master");
      for (double v : *x)
        std::printf(" %a", v);
      std::printf("\n");
    }
  }
  std::printf("stress_segmentation: %ld generated pairs, %ld failures, %.1f s "
              "(seed %llu)\n",
              pairs,
              total_failures,
              seconds,
              static_cast<unsigned long long>(seed));
  return total_failures == 0 ? 0 : 1;
}
