// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
//
// Bindings of the segmentation (mortar integrals per pair and their points) and
// of the current pair gaps with derivatives: numpy views in, typed results out.
#include "bindings.h"

#include <dolfinx_mortar/current_pair_gaps.h>
#include <dolfinx_mortar/mortar_integrals.h>

#include <optional>
#include <pybind11/stl.h>

namespace dolfinx_mortar::bindings
{
namespace
{
py::ssize_t
size(std::size_t n)
{
  return static_cast<py::ssize_t>(n);
}

/// A read-only numpy property of a result: @p shape from the result.
template<typename Result, typename Field, typename Shape>
auto
array_property(Field field, Shape shape)
{
  return [field, shape](const Result& r)
  {
    const auto& v = r.*field;
    using T = typename std::decay_t<decltype(v)>::value_type;
    return py::array_t<T>(shape(r), v.data());
  };
}
} // namespace

void
bind_segmentation(py::module_& m)
{
  using MI = MortarIntegrals;
  auto pairs_of = [](const MI& r) { return size(r.area.size()); };
  auto points_of = [](const MI& r) { return size(r.point_pairs.size()); };
  py::class_<MI>(
    m,
    "MortarIntegrals",
    "The segmentation of slave–master cell pairs: per pair D = ∫ N_A N_B, "
    "M = ∫ N_A N^m_C, gap = ∫ N_A d and the covered area; per quadrature "
    "point (with keep_points) its pair, weight, gap, unit normal and shape "
    "functions")
    .def_property_readonly(
      "pairs",
      array_property<MI>(&MI::pairs,
                         [=](const MI& r) {
                           return std::vector<py::ssize_t>{ pairs_of(r), 2 };
                         }))
    .def_property_readonly(
      "D",
      array_property<MI>(&MI::D,
                         [=](const MI& r)
                         {
                           return std::vector<py::ssize_t>{ pairs_of(r),
                                                            r.slave_nodes,
                                                            r.slave_nodes };
                         }))
    .def_property_readonly(
      "M",
      array_property<MI>(&MI::M,
                         [=](const MI& r)
                         {
                           return std::vector<py::ssize_t>{ pairs_of(r),
                                                            r.slave_nodes,
                                                            r.master_nodes };
                         }))
    .def_property_readonly(
      "gap",
      array_property<MI>(
        &MI::gap,
        [=](const MI& r) {
          return std::vector<py::ssize_t>{ pairs_of(r), r.slave_nodes };
        }))
    .def_property_readonly(
      "area",
      array_property<MI>(&MI::area,
                         [=](const MI& r)
                         { return std::vector<py::ssize_t>{ pairs_of(r) }; }))
    .def_readonly("failed_projections", &MI::failed_projections)
    .def_property_readonly(
      "degenerate_slave_facets",
      array_property<MI>(&MI::degenerate_slave_facets,
                         [](const MI& r) {
                           return std::vector<py::ssize_t>{ size(
                             r.degenerate_slave_facets.size()) };
                         }))
    .def_property_readonly(
      "degenerate_master_facets",
      array_property<MI>(&MI::degenerate_master_facets,
                         [](const MI& r)
                         {
                           return std::vector<py::ssize_t>{ size(
                             r.degenerate_master_facets.size()) };
                         }))
    .def_property_readonly(
      "point_pairs",
      array_property<MI>(&MI::point_pairs,
                         [=](const MI& r)
                         { return std::vector<py::ssize_t>{ points_of(r) }; }))
    .def_property_readonly(
      "point_weights",
      array_property<MI>(&MI::point_weights,
                         [=](const MI& r)
                         { return std::vector<py::ssize_t>{ points_of(r) }; }))
    .def_property_readonly(
      "point_gap",
      array_property<MI>(&MI::point_gap,
                         [=](const MI& r)
                         { return std::vector<py::ssize_t>{ points_of(r) }; }))
    .def_property_readonly(
      "point_normals",
      array_property<MI>(
        &MI::point_normals,
        [=](const MI& r) {
          return std::vector<py::ssize_t>{ points_of(r), r.gdim };
        }))
    .def_property_readonly(
      "point_slave_N",
      array_property<MI>(
        &MI::point_slave_N,
        [=](const MI& r) {
          return std::vector<py::ssize_t>{ points_of(r), r.slave_nodes };
        }))
    .def_property_readonly(
      "point_master_N",
      array_property<MI>(
        &MI::point_master_N,
        [=](const MI& r) {
          return std::vector<py::ssize_t>{ points_of(r), r.master_nodes };
        }));

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
       bool project_along_normals,
       bool keep_slivers)
    {
      auto slave = surface_view(slave_type, xs, cs);
      auto master = surface_view(master_type, xm, cm);
      const SegmentationOptions options{ opposing_normals_only, length_scale,
                                         keep_points,           axisymmetric,
                                         project_along_normals, keep_slivers };
      py::gil_scoped_release release;
      return mortar_integrals(
        slave,
        as_span(slave_normals),
        master,
        std::span<const std::int32_t>(candidates.data(), candidates.size()),
        as_span(points),
        as_span(weights),
        options);
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
    py::arg("keep_slivers") = false,
    "Segmentation and slave-basis mortar integrals per cell pair");

