// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

// What every binding file shares: numpy arrays in (views, no copy) and out
// (one copy into numpy-owned memory).
#include <dolfinx_mortar/facet_element.h>
#include <dolfinx_mortar/surface_geometry.h>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace dolfinx_mortar::bindings
{
namespace py = pybind11;

using array_t = py::array_t<double, py::array::c_style | py::array::forcecast>;
using int_array_t =
  py::array_t<std::int32_t, py::array::c_style | py::array::forcecast>;
using int64_array_t =
  py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;

template<typename T>
py::array_t<T>
to_numpy_as(const std::vector<T>& v, std::vector<py::ssize_t> shape)
{
  return py::array_t<T>(shape, v.data());
}

/// A FacetSurface viewing numpy arrays that the caller keeps alive.
inline FacetSurface
surface_view(FacetType type, const array_t& x, const int_array_t& cells)
{
  if (x.ndim() != 2 or cells.ndim() != 2)
    throw std::invalid_argument(
      "x must be (nodes, gdim), cells (cells, nodes)");
  if (cells.shape(1) != facet_num_nodes(type))
    throw std::invalid_argument(to_string(type) + " cells need " +
                                std::to_string(facet_num_nodes(type)) +
                                " nodes");
  return FacetSurface{ type,
                       static_cast<int>(x.shape(1)),
                       std::span<const double>(x.data(), x.size()),
                       std::span<const std::int32_t>(cells.data(),
                                                     cells.size()) };
}

/// A view of a numpy array's data.
inline std::span<const double>
as_span(const array_t& a)
{
  return std::span<const double>(a.data(), static_cast<std::size_t>(a.size()));
}

// One copy into numpy-owned memory: cheap next to the kernel work, and it
// keeps ownership simple.
inline array_t
to_numpy(const std::vector<double>& v, std::vector<py::ssize_t> shape)
{
  return array_t(shape, v.data());
}

/// The current surface's cell quantities (current_surface.h).
void
bind_current_surface(py::module_& m);

/// The segmentation's integrals and the current configuration's pair gaps
/// (mortar_integrals.h, current_pair_gaps.h).
void
bind_segmentation(py::module_& m);

} // namespace dolfinx_mortar::bindings
