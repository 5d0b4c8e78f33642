// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
//
// Thin bindings: numpy in, numpy out, no logic beyond shape handling.
#include <dolfinx_mortar/basis_coefficients.h>
#include <dolfinx_mortar/basis_kind.h>
#include <dolfinx_mortar/bounding_box_tree.h>
#include <dolfinx_mortar/element_integrals.h>
#include <dolfinx_mortar/facet_element.h>
#include <dolfinx_mortar/geometric_tolerance.h>
#include <dolfinx_mortar/sparse_pattern.h>
#include <dolfinx_mortar/surface_geometry.h>

#include "bindings.h"

#include <optional>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <span>
#include <stdexcept>
#include <vector>

namespace py = pybind11;
using namespace dolfinx_mortar;
using namespace dolfinx_mortar::bindings;

namespace
{
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

template<typename I>
using exact_int_t = py::array_t<I, py::array::c_style>;

/// positions_in_pattern for one index type of the outer pattern (PETSc's
/// PetscInt: 32 bits in Debian's build, 64 in others); no copy of it.
template<typename I>
void
bind_positions_in_pattern(py::module_& m)
{
  m.def(
    "positions_in_pattern",
    [](const exact_int_t<I>& outer_rows,
       const exact_int_t<I>& outer_columns,
       const int64_array_t& inner_rows,
       const int64_array_t& inner_columns)
      -> std::optional<py::array_t<std::int64_t>>
    {
      auto found = positions_in_pattern(
        std::span<const I>(outer_rows.data(), outer_rows.size()),
        std::span<const I>(outer_columns.data(), outer_columns.size()),
        std::span<const std::int64_t>(inner_rows.data(), inner_rows.size()),
        std::span<const std::int64_t>(inner_columns.data(),
                                      inner_columns.size()));
      if (!found)
        return std::nullopt;
      return to_numpy_as<std::int64_t>(
        *found, { static_cast<py::ssize_t>(found->size()) });
    },
    py::arg("outer_rows"),
    py::arg("outer_columns"),
    py::arg("inner_rows"),
    py::arg("inner_columns"),
    "Index in outer_columns of each entry of the pattern inner (both CSR, "
    "columns ascending in each row, the same rows), or None where one is "
    "not in outer");
}

} // namespace

PYBIND11_MODULE(_kernels, m)
{
  m.doc() = "dolfinx_mortar C++ kernels";
  bind_positions_in_pattern<std::int32_t>(m);
  bind_positions_in_pattern<std::int64_t>(m);
  bind_current_surface(m);

  m.attr("geometric_tolerance") = geometric_tolerance;
  m.attr("negligible_facet_ratio") = negligible_facet_ratio;
  m.def(
    "length_scale",
    [](const array_t& x)
    {
      if (x.ndim() != 2)
        throw std::invalid_argument("x must have shape (points, gdim)");
      return length_scale(as_span(x), static_cast<int>(x.shape(1)));
    },
    py::arg("x"),
    "Largest coordinate magnitude or bounding-box diagonal of x (points, "
    "gdim)");

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
    "check_element_measures",
    [](const array_t& element_weights,
       const array_t& points,
       int tdim,
       double length_scale)
    {
      if (element_weights.ndim() != 2 or points.ndim() != 3 or
          points.shape(0) != element_weights.shape(0))
        throw std::invalid_argument("element weights must be (cells, "
                                    "functions), points (cells, points, "
                                    "gdim)");
      check_element_measures(as_span(element_weights),
                             element_weights.shape(1),
                             as_span(points),
                             static_cast<int>(points.shape(2)),
                             tdim,
                             length_scale);
    },
    py::arg("element_weights"),
    py::arg("points"),
    py::arg("tdim"),
    py::arg("length_scale"),
    "Raise naming the first element whose measure is at most the zero "
    "measure of the geometry");
  m.def(
    "check_lumped_weights",
    [](BasisKind kind,
       const array_t& element_weights,
       const array_t& nodal_weights)
    {
      if (element_weights.ndim() != 2)
        throw std::invalid_argument("element weights must be 2D");
      check_lumped_weights(kind,
                           as_span(element_weights),
                           as_span(nodal_weights),
                           element_weights.shape(1));
    },
    py::arg("kind"),
    py::arg("element_weights"),
    py::arg("nodal_weights"));
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

  py::enum_<FacetType>(m, "FacetType")
    .value("P1_line", FacetType::P1_line)
    .value("P2_line", FacetType::P2_line)
    .value("P1_triangle", FacetType::P1_triangle)
    .value("P2_triangle", FacetType::P2_triangle)
    .value("Q1_quadrilateral", FacetType::Q1_quadrilateral)
    .value("Q2_quadrilateral", FacetType::Q2_quadrilateral)
    .value("Q8_quadrilateral", FacetType::Q8_quadrilateral);

  m.def(
    "facet_shape_functions",
    [](FacetType type, const array_t& X)
    {
      const int tdim = facet_tdim(type), nn = facet_num_nodes(type);
      if (X.ndim() != 2 or X.shape(1) != tdim)
        throw std::invalid_argument("X must have shape (points, tdim)");
      std::vector<double> N(X.shape(0) * nn), dN(X.shape(0) * tdim * nn);
      for (py::ssize_t i = 0; i < X.shape(0); ++i)
        facet_shape_functions(type,
                              std::span(X.data() + i * tdim, tdim),
                              std::span(N.data() + i * nn, nn),
                              std::span(dN.data() + i * tdim * nn, tdim * nn));
      return py::make_tuple(to_numpy(N, { X.shape(0), nn }),
                            to_numpy(dN, { X.shape(0), tdim, nn }));
    },
    py::arg("type"),
    py::arg("X"),
    "Shape functions (points, nodes) and reference gradients (points, "
    "tdim, nodes)");

  m.def(
    "element_node_normals",
    [](FacetType type,
       const array_t& x,
       const int_array_t& cells,
       bool size_weighted)
    {
      auto s = surface_view(type, x, cells);
      return to_numpy(element_node_normals(s, size_weighted),
                      { cells.shape(0), cells.shape(1), x.shape(1) });
    },
    py::arg("type"),
    py::arg("x"),
    py::arg("cells"),
    py::arg("size_weighted") = false,
    "Normal of every cell at its nodes (cells, nodes, gdim): unit, or of "
    "length |J| with size_weighted");

  m.def(
    "facet_bounding_boxes",
    [](
      FacetType type, const array_t& x, const int_array_t& cells, double margin)
    {
      auto s = surface_view(type, x, cells);
      return to_numpy(facet_bounding_boxes(s, margin), { cells.shape(0), 6 });
    },
    py::arg("type"),
    py::arg("x"),
    py::arg("cells"),
    py::arg("margin"));

  m.def(
    "overlapping_box_pairs",
    [](const array_t& a, const array_t& b)
    {
      auto pairs = overlapping_box_pairs(as_span(a), as_span(b));
      return to_numpy_as<std::int32_t>(
        pairs, { static_cast<py::ssize_t>(pairs.size() / 2), 2 });
    },
    py::arg("a"),
    py::arg("b"),
    "Pairs (i, j) of overlapping boxes, i in a, j in b; boxes (n, 6)");
  bind_segmentation(m);
}
