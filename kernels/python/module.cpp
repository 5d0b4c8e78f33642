// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
//
// Thin bindings: numpy in, numpy out, no logic beyond shape handling.
#include <dolfinx_mortar/basis_coefficients.h>
#include <dolfinx_mortar/basis_kind.h>
#include <dolfinx_mortar/element_integrals.h>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <span>
#include <stdexcept>
#include <vector>

namespace py = pybind11;
using namespace dolfinx_mortar;

namespace
{
using array_t = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::span<const double>
as_span(const array_t& a)
{
  return std::span<const double>(a.data(), static_cast<std::size_t>(a.size()));
}

TabulationShape
tabulation_shape(const array_t& phi, const array_t& weights)
{
  if (phi.ndim() != 3)
    throw std::invalid_argument(
      "phi must have shape (cells, points, functions)");
  if (weights.ndim() != 2 or weights.shape(0) != phi.shape(0) or
      weights.shape(1) != phi.shape(1))
    throw std::invalid_argument("weights must have shape (cells, points) "
                                "matching phi");
  return { static_cast<std::size_t>(phi.shape(0)),
           static_cast<std::size_t>(phi.shape(1)),
           static_cast<std::size_t>(phi.shape(2)) };
}

// One copy into numpy-owned memory: cheap next to the kernel work, and it
// keeps ownership simple.
array_t
to_numpy(const std::vector<double>& v, std::vector<py::ssize_t> shape)
{
  return array_t(shape, v.data());
}
} // namespace

PYBIND11_MODULE(_kernels, m)
{
  m.doc() = "dolfinx_mortar C++ kernels";

  py::enum_<BasisKind>(m, "BasisKind")
    .value("GLS", BasisKind::GLS)
    .value("GLS_star", BasisKind::GLS_star)
    .value("LmLS", BasisKind::LmLS)
    .value("LmLS_star", BasisKind::LmLS_star)
    .value("LcLS_star", BasisKind::LcLS_star)
    .value("LcLS", BasisKind::LcLS);

  m.def(
    "to_string",
    [](BasisKind k) { return to_string(k); },
    py::arg("kind"),
    "Canonical name of a kind (\"GLS*\", ...)");

  m.def("basis_kind_from_string", &basis_kind_from_string, py::arg("name"));
  m.def("all_basis_kinds",
        []
        {
          return std::vector<BasisKind>(all_basis_kinds.begin(),
                                        all_basis_kinds.end());
        });
  m.def("is_partition_of_unity", &is_partition_of_unity);
  m.def("unstarred_partner", &unstarred_partner);
  m.def("is_global", &is_global);
  m.def("needs_positive_weights", &needs_positive_weights);

  m.def(
    "element_integrals",
    [](const array_t& phi, const array_t& weights)
    {
      auto shape = tabulation_shape(phi, weights);
      return to_numpy(element_integrals(as_span(phi), as_span(weights), shape),
                      { phi.shape(0), phi.shape(2) });
    },
    py::arg("phi"),
    py::arg("weights"),
    "∫_e N_i f dA for weights = quadrature weight·|J|·f, shape (cells, "
    "functions)");
  m.def(
    "element_mass_matrices",
    [](const array_t& phi, const array_t& weights)
    {
      auto shape = tabulation_shape(phi, weights);
      return to_numpy(
        element_mass_matrices(as_span(phi), as_span(weights), shape),
        { phi.shape(0), phi.shape(2), phi.shape(2) });
    },
    py::arg("phi"),
    py::arg("weights"));
  m.def(
    "check_lumped_weights",
    [](BasisKind kind,
       const array_t& element_weights,
       const array_t& nodal_weights,
       double tol)
    {
      if (element_weights.ndim() != 2)
        throw std::invalid_argument("element weights must be 2D");
      check_lumped_weights(kind,
                           as_span(element_weights),
                           as_span(nodal_weights),
                           element_weights.shape(1),
                           tol);
    },
    py::arg("kind"),
    py::arg("element_weights"),
    py::arg("nodal_weights"),
    py::arg("relative_tolerance") = 1e-12);
  m.def(
    "basis_coefficients",
    [](BasisKind kind,
       const array_t& element_mass,
       const array_t& element_weights,
       const array_t& nodal_weights)
    {
      if (element_weights.ndim() != 2)
        throw std::invalid_argument("element weights must be 2D");
      const py::ssize_t nd = element_weights.shape(1);
      return to_numpy(basis_coefficients(kind,
                                         as_span(element_mass),
                                         as_span(element_weights),
                                         as_span(nodal_weights),
                                         nd),
                      { element_weights.shape(0), nd, nd });
    },
    py::arg("kind"),
    py::arg("element_mass"),
    py::arg("element_weights"),
    py::arg("nodal_weights"));
}
