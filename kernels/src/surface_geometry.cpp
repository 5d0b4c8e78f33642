// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#include <dolfinx_mortar/surface_geometry.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace dolfinx_mortar
{

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
  const int nn = facet_num_nodes(s.type), tdim = facet_tdim(s.type);
  facet_shape_functions(s.type, X, N, dN);
  x = { 0, 0, 0 };
  tangents = { Point3{ 0, 0, 0 }, Point3{ 0, 0, 0 } };
  const std::int32_t* nodes = s.cells.data() + c * nn;
  for (int i = 0; i < nn; ++i)
  {
    const double* xi = s.x.data() + nodes[i] * s.gdim;
    for (int k = 0; k < s.gdim; ++k)
    {
      x[k] += N[i] * xi[k];
      for (int j = 0; j < tdim; ++j)
        tangents[j][k] += dN[j * nn + i] * xi[k];
    }
  }
}

Point3
size_weighted_normal(int gdim, const std::array<Point3, 2>& t)
{
  if (gdim == 2)
    return { t[0][1], -t[0][0], 0 };
  return { t[0][1] * t[1][2] - t[0][2] * t[1][1],
           t[0][2] * t[1][0] - t[0][0] * t[1][2],
           t[0][0] * t[1][1] - t[0][1] * t[1][0] };
}

Point3
normal_from_tangents(int gdim, const std::array<Point3, 2>& t)
{
  Point3 n = size_weighted_normal(gdim, t);
  const double norm = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (norm > 0)
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
  Point3 x;
  std::array<Point3, 2> t;
  for (std::size_t c = 0; c < s.num_cells(); ++c)
    for (int i = 0; i < nn; ++i)
    {
      facet_geometry(
        s, c, std::span(nodes.data() + i * tdim, tdim), N, dN, x, t);
      const Point3 n = size_weighted ? size_weighted_normal(s.gdim, t)
                                     : normal_from_tangents(s.gdim, t);
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
  const int nn = facet_num_nodes(s.type), tdim = facet_tdim(s.type);
  const int n = s.gdim;         // unknowns: tdim reference coordinates and t
  std::array<double, 9> Nbuf;   // at most 9 nodes
  std::array<double, 18> dNbuf; // tdim * nodes
  Projection out{ X0, 0.0, false };
  Point3 x;
  std::array<Point3, 2> t;
  // Residuals are judged against the cell's size and position: roundoff in
  // x(X) grows with |x|, so an absolute tolerance fails far from the origin.
  double size = 0, position = 0;
  {
    const std::int32_t* nodes = s.cells.data() + c * nn;
    const double* x0 = s.x.data() + nodes[0] * s.gdim;
    for (int i = 0; i < nn; ++i)
      for (int k = 0; k < s.gdim; ++k)
      {
        const double v = s.x[nodes[i] * s.gdim + k];
        size = std::max(size, std::abs(v - x0[k]));
        position = std::max(position, std::abs(v));
      }
  }
  const double residual_tolerance =
    1e-14 *
    std::max(
      { size, position, std::abs(p[0]), std::abs(p[1]), std::abs(p[2]) });
  for (int it = 0; it < 30; ++it)
  {
    facet_geometry(s,
                   c,
                   std::span(out.X.data(), tdim),
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
    Eigen::Vector3d delta = Eigen::Vector3d::Zero();
    if (n == 2)
    {
      Eigen::Matrix2d J2 = J.topLeftCorner<2, 2>();
      const double det = J2.determinant();
      if (det == 0.0 or !std::isfinite(det))
        return out;
      delta.head<2>() = J2.inverse() * F.head<2>();
    }
    else
    {
      const double det = J.determinant();
      if (det == 0.0 or !std::isfinite(det))
        return out;
      delta = J.inverse() * F;
    }
    for (int j = 0; j < tdim; ++j)
      out.X[j] -= delta[j];
    out.t -= delta[tdim];
    double step = 0;
    for (int j = 0; j < tdim; ++j)
      step = std::max(step, std::abs(delta[j]));
    // A step at roundoff level ends the iteration: the residual cannot fall
    // further.
    if (step < 1e-13)
    {
      out.converged = true;
      return out;
    }
  }
  return out;
}

} // namespace dolfinx_mortar
