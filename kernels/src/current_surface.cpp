// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT

#include "dolfinx_mortar/current_surface.h"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>

namespace dolfinx_mortar
{

void
SurfaceCells::check() const
{
  if (gdim < 2 or gdim > 3 or tdim != gdim - 1 or nodes < 2 or nodes > 9)
    throw std::invalid_argument(
      "surface cells: gdim 2 or 3, tdim = gdim - 1, 2 to 9 nodes per cell");
  if (x.size() % static_cast<std::size_t>(nodes * gdim) != 0)
    throw std::invalid_argument("x must have shape (cells, nodes, gdim)");
  const std::size_t q = weights.size();
  if (N.size() != q * nodes or phi.size() != q * nodes or
      dN.size() != q * tdim * nodes)
    throw std::invalid_argument(
      "N and phi must have shape (points, nodes), dN (points, tdim, nodes)");
  if (axisymmetric and gdim != 2)
    throw std::invalid_argument(
      "axisymmetric cells are (r, z) lines: gdim must be 2");
}

namespace
{

void
check_obstacle(const SurfaceCells& s, const ObstacleAtPoints& ob)
{
  const std::size_t n = s.num_cells() * s.num_points();
  const auto g = static_cast<std::size_t>(s.gdim);
  if (ob.d.size() != n or ob.gradient.size() != n * g or
      ob.hessian.size() != n * g * g)
    throw std::invalid_argument(
      "the obstacle's d, gradient and hessian must have shapes "
      "(cells, points), (cells, points, gdim) and (cells, points, "
      "gdim, gdim)");
}

/// d at point q of cell c as a Jet: its second-order Taylor expansion about
/// the point, in the displacement δ = x_q − value(x_q) of the point (which
/// is 0 at the point: the value is d and the derivatives are exact there).
template<typename J>
J
obstacle_gap(const ObstacleAtPoints& ob,
             const Vec3<J>& xq,
             int gdim,
             std::size_t cq)
{
  std::array<J, 3> delta{};
  for (int i = 0; i < gdim; ++i)
    delta[i] = xq[i] - value(xq[i]);
  J d(ob.d[cq]);
  const double* grad = ob.gradient.data() + cq * gdim;
  const double* hess = ob.hessian.data() + cq * gdim * gdim;
  for (int i = 0; i < gdim; ++i)
  {
    add_scaled(d, grad[i], delta[i]);
    J row(0.0);
    for (int j = 0; j < gdim; ++j)
      add_scaled(row, 0.5 * hess[i * gdim + j], delta[j]);
    d += delta[i] * row;
  }
  return d;
}

/// The quantities of cell c on Jets over its NV node coordinates. Order 1:
/// W, ĝ, ĝ⁺ with gradients into @p out; Order 2: the Hessian of the
/// weighted sum into @p hessian (NV × NV).
template<int NV, int Order>
void
cell_quantities(const SurfaceCells& s,
                const ObstacleAtPoints* ob,
                std::size_t c,
                SurfaceCellDerivatives* out,
                std::span<const double> W_weights,
                std::span<const double> gap_weights,
                double* hessian)
{
  using J = Jet<NV, Order>;
  const int nd = s.nodes, gdim = s.gdim, tdim = s.tdim;
  std::array<J, NV> x;
  for (int k = 0; k < NV; ++k)
    x[k] = J::variable(s.x[c * NV + k], k);
  // nodal values with gradients (Order 1), or one weighted sum (Order 2)
  constexpr std::size_t nodal = Order == 1 ? 9 : 1;
  std::array<J, nodal> W, g, gp;
  J sum(0.0);
  for (std::size_t q = 0; q < s.num_points(); ++q)
  {
    std::span<const double> N = s.N.subspan(q * nd, nd);
    std::span<const double> phi = s.phi.subspan(q * nd, nd);
    const J wJ =
      s.weights[q] * area_element<J>(std::span<const J>(x.data(), NV),
                                     N,
                                     s.dN.subspan(q * tdim * nd, tdim * nd),
                                     gdim,
                                     tdim,
                                     s.axisymmetric);
    J wJd(0.0);
    bool penetrating = false;
    if (ob)
    {
      Vec3<J> xq{};
      for (int b = 0; b < nd; ++b)
        for (int i = 0; i < gdim; ++i)
          add_scaled(xq[i], N[b], x[b * gdim + i]);
      const std::size_t cq = c * s.num_points() + q;
      wJd = wJ * obstacle_gap(*ob, xq, gdim, cq);
      penetrating = ob->d[cq] > 0;
    }
    if constexpr (Order == 1)
    {
      for (int a = 0; a < nd; ++a)
      {
        W[a].add_scaled(N[a], wJ);
        if (ob)
        {
          g[a].add_scaled(phi[a], wJd);
          if (penetrating)
            gp[a].add_scaled(phi[a], wJd);
        }
      }
    }
    else
    {
      double wW = 0, wg = 0;
      for (int a = 0; a < nd; ++a)
      {
        wW += W_weights[c * nd + a] * N[a];
        if (ob)
          wg += gap_weights[c * nd + a] * phi[a];
      }
      sum.add_scaled(wW, wJ);
      if (ob)
        sum.add_scaled(wg, wJd);
    }
  }
  if constexpr (Order == 1)
  {
    auto put = [&](const std::array<J, nodal>& f,
                   std::vector<double>& value,
                   std::vector<double>& gradient)
    {
      for (int a = 0; a < nd; ++a)
      {
        value[c * nd + a] = f[a].v;
        std::copy(
          f[a].g.begin(), f[a].g.end(), gradient.begin() + (c * nd + a) * NV);
      }
    };
    put(W, out->W, out->W_gradient);
    if (ob)
      put(g, out->gap, out->gap_gradient);
    if (ob and ob->positive_part)
      put(gp, out->gap_plus, out->gap_plus_gradient);
  }
  else
  {
    for (int i = 0; i < NV; ++i)
      for (int j = 0; j < NV; ++j)
        hessian[i * NV + j] = sum.hessian(i, j);
  }
}

using CellFunction = void (*)(const SurfaceCells&,
                              const ObstacleAtPoints*,
                              std::size_t,
                              SurfaceCellDerivatives*,
                              std::span<const double>,
                              std::span<const double>,
                              double*);

/// The instantiation for NV variables per cell: every Lagrange facet type
/// (P1/P2 lines in 2D; P1/P2 triangles, Q1/Q8/Q2 quadrilaterals in 3D).
template<int Order>
CellFunction
cell_function(int NV)
{
  switch (NV)
  {
    case 4:
      return &cell_quantities<4, Order>;
    case 6:
      return &cell_quantities<6, Order>;
    case 9:
      return &cell_quantities<9, Order>;
    case 12:
      return &cell_quantities<12, Order>;
    case 18:
      return &cell_quantities<18, Order>;
    case 24:
      return &cell_quantities<24, Order>;
    case 27:
      return &cell_quantities<27, Order>;
  }
  throw std::invalid_argument(
    "no instantiation of the current surface's cell quantities "
    "for " +
    std::to_string(NV) + " variables per cell");
}

} // namespace

SurfaceCellDerivatives
current_surface_cells(const SurfaceCells& s, const ObstacleAtPoints* obstacle)
{
  s.check();
  if (obstacle)
    check_obstacle(s, *obstacle);
  const CellFunction f = cell_function<1>(s.num_variables());
  SurfaceCellDerivatives out;
  out.num_cells = s.num_cells();
  out.nodes = s.nodes;
  out.num_variables = s.num_variables();
  const std::size_t values = out.num_cells * s.nodes;
  const std::size_t gradients = values * out.num_variables;
  out.W.resize(values);
  out.W_gradient.resize(gradients);
  if (obstacle)
  {
    out.gap.resize(values);
    out.gap_gradient.resize(gradients);
    if (obstacle->positive_part)
    {
      out.gap_plus.resize(values);
      out.gap_plus_gradient.resize(gradients);
    }
  }
  for (std::size_t c = 0; c < out.num_cells; ++c)
    f(s, obstacle, c, &out, {}, {}, nullptr);
  return out;
}

std::vector<double>
current_surface_hessians(const SurfaceCells& s,
                         const ObstacleAtPoints* obstacle,
                         std::span<const double> W_weights,
                         std::span<const double> gap_weights)
{
  s.check();
  if (obstacle)
    check_obstacle(s, *obstacle);
  const std::size_t values = s.num_cells() * s.nodes;
  if (W_weights.size() != values or (obstacle and gap_weights.size() != values))
    throw std::invalid_argument("the weights must have shape (cells, nodes)");
  const CellFunction f = cell_function<2>(s.num_variables());
  const std::size_t nv = s.num_variables();
  std::vector<double> hessians(s.num_cells() * nv * nv);
  for (std::size_t c = 0; c < s.num_cells(); ++c)
    f(s,
      obstacle,
      c,
      nullptr,
      W_weights,
      gap_weights,
      hessians.data() + c * nv * nv);
  return hessians;
}

} // namespace dolfinx_mortar
