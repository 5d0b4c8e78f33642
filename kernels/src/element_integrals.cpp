// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#include <dolfinx_mortar/element_integrals.h>

#include <Eigen/Core>
#include <stdexcept>
#include <string>

namespace dolfinx_mortar
{
namespace
{
using RowMatrix =
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

void
check_sizes(std::span<const double> phi,
            std::span<const double> weights,
            TabulationShape shape)
{
  const auto [nc, nq, nd] = shape;
  if (phi.size() != nc * nq * nd)
    throw std::invalid_argument("phi has " + std::to_string(phi.size()) +
                                " values, expected cells*points*functions = " +
                                std::to_string(nc * nq * nd));
  if (weights.size() != nc * nq)
    throw std::invalid_argument(
      "weights have " + std::to_string(weights.size()) +
      " values, expected cells*points = " + std::to_string(nc * nq));
}
} // namespace

std::vector<double>
element_integrals(std::span<const double> phi,
                  std::span<const double> weights,
                  TabulationShape shape)
{
  check_sizes(phi, weights, shape);
  const auto [nc, nq, nd] = shape;
  std::vector<double> out(nc * nd);
  for (std::size_t c = 0; c < nc; ++c)
  {
    Eigen::Map<const RowMatrix> N(phi.data() + c * nq * nd, nq, nd);
    Eigen::Map<const Eigen::VectorXd> w(weights.data() + c * nq, nq);
    Eigen::Map<Eigen::VectorXd>(out.data() + c * nd, nd) = N.transpose() * w;
  }
  return out;
}

std::vector<double>
element_mass_matrices(std::span<const double> phi,
                      std::span<const double> weights,
                      TabulationShape shape)
{
  check_sizes(phi, weights, shape);
  const auto [nc, nq, nd] = shape;
  std::vector<double> out(nc * nd * nd);
  for (std::size_t c = 0; c < nc; ++c)
  {
    Eigen::Map<const RowMatrix> N(phi.data() + c * nq * nd, nq, nd);
    Eigen::Map<const Eigen::VectorXd> w(weights.data() + c * nq, nq);
    Eigen::Map<RowMatrix>(out.data() + c * nd * nd, nd, nd) =
      N.transpose() * w.asDiagonal() * N;
  }
  return out;
}

} // namespace dolfinx_mortar
