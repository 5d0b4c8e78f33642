// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#include <dolfinx_mortar/geometric_tolerance.h>
#include <dolfinx_mortar/pair_segmentation.h>
#include <dolfinx_mortar/surface_geometry.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace dolfinx_mortar
{

void
gather_cell_nodes(const FacetSurface& s, std::size_t c, std::span<double> out)
{
  const int nn = facet_num_nodes(s.type);
  const std::int32_t* nodes = s.cells.data() + c * nn;
  for (int i = 0; i < nn; ++i)
    std::copy_n(
      s.x.data() + nodes[i] * s.gdim, s.gdim, out.data() + i * s.gdim);
}

void
FacetSurface::check() const
{
  const int nn = facet_num_nodes(type);
  if (gdim != facet_tdim(type) + 1)
    throw std::invalid_argument(to_string(type) + " facets need gdim " +
                                std::to_string(facet_tdim(type) + 1) +
                                ", got " + std::to_string(gdim));
  if (x.size() % gdim != 0 or cells.size() % nn != 0)
    throw std::invalid_argument("surface arrays must have shapes (nodes, gdim) "
                                "and (cells, nodes per cell)");
  const auto num_nodes = static_cast<std::int32_t>(x.size() / gdim);
  for (std::int32_t v : cells)
    if (v < 0 or v >= num_nodes)
      throw std::invalid_argument("cell node index out of range");
  // NaN fails every comparison: left in, it would make facets silently
  // non-degenerate, non-overlapping or unprojectable
  for (std::size_t i = 0; i < x.size(); ++i)
    if (!std::isfinite(x[i]))
    {
      const std::size_t node = i / gdim;
      std::string coords;
      for (int k = 0; k < gdim; ++k)
        coords += (k ? ", " : "") + std::to_string(x[node * gdim + k]);
      throw std::invalid_argument("node " + std::to_string(node) +
                                  " has a non-finite coordinate (" + coords +
                                  ")");
    }
}

void
facet_geometry(const FacetSurface& s,
               std::size_t c,
               std::span<const double> X,
               std::span<double> N,
               std::span<double> dN,
               Point3& x,
               std::array<Point3, 2>& tangents)
{
  std::array<double, 27> nodes; // at most 9 nodes × 3
  const int nn = facet_num_nodes(s.type);
  gather_cell_nodes(s, c, nodes);
  cell_geometry<double>(s.type,
                        s.gdim,
                        std::span<const double>(nodes.data(), nn * s.gdim),
                        X,
                        N,
                        dN,
                        x,
                        tangents);
}

Point3
normal_from_tangents(int gdim, const std::array<Point3, 2>& t, double zero)
{
  Point3 n = size_weighted_normal(gdim, t);
  const double norm = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  // 3D: |n| over the longer tangent is the height of the tangent
  // parallelogram; 2D: |n| is the tangent's length
  const double longest =
    gdim == 2 ? 1.0
              : std::sqrt(std::max(
                  t[0][0] * t[0][0] + t[0][1] * t[0][1] + t[0][2] * t[0][2],
                  t[1][0] * t[1][0] + t[1][1] * t[1][1] + t[1][2] * t[1][2]));
  if (!(norm > zero * longest))
    return { 0, 0, 0 };
  for (double& v : n)
    v /= norm;
  return n;
}

std::vector<double>
facet_reference_nodes(FacetType type)
{
  switch (type)
  {
    case FacetType::P1_line:
      return { 0, 1 };
    case FacetType::P2_line:
      return { 0, 1, 0.5 };
    case FacetType::P1_triangle:
      return { 0, 0, 1, 0, 0, 1 };
    case FacetType::P2_triangle:
      return { 0, 0, 1, 0, 0, 1, 0.5, 0.5, 0, 0.5, 0.5, 0 };
    case FacetType::Q1_quadrilateral:
      return { 0, 0, 1, 0, 0, 1, 1, 1 };
    case FacetType::Q2_quadrilateral:
      return {
        0, 0, 1, 0, 0, 1, 1, 1, 0.5, 0, 0, 0.5, 1, 0.5, 0.5, 1, 0.5, 0.5
      };
    case FacetType::Q8_quadrilateral:
      return { 0, 0, 1, 0, 0, 1, 1, 1, 0.5, 0, 0, 0.5, 1, 0.5, 0.5, 1 };
  }
  throw std::logic_error("corrupt FacetType");
}

std::vector<double>
element_node_normals(const FacetSurface& s, bool size_weighted)
{
  s.check();
  const int nn = facet_num_nodes(s.type), tdim = facet_tdim(s.type);
  const std::vector<double> nodes = facet_reference_nodes(s.type);
  std::vector<double> N(nn), dN(tdim * nn), out(s.num_cells() * nn * s.gdim);
  const double zero = zero_length(s.x, s.gdim);
  Point3 x;
  std::array<Point3, 2> t;
  for (std::size_t c = 0; c < s.num_cells(); ++c)
    for (int i = 0; i < nn; ++i)
    {
      facet_geometry(
        s, c, std::span(nodes.data() + i * tdim, tdim), N, dN, x, t);
      const Point3 n = size_weighted ? size_weighted_normal(s.gdim, t)
                                     : normal_from_tangents(s.gdim, t, zero);
      std::copy_n(n.begin(), s.gdim, out.begin() + (c * nn + i) * s.gdim);
    }
  return out;
}

std::vector<double>
facet_bounding_boxes(const FacetSurface& s, double margin)
{
  s.check();
  const int nn = facet_num_nodes(s.type);
  std::vector<double> boxes(6 * s.num_cells());
  for (std::size_t c = 0; c < s.num_cells(); ++c)
  {
    double* b = boxes.data() + 6 * c;
    std::fill_n(b, 3, 1e300);
    std::fill_n(b + 3, 3, -1e300);
    for (int i = 0; i < nn; ++i)
    {
      const double* xi = s.x.data() + s.cells[c * nn + i] * s.gdim;
      for (int k = 0; k < 3; ++k)
      {
        const double v = k < s.gdim ? xi[k] : 0.0;
        b[k] = std::min(b[k], v - margin);
        b[k + 3] = std::max(b[k + 3], v + margin);
      }
    }
  }
  return boxes;
}

Projection
project_along(const FacetSurface& s,
              std::size_t c,
              const Point3& p,
              const Point3& direction,
              std::array<double, 2> X0)
{
  std::array<double, 27> nodes; // at most 9 nodes × 3
  gather_cell_nodes(s, c, nodes);
  return project_along(
    s.type,
    s.gdim,
    std::span<const double>(nodes.data(), facet_num_nodes(s.type) * s.gdim),
    p,
    direction,
    X0);
}

Projection
project_along(FacetType type,
              int gdim,
              std::span<const double> cell_nodes,
              const Point3& p,
              const Point3& direction,
              std::array<double, 2> X0)
{
  const int nn = facet_num_nodes(type), tdim = facet_tdim(type);
  const int n = gdim;           // unknowns: tdim reference coordinates and t
  std::array<double, 9> Nbuf;   // at most 9 nodes
  std::array<double, 18> dNbuf; // tdim * nodes
  Projection out{ X0, 0.0, false };
  Point3 x;
  std::array<Point3, 2> t;
  // Residuals are judged against the cell's size and position: roundoff in
  // x(X) grows with |x|, so an absolute tolerance fails far from the origin.
  // The same scale judges a singular Jacobian and a step at round-off.
  double size = 0, position = 0;
  for (int i = 0; i < nn; ++i)
    for (int k = 0; k < gdim; ++k)
    {
      const double v = cell_nodes[i * gdim + k];
      size = std::max(size, std::abs(v - cell_nodes[k]));
      position = std::max(position, std::abs(v));
    }
  const double scale = std::max(
    { size, position, std::abs(p[0]), std::abs(p[1]), std::abs(p[2]) });
  // Newton's residual target: a few round-offs of x(X), far below the zero
  // length (the projected point must be accurate, not just "not apart")
  const double residual_tolerance = 1e-14 * scale;
  const double zero =
    std::max(geometric_tolerance * scale, std::numeric_limits<double>::min());
  for (int it = 0; it < 30; ++it)
  {
    cell_geometry<double>(type,
                          gdim,
                          cell_nodes,
                          std::span<const double>(out.X.data(), tdim),
                          std::span(Nbuf.data(), nn),
                          std::span(dNbuf.data(), tdim * nn),
                          x,
                          t);
    Eigen::Matrix3d J = Eigen::Matrix3d::Identity();
    Eigen::Vector3d F(0, 0, 0);
    double residual = 0;
    for (int k = 0; k < n; ++k)
    {
      F[k] = x[k] - p[k] - out.t * direction[k];
      residual = std::max(residual, std::abs(F[k]));
      for (int j = 0; j < tdim; ++j)
        J(k, j) = t[j][k];
      J(k, tdim) = -direction[k];
    }
    if (residual <= residual_tolerance)
    {
      out.converged = true;
      return out;
    }
    // The columns are the tangents (lengths) and the direction: the
    // determinant over the longest tangent projected along the direction is
    // the height of the tangents' projected parallelogram (2D: the projected
    // tangent's length). At most the zero length: the facet is degenerate or
    // seen edge-on, and has no projection.
    const Eigen::Vector3d d(direction[0], direction[1], direction[2]);
    const double dd = d.squaredNorm();
    double longest = 0;
    for (int j = 0; j < tdim; ++j)
    {
      const Eigen::Vector3d tj = J.col(j);
      longest = std::max(longest, (tj - (tj.dot(d) / dd) * d).norm());
    }
    Eigen::Vector3d delta = Eigen::Vector3d::Zero();
    if (n == 2)
    {
      Eigen::Matrix2d J2 = J.topLeftCorner<2, 2>();
      const double det = J2.determinant();
      if (!(std::abs(det) > zero * std::sqrt(dd))) // NaN too
        return out;
      delta.head<2>() = J2.inverse() * F.head<2>();
    }
    else
    {
      const double det = J.determinant();
      if (!(std::abs(det) > zero * longest * std::sqrt(dd)))
        return out;
      delta = J.inverse() * F;
    }
    for (int j = 0; j < tdim; ++j)
      out.X[j] -= delta[j];
    out.t -= delta[tdim];
    // The step's physical length: reference steps times the tangents, plus
    // the move along the unit direction.
    double step = std::abs(delta[tdim]);
    for (int j = 0; j < tdim; ++j)
      step = std::max(step, std::abs(delta[j]) * J.col(j).head(n).norm());
    // A step below the zero length ends the iteration: Newton converges
    // quadratically, so what remains is far below it, and the residual may
    // not reach its target at round-off level.
    if (step <= zero)
    {
      out.converged = true;
      return out;
    }
  }
  return out;
}

} // namespace dolfinx_mortar
