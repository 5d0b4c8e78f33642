// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#include <dolfinx_mortar/basis_coefficients.h>
#include <dolfinx_mortar/element_integrals.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <stdexcept>
#include <vector>

using namespace dolfinx_mortar;

namespace
{
// Two-point Gauss rule on [0, h] for P1 line elements: exact for L^e.
struct LineTabulation
{
  std::vector<double> phi;
  std::vector<double> weights;
  TabulationShape shape;
};

LineTabulation
p1_lines(const std::vector<double>& lengths)
{
  const double g = 0.5 / std::sqrt(3.0);
  const std::array<double, 2> xi = { 0.5 - g, 0.5 + g };
  LineTabulation t{ {}, {}, { lengths.size(), 2, 2 } };
  for (double h : lengths)
    for (double x : xi)
    {
      t.phi.push_back(1.0 - x);
      t.phi.push_back(x);
      t.weights.push_back(0.5 * h);
    }
  return t;
}
} // namespace

TEST(ElementIntegrals, P1LineMassMatrixIsExact)
{
  auto t = p1_lines({ 2.0 });
  auto L = element_mass_matrices(t.phi, t.weights, t.shape);
  EXPECT_NEAR(L[0], 2.0 / 3.0, 1e-15);
  EXPECT_NEAR(L[1], 1.0 / 3.0, 1e-15);
  EXPECT_NEAR(L[3], 2.0 / 3.0, 1e-15);
  auto W = element_integrals(t.phi, t.weights, t.shape);
  EXPECT_NEAR(W[0], 1.0, 1e-15);
  EXPECT_NEAR(W[1], 1.0, 1e-15);
}

TEST(BasisCoefficients, DualP1LineIsBiorthogonalAndPU)
{
  auto t = p1_lines({ 0.7 });
  auto L = element_mass_matrices(t.phi, t.weights, t.shape);
  auto W = element_integrals(t.phi, t.weights, t.shape);
  auto C = basis_coefficients(BasisKind::LcLS_star, L, W, W, 2);
  // Classical P1 dual functions: M_0 = 2 N_0 - N_1, M_1 = 2 N_1 - N_0.
  EXPECT_NEAR(C[0], 2.0, 1e-14);
  EXPECT_NEAR(C[1], -1.0, 1e-14);
  EXPECT_NEAR(C[2], -1.0, 1e-14);
  EXPECT_NEAR(C[3], 2.0, 1e-14);
  // ∫ M_A N_B = Σ_C C_CA L_CB = δ_AB W_A
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
    {
      double v = C[0 * 2 + a] * L[0 * 2 + b] + C[1 * 2 + a] * L[1 * 2 + b];
      EXPECT_NEAR(v, a == b ? W[a] : 0.0, 1e-15);
    }
}

TEST(BasisCoefficients, ZeroWeightIsRejectedByWeightedKinds)
{
  std::vector<double> L = { 1.0, 0.0, 0.0, 1.0 };
  std::vector<double> W = { 1.0, 0.0 };
  EXPECT_THROW(basis_coefficients(BasisKind::LcLS_star, L, W, W, 2),
               std::domain_error);
  EXPECT_THROW(basis_coefficients(BasisKind::LmLS, L, W, W, 2),
               std::domain_error);
  EXPECT_NO_THROW(basis_coefficients(BasisKind::LmLS_star, L, W, W, 2));
}

TEST(BasisCoefficients, DegenerateElementIsRejected)
{
  auto t = p1_lines({ 0.0 });
  auto L = element_mass_matrices(t.phi, t.weights, t.shape);
  auto W = element_integrals(t.phi, t.weights, t.shape);
  EXPECT_THROW(basis_coefficients(BasisKind::LcLS_star, L, W, W, 2),
               std::domain_error);
}

TEST(BasisCoefficients, GlobalKindsHaveNoElementCoefficients)
{
  std::vector<double> L = { 1.0 }, W = { 1.0 };
  EXPECT_THROW(basis_coefficients(BasisKind::GLS, L, W, W, 1),
               std::invalid_argument);
}
