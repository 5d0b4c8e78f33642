// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
//
// Bindings of the current surface's cell quantities: numpy views in, a typed
// result out.
#include "bindings.h"

#include <dolfinx_mortar/current_surface.h>

#include <optional>
#include <pybind11/stl.h>

namespace dolfinx_mortar::bindings
{
namespace
{
/// The cells and their rule, viewing the caller's arrays.
SurfaceCells
cells_view(const array_t& x,
           const array_t& N,
           const array_t& dN,
           const array_t& weights,
           const array_t& phi,
           bool axisymmetric)
{
  if (x.ndim() != 3 or N.ndim() != 2 or dN.ndim() != 3 or weights.ndim() != 1 or
      phi.ndim() != 2)
    throw std::invalid_argument(
      "x must have shape (cells, nodes, gdim), N and phi "
      "(points, nodes), dN (points, tdim, nodes), weights "
      "(points)");
  SurfaceCells s;
  s.gdim = static_cast<int>(x.shape(2));
  s.nodes = static_cast<int>(x.shape(1));
  s.tdim = static_cast<int>(dN.shape(1));
  s.x = as_span(x);
  s.N = as_span(N);
  s.dN = as_span(dN);
  s.weights = as_span(weights);
  s.phi = as_span(phi);
  s.axisymmetric = axisymmetric;
  return s;
}

/// The obstacle's point data, or nothing if none is given.
std::optional<ObstacleAtPoints>
obstacle_view(const std::optional<array_t>& d,
              const std::optional<array_t>& gradient,
              const std::optional<array_t>& hessian,
              bool positive_part)
{
  if (!d and !gradient and !hessian)
    return std::nullopt;
  if (!d or !gradient or !hessian)
    throw std::invalid_argument(
      "an obstacle needs its d, gradient and hessian together");
  return ObstacleAtPoints{
    as_span(*d), as_span(*gradient), as_span(*hessian), positive_part
  };
}

/// (cells, nodes) and (cells, nodes, variables) arrays of a result, or None
/// where the result has none.
py::object
maybe(const std::vector<double>& v, std::vector<py::ssize_t> shape)
{
  if (v.empty())
    return py::none();
  return to_numpy(v, std::move(shape));
}
} // namespace

void
bind_current_surface(py::module_& m)
{
  py::class_<SurfaceCellDerivatives>(
    m,
    "SurfaceCellDerivatives",
    "Cell quantities of a surface in the current configuration with their "
    "gradients "
    "with respect to each cell's node coordinates: W = ∫ N_a J and, against an "
    "obstacle, the gaps ∫ φ_a J d (and ∫ φ_a J <d>)")
    .def_property_readonly(
      "W",
      [](const SurfaceCellDerivatives& r) {
        return to_numpy(r.W,
                        { static_cast<py::ssize_t>(r.num_cells), r.nodes });
      })
    .def_property_readonly(
      "W_gradient",
      [](const SurfaceCellDerivatives& r)
      {
        return to_numpy(
          r.W_gradient,
          { static_cast<py::ssize_t>(r.num_cells), r.nodes, r.num_variables });
      })
    .def_property_readonly(
      "gap",
      [](const SurfaceCellDerivatives& r) {
        return maybe(r.gap, { static_cast<py::ssize_t>(r.num_cells), r.nodes });
      })
    .def_property_readonly(
      "gap_gradient",
      [](const SurfaceCellDerivatives& r)
      {
        return maybe(
          r.gap_gradient,
          { static_cast<py::ssize_t>(r.num_cells), r.nodes, r.num_variables });
      })
    .def_property_readonly(
      "gap_plus",
      [](const SurfaceCellDerivatives& r)
      {
        return maybe(r.gap_plus,
                     { static_cast<py::ssize_t>(r.num_cells), r.nodes });
      })
    .def_property_readonly(
      "gap_plus_gradient",
      [](const SurfaceCellDerivatives& r)
      {
        return maybe(
          r.gap_plus_gradient,
          { static_cast<py::ssize_t>(r.num_cells), r.nodes, r.num_variables });
      });

  m.def(
    "current_surface_cells",
    [](const array_t& x,
       const array_t& N,
       const array_t& dN,
       const array_t& weights,
       const array_t& phi,
       bool axisymmetric,
       std::optional<array_t> obstacle_d,
       std::optional<array_t> obstacle_gradient,
       std::optional<array_t> obstacle_hessian,
       bool positive_part)
    {
      const SurfaceCells s = cells_view(x, N, dN, weights, phi, axisymmetric);
      const auto ob = obstacle_view(
        obstacle_d, obstacle_gradient, obstacle_hessian, positive_part);
      py::gil_scoped_release release;
      return current_surface_cells(s, ob ? &*ob : nullptr);
    },
    py::arg("x"),
    py::arg("N"),
    py::arg("dN"),
    py::arg("weights"),
    py::arg("phi"),
    py::arg("axisymmetric") = false,
    py::arg("obstacle_d") = py::none(),
    py::arg("obstacle_gradient") = py::none(),
    py::arg("obstacle_hessian") = py::none(),
    py::arg("positive_part") = false,
    "W = ∫ N_a J per cell and, with an obstacle's d = -φ(x) and its "
    "derivatives at the "
    "points, the gaps ∫ φ_a J d (and with positive_part ∫ φ_a J <d>), with "
    "their exact "
    "gradients");

  m.def(
    "current_surface_hessians",
    [](const array_t& x,
       const array_t& N,
       const array_t& dN,
       const array_t& weights,
       const array_t& phi,
       const array_t& W_weights,
       bool axisymmetric,
       std::optional<array_t> obstacle_d,
       std::optional<array_t> obstacle_gradient,
       std::optional<array_t> obstacle_hessian,
       std::optional<array_t> gap_weights)
    {
      const SurfaceCells s = cells_view(x, N, dN, weights, phi, axisymmetric);
      const auto ob =
        obstacle_view(obstacle_d, obstacle_gradient, obstacle_hessian, false);
      if (ob and !gap_weights)
        throw std::invalid_argument(
          "an obstacle's gap Hessian needs gap_weights");
      std::vector<double> h;
      {
        py::gil_scoped_release release;
        h = current_surface_hessians(s,
                                     ob ? &*ob : nullptr,
                                     as_span(W_weights),
                                     gap_weights ? as_span(*gap_weights)
                                                 : std::span<const double>());
      }
      const auto nv = static_cast<py::ssize_t>(s.num_variables());
      return to_numpy(h, { static_cast<py::ssize_t>(s.num_cells()), nv, nv });
    },
    py::arg("x"),
    py::arg("N"),
    py::arg("dN"),
    py::arg("weights"),
    py::arg("phi"),
    py::arg("W_weights"),
    py::arg("axisymmetric") = false,
    py::arg("obstacle_d") = py::none(),
    py::arg("obstacle_gradient") = py::none(),
    py::arg("obstacle_hessian") = py::none(),
    py::arg("gap_weights") = py::none(),
    "The Hessian of sum_a (W_weights_a W_a + gap_weights_a gap_a) of every "
    "cell, (cells, "
    "variables, variables)");
}

} // namespace dolfinx_mortar::bindings
