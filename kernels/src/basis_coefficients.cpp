// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#include <dolfinx_mortar/basis_coefficients.h>
#include <dolfinx_mortar/geometric_tolerance.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <stdexcept>

namespace dolfinx_mortar
{
namespace
{
using RowMatrix =
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

double
element_measure(std::span<const double> w)
{
  return std::accumulate(w.begin(), w.end(), 0.0);
}

[[noreturn]] void
throw_weight_error(BasisKind kind,
                   std::size_t cell,
                   std::size_t function,
                   double value,
                   double measure,
                   bool nodal)
{
  std::ostringstream msg;
  msg << "basis kind '" << to_string(kind) << "' needs "
      << (nodal ? "W_A = ∫N_A dA > 0 at every slave function"
                : "∫_e N_A dA > 0 on every element")
      << ", but cell " << cell << " (local function " << function << ") has "
      << (nodal ? "W_A = " : "∫_e N_A dA = ") << value << " (element measure "
      << measure << ")";
  throw std::domain_error(msg.str());
}
} // namespace

void
check_element_measures(std::span<const double> element_weights,
                       std::size_t num_functions,
                       std::span<const double> points,
                       int gdim,
                       int tdim,
                       double length_scale)
{
  if (num_functions == 0 or element_weights.size() % num_functions != 0)
    throw std::invalid_argument(
      "element weights must have shape (cells, functions)");
  const std::size_t nc = element_weights.size() / num_functions;
  if (nc == 0)
    return; // a rank may hold no element
  if (gdim < 1 or gdim > 3 or tdim < 1 or tdim > 2 or
      points.size() % (nc * gdim) != 0)
    throw std::invalid_argument(
      "quadrature points must have shape (cells, points, gdim)");
  const std::size_t per_cell = points.size() / nc;
  const double zero = std::max(geometric_tolerance * length_scale,
                               std::numeric_limits<double>::min());
  for (std::size_t c = 0; c < nc; ++c)
  {
    const double measure = element_measure(
      element_weights.subspan(c * num_functions, num_functions));
    // the extent of the element's points: its size, whatever its position
    const auto x = points.subspan(c * per_cell, per_cell);
    double extent = 0;
    for (int k = 0; k < gdim; ++k)
    {
      double lo = x[k], hi = x[k];
      for (std::size_t i = k; i < x.size(); i += gdim)
      {
        lo = std::min(lo, x[i]);
        hi = std::max(hi, x[i]);
      }
      extent += (hi - lo) * (hi - lo);
    }
    const double zero_measure = tdim == 1 ? zero : zero * std::sqrt(extent);
    if (!(measure > zero_measure) or !std::isfinite(measure))
    {
      std::ostringstream msg;
      msg << "degenerate slave element: cell " << c << " has measure "
          << measure << ", at most the zero "
          << (tdim == 1 ? "length " : "measure ") << zero_measure
          << " (tolerance " << geometric_tolerance << " × length scale "
          << length_scale << ")";
      throw std::domain_error(msg.str());
    }
  }
}

void
check_lumped_weights(BasisKind kind,
                     std::span<const double> element_weights,
                     std::span<const double> nodal_weights,
                     std::size_t num_functions)
{
  if (num_functions == 0 or element_weights.size() % num_functions != 0 or
      nodal_weights.size() != element_weights.size())
    throw std::invalid_argument(
      "element and nodal weights must both have shape (cells, functions)");
  const bool element_check =
    kind == BasisKind::LcLS_star or kind == BasisKind::LcLS;
  const bool nodal_check = kind == BasisKind::LmLS or kind == BasisKind::LcLS or
                           kind == BasisKind::GLS_star;
  const std::size_t nc = element_weights.size() / num_functions;
  for (std::size_t c = 0; c < nc; ++c)
  {
    auto we = element_weights.subspan(c * num_functions, num_functions);
    auto wn = nodal_weights.subspan(c * num_functions, num_functions);
    const double measure = element_measure(we);
    // Degeneracy against the geometry is check_element_measures' decision;
    // this only keeps a non-positive or NaN measure (a covered part of
    // nothing) out of the ratios below.
    if (!(measure > 0.0) or !std::isfinite(measure))
    {
      std::ostringstream msg;
      msg << "degenerate slave element: cell " << c << " has measure "
          << measure;
      throw std::domain_error(msg.str());
    }
    for (std::size_t i = 0; i < num_functions; ++i)
    {
      if (element_check and !(we[i] > geometric_tolerance * measure))
        throw_weight_error(kind, c, i, we[i], measure, false);
      if (nodal_check and !(wn[i] > geometric_tolerance * measure))
        throw_weight_error(kind, c, i, wn[i], measure, true);
    }
  }
}

std::vector<double>
basis_coefficients(BasisKind kind,
                   std::span<const double> element_mass,
                   std::span<const double> element_weights,
                   std::span<const double> nodal_weights,
                   std::size_t num_functions)
{
  if (is_global(kind))
    throw std::invalid_argument("basis kind '" + to_string(kind) +
                                "' has global support: it has no "
                                "element-wise coefficients");
  const std::size_t nd = num_functions;
  if (nd == 0 or element_weights.size() % nd != 0)
    throw std::invalid_argument("element weights must have shape (cells, "
                                "functions)");
  const std::size_t nc = element_weights.size() / nd;
  // Only the dual kinds use L^e: the others may pass an empty array.
  const bool dual = kind == BasisKind::LcLS_star or kind == BasisKind::LcLS;
  if (dual and element_mass.size() != nc * nd * nd)
    throw std::invalid_argument("element mass matrices must have shape "
                                "(cells, functions, functions)");
  check_lumped_weights(kind, element_weights, nodal_weights, nd);

  std::vector<double> out(nc * nd * nd, 0.0);
  for (std::size_t c = 0; c < nc; ++c)
  {
    Eigen::Map<RowMatrix> C(out.data() + c * nd * nd, nd, nd);
    Eigen::Map<const Eigen::VectorXd> We(element_weights.data() + c * nd, nd);
    Eigen::Map<const Eigen::VectorXd> Wn(nodal_weights.data() + c * nd, nd);
    switch (kind)
    {
      case BasisKind::LmLS_star:
        C.setIdentity();
        break;
      case BasisKind::LmLS:
        C = Wn.cwiseInverse().asDiagonal();
        break;
      case BasisKind::LcLS_star:
      case BasisKind::LcLS:
      {
        Eigen::Map<const RowMatrix> Le(
          element_mass.data() + c * nd * nd, nd, nd);
        // L^e is SPD for a non-degenerate element: Cholesky both solves and
        // detects degeneracy.
        Eigen::LLT<Eigen::MatrixXd> llt(Le);
        if (llt.info() != Eigen::Success)
        {
          std::ostringstream msg;
          msg << "element mass matrix of cell " << c
              << " is not positive definite: degenerate slave element";
          throw std::domain_error(msg.str());
        }
        Eigen::MatrixXd rhs = We.asDiagonal();
        if (kind == BasisKind::LcLS)
          rhs = rhs * Wn.cwiseInverse().asDiagonal();
        C = llt.solve(rhs);
        break;
      }
      default:
        throw std::logic_error("unreachable basis kind");
    }
  }
  return out;
}

} // namespace dolfinx_mortar