  using PG = PairGapDerivatives;
  auto variables = [](const PG& r) { return size(r.num_nodes) * r.gdim; };
  py::class_<PG>(
    m,
    "PairGapDerivatives",
    "Current-configuration mortar gaps c_A = ∫ N_A d of cell pairs with their "
    "exact gradients and Hessians with respect to the pairs' variable nodes "
    "(nodes: their global ids, −1 pads)")
    .def_property_readonly(
      "nodes",
      array_property<PG>(
        &PG::nodes,
        [](const PG& r) {
          return std::vector<py::ssize_t>{ size(r.num_pairs), r.num_nodes };
        }))
    .def_property_readonly(
      "value",
      array_property<PG>(
        &PG::value,
        [](const PG& r) {
          return std::vector<py::ssize_t>{ size(r.num_pairs), r.functions };
        }))
    .def_property_readonly(
      "gradient",
      array_property<PG>(&PG::gradient,
                         [=](const PG& r)
                         {
                           return std::vector<py::ssize_t>{ size(r.num_pairs),
                                                            r.functions,
                                                            variables(r) };
                         }))
    .def_property_readonly(
      "hessian",
      array_property<PG>(&PG::hessian,
                         [=](const PG& r)
                         {
                           const py::ssize_t nh =
                             r.hessian.empty() ? 0 : variables(r);
                           return std::vector<py::ssize_t>{
                             size(r.num_pairs), r.functions, nh, nh
                           };
                         }))
    .def_property_readonly(
      "value_plus",
      array_property<PG>(&PG::value_plus,
                         [](const PG& r)
                         {
                           const py::ssize_t np =
                             r.value_plus.empty() ? 0 : size(r.num_pairs);
                           return std::vector<py::ssize_t>{ np, r.slave_nodes };
                         }))
    .def_property_readonly(
      "gradient_plus",
      array_property<PG>(
        &PG::gradient_plus,
        [=](const PG& r)
        {
          const py::ssize_t np = r.value_plus.empty() ? 0 : size(r.num_pairs);
          return std::vector<py::ssize_t>{ np, r.slave_nodes, variables(r) };
        }))
    .def_readonly("failed_projections", &PG::failed_projections);

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
       std::optional<array_t> node_weights,
       bool with_mass,
       bool keep_slivers)
    {
      auto slave = surface_view(slave_type, xs, cs);
      auto master = surface_view(master_type, xm, cm);
      const PairGapOptions options{ as_span(points),
                                    as_span(weights),
                                    zero,
                                    opposing_normals_only,
                                    with_hessian,
                                    with_positive_part,
                                    axisymmetric,
                                    node_weights ? as_span(*node_weights)
                                                 : std::span<const double>(),
                                    with_mass,
                                    keep_slivers };
      py::gil_scoped_release release;
      return current_pair_gaps(
        slave,
        std::span<const std::int64_t>(slave_ids.data(), slave_ids.size()),
        master,
        std::span<const std::int64_t>(master_ids.data(), master_ids.size()),
        std::span<const std::int32_t>(pairs.data(), pairs.size()),
        options);
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
    py::arg("with_mass") = false,
    py::arg("keep_slivers") = false,
    "Current-configuration mortar gaps of cell pairs with exact gradients and "
    "Hessians (and, with_positive_part, the pointwise active set's integrals "
    "of <d> with their gradients); with node_weights (pairs, ns), those of the "
    "one function sum_A w_A c_A per pair instead; with_mass, also the covered "
    "mass L_AB = int N_A N_B (ns^2 functions after the ns c_A; node_weights "
    "then (pairs, ns + ns^2)); keep_slivers: overlaps of any width count");

  using ND = NormalDerivatives;
  py::class_<ND>(
    m,
    "NormalDerivatives",
    "The averaged unit normal at a node with its exact derivatives with "
    "respect to the nodes of its star")
    .def_property_readonly("star",
                           array_property<ND>(&ND::star,
                                              [](const ND& r) {
                                                return std::vector<py::ssize_t>{
                                                  size(r.star.size())
                                                };
                                              }))
    .def_property_readonly(
      "value",
      [](const ND& r)
      { return py::array_t<double>({ size(r.gdim) }, r.value.data()); })
    .def_readonly("gdim", &ND::gdim)
    .def_property_readonly("gradient",
                           array_property<ND>(&ND::gradient,
                                              [](const ND& r) {
                                                return std::vector<py::ssize_t>{
                                                  r.gdim,
                                                  size(r.star.size()) * r.gdim
                                                };
                                              }))
    .def_property_readonly(
      "hessian",
      array_property<ND>(&ND::hessian,
                         [](const ND& r)
                         {
                           const py::ssize_t K = size(r.star.size()) * r.gdim;
                           return std::vector<py::ssize_t>{ r.gdim, K, K };
                         }));

  m.def(
    "averaged_normal_derivatives",
    [](FacetType type,
       const array_t& x,
       const int_array_t& cells,
       const int64_array_t& ids,
       std::int64_t node)
    {
      auto s = surface_view(type, x, cells);
      return averaged_normal_derivatives(
        s, std::span<const std::int64_t>(ids.data(), ids.size()), node);
    },
    py::arg("facet_type"),
    py::arg("x"),
    py::arg("cells"),
    py::arg("ids"),
    py::arg("node"),
    "The averaged unit normal at a node with its exact derivatives");

  m.def(
    "normal_clusters",
    [](FacetType type,
       const array_t& x,
       const int_array_t& cells,
       const int64_array_t& ids)
    {
      auto s = surface_view(type, x, cells);
      std::vector<std::int64_t> root = normal_clusters(
        s, std::span<const std::int64_t>(ids.data(), ids.size()));
      return py::array_t<std::int64_t>(static_cast<py::ssize_t>(root.size()),
                                       root.data());
    },
    py::arg("facet_type"),
    py::arg("x"),
    py::arg("cells"),
    py::arg("ids"),
    "Per node, the smallest id of the nodes that share its averaged normal "
    "(joined by a cell edge shorter than negligible_facet_ratio times the "
    "largest cell around them)");
}

} // namespace dolfinx_mortar::bindings
