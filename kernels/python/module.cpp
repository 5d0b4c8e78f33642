// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
//
// Thin bindings: numpy in, numpy out, no logic beyond shape handling.
#include <dolfinx_mortar/basis_coefficients.h>
#include <dolfinx_mortar/basis_kind.h>
#include <dolfinx_mortar/bounding_box_tree.h>
#include <dolfinx_mortar/current_pair_gaps.h>
#include <dolfinx_mortar/element_integrals.h>
#include <dolfinx_mortar/facet_element.h>
#include <dolfinx_mortar/geometric_tolerance.h>
#include <dolfinx_mortar/mortar_integrals.h>
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

} // namespace

PYBIND11_MODULE(_kernels, m)
{
  m.doc() = "dolfinx_mortar C++ kernels";
  bind_current_surface(m);

  m.attr("geometric_tolerance") = geometric_tolerance;
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

  m.def(
    "mortar_integrals",
    [](FacetType slave_type,
       const array_t& xs,
       const int_array_t& cs,
       const array_t& slave_normals,
       FacetType master_type,
       const array_t& xm,
       const int_array_t& cm,
       const int_array_t& candidates,
       const array_t& points,
       const array_t& weights,
       bool opposing_normals_only,
       double length_scale,
       bool keep_points,
       bool axisymmetric,
       bool project_along_normals)
    {
      auto slave = surface_view(slave_type, xs, cs);
      auto master = surface_view(master_type, xm, cm);
      SegmentationOptions options{ opposing_normals_only,
                                   length_scale,
                                   keep_points,
                                   axisymmetric,
                                   project_along_normals };
      MortarIntegrals r;
      {
        py::gil_scoped_release release;
        r = mortar_integrals(
          slave,
          as_span(slave_normals),
          master,
          std::span<const std::int32_t>(candidates.data(), candidates.size()),
          as_span(points),
          as_span(weights),
          options);
      }
      const auto np = static_cast<py::ssize_t>(r.area.size());
      const py::ssize_t ns = cs.shape(1), nm = cm.shape(1);
      py::dict out;
      out["pairs"] = to_numpy_as<std::int32_t>(r.pairs, { np, 2 });
      out["D"] = to_numpy(r.D, { np, ns, ns });
      out["M"] = to_numpy(r.M, { np, ns, nm });
      out["gap"] = to_numpy(r.gap, { np, ns });
      out["area"] = to_numpy(r.area, { np });
      out["failed_projections"] = r.failed_projections;
      out["degenerate_slave_facets"] = to_numpy_as<std::int32_t>(
        r.degenerate_slave_facets,
        { static_cast<py::ssize_t>(r.degenerate_slave_facets.size()) });
      out["degenerate_master_facets"] = to_numpy_as<std::int32_t>(
        r.degenerate_master_facets,
        { static_cast<py::ssize_t>(r.degenerate_master_facets.size()) });
      if (keep_points)
      {
        const auto nq = static_cast<py::ssize_t>(r.point_pairs.size());
        const py::ssize_t gdim = xs.shape(1);
        out["point_pairs"] = to_numpy_as<std::int32_t>(r.point_pairs, { nq });
        out["point_weights"] = to_numpy(r.point_weights, { nq });
        out["point_gap"] = to_numpy(r.point_gap, { nq });
        out["point_normals"] = to_numpy(r.point_normals, { nq, gdim });
        out["point_slave_N"] = to_numpy(r.point_slave_N, { nq, ns });
        out["point_master_N"] = to_numpy(r.point_master_N, { nq, nm });
      }
      return out;
    },
    py::arg("slave_type"),
    py::arg("slave_x"),
    py::arg("slave_cells"),
    py::arg("slave_normals"),
    py::arg("master_type"),
    py::arg("master_x"),
    py::arg("master_cells"),
    py::arg("candidates"),
    py::arg("points"),
    py::arg("weights"),
    py::arg("opposing_normals_only") = true,
    py::arg("length_scale") = 0.0,
    py::arg("keep_points") = false,
    py::arg("axisymmetric") = false,
    py::arg("project_along_normals") = false,
    "Segmentation and slave-basis mortar integrals per cell pair");
  m.def(
    "current_pair_gaps",
    [](FacetType slave_type,
       const array_t& xs,
       const int_array_t& cs,
       const int64_array_t& slave_ids,
       FacetType master_type,
       const array_t& xm,
       const int_array_t& cm,
       const int64_array_t& master_ids,
       const int_array_t& pairs,
       const array_t& points,
       const array_t& weights,
       double zero,
       bool opposing_normals_only,
       bool with_hessian,
       bool with_positive_part,
       bool axisymmetric,
       std::optional<array_t> node_weights)
    {
      auto slave = surface_view(slave_type, xs, cs);
      auto master = surface_view(master_type, xm, cm);
      PairGapDerivatives r;
      {
        py::gil_scoped_release release;
        r = current_pair_gaps(
          slave,
          std::span<const std::int64_t>(slave_ids.data(), slave_ids.size()),
          master,
          std::span<const std::int64_t>(master_ids.data(), master_ids.size()),
          std::span<const std::int32_t>(pairs.data(), pairs.size()),
          as_span(points),
          as_span(weights),
          zero,
          opposing_normals_only,
          with_hessian,
          with_positive_part,
          axisymmetric,
          node_weights ? as_span(*node_weights) : std::span<const double>());
      }
      const auto np = static_cast<py::ssize_t>(pairs.size() / 2);
      const py::ssize_t ns = cs.shape(1);
      // functions per pair: the ns c_A, or their weighted sum
      const py::ssize_t nf = node_weights ? 1 : ns;
      const py::ssize_t nv =
        static_cast<py::ssize_t>(r.num_nodes) * xs.shape(1);
      py::dict out;
      out["nodes"] = to_numpy_as<std::int64_t>(r.nodes, { np, r.num_nodes });
      out["value"] = to_numpy(r.value, { np, nf });
      out["gradient"] = to_numpy(r.gradient, { np, nf, nv });
      const py::ssize_t nh = with_hessian ? nv : 0;
      out["hessian"] = to_numpy(r.hessian, { np, nf, nh, nh });
      const py::ssize_t npp = with_positive_part ? np : 0;
      out["value_plus"] = to_numpy(r.value_plus, { npp, ns });
      out["gradient_plus"] = to_numpy(r.gradient_plus, { npp, ns, nv });
      out["failed_projections"] = r.failed_projections;
      return out;
    },
    py::arg("slave_type"),
    py::arg("slave_x"),
    py::arg("slave_cells"),
    py::arg("slave_ids"),
    py::arg("master_type"),
    py::arg("master_x"),
    py::arg("master_cells"),
    py::arg("master_ids"),
    py::arg("pairs"),
    py::arg("points"),
    py::arg("weights"),
    py::arg("zero"),
    py::arg("opposing_normals_only") = true,
    py::arg("with_hessian") = true,
    py::arg("with_positive_part") = false,
    py::arg("axisymmetric") = false,
    py::arg("node_weights") = py::none(),
    "Current-configuration mortar gaps of cell pairs with exact gradients "
    "and Hessians (and, with_positive_part, the pointwise active set's "
    "integrals of <d> with their gradients); with node_weights (pairs, ns), "
    "those of the one function sum_A w_A c_A per pair instead");

  m.def(
    "averaged_normal_derivatives",
    [](FacetType type,
       const array_t& x,
       const int_array_t& cells,
       const int64_array_t& ids,
       std::int64_t node)
    {
      auto s = surface_view(type, x, cells);
      NormalDerivatives r = averaged_normal_derivatives(
        s, std::span<const std::int64_t>(ids.data(), ids.size()), node);
      const py::ssize_t gdim = x.shape(1);
      const auto K = static_cast<py::ssize_t>(r.star.size()) * gdim;
      py::dict out;
      out["star"] = to_numpy_as<std::int64_t>(
        r.star, { static_cast<py::ssize_t>(r.star.size()) });
      out["value"] = py::array_t<double>({ gdim }, r.value.data());
      out["gradient"] = to_numpy(r.gradient, { gdim, K });
      out["hessian"] = to_numpy(r.hessian, { gdim, K, K });
      return out;
    },
    py::arg("facet_type"),
    py::arg("x"),
    py::arg("cells"),
    py::arg("ids"),
    py::arg("node"),
    "The averaged unit normal at a node with its exact derivatives");
}
