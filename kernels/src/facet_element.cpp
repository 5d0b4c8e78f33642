// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#include <dolfinx_mortar/facet_element.h>

#include <stdexcept>

namespace dolfinx_mortar
{

int
facet_tdim(FacetType type)
{
  return (type == FacetType::P1_line or type == FacetType::P2_line) ? 1 : 2;
}

int
facet_num_nodes(FacetType type)
{
  switch (type)
  {
    case FacetType::P1_line:
      return 2;
    case FacetType::P2_line:
      return 3;
    case FacetType::P1_triangle:
      return 3;
    case FacetType::P2_triangle:
      return 6;
    case FacetType::Q1_quadrilateral:
      return 4;
    case FacetType::Q2_quadrilateral:
      return 9;
    case FacetType::Q8_quadrilateral:
      return 8;
  }
  throw std::logic_error("corrupt FacetType");
}

std::string
to_string(FacetType type)
{
  switch (type)
  {
    case FacetType::P1_line:
      return "P1 line";
    case FacetType::P2_line:
      return "P2 line";
    case FacetType::P1_triangle:
      return "P1 triangle";
    case FacetType::P2_triangle:
      return "P2 triangle";
    case FacetType::Q1_quadrilateral:
      return "Q1 quadrilateral";
    case FacetType::Q2_quadrilateral:
      return "Q2 quadrilateral";
    case FacetType::Q8_quadrilateral:
      return "8-node quadrilateral";
  }
  throw std::logic_error("corrupt FacetType");
}

void
facet_shape_functions(FacetType type,
                      std::span<const double> X,
                      std::span<double> N,
                      std::span<double> dN)
{
  shape_functions<double>(type, X, N, dN);
}

const std::vector<std::vector<std::array<double, 2>>>&
facet_subfacets(FacetType type)
{
  using Polygons = std::vector<std::vector<std::array<double, 2>>>;
  static const Polygons line1 = { { { 0, 0 }, { 1, 0 } } };
  static const Polygons line2 = { { { 0, 0 }, { 0.5, 0 } },
                                  { { 0.5, 0 }, { 1, 0 } } };
  static const Polygons triangle1 = { { { 0, 0 }, { 1, 0 }, { 0, 1 } } };
  static const Polygons triangle2 = {
    { { 0, 0 }, { 0.5, 0 }, { 0, 0.5 } },
    { { 0.5, 0 }, { 1, 0 }, { 0.5, 0.5 } },
    { { 0, 0.5 }, { 0.5, 0.5 }, { 0, 1 } },
    { { 0.5, 0 }, { 0.5, 0.5 }, { 0, 0.5 } }
  };
  static const Polygons quad1 = { { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } } };
  static const Polygons quad2 = {
    { { 0, 0 }, { 0.5, 0 }, { 0.5, 0.5 }, { 0, 0.5 } },
    { { 0.5, 0 }, { 1, 0 }, { 1, 0.5 }, { 0.5, 0.5 } },
    { { 0, 0.5 }, { 0.5, 0.5 }, { 0.5, 1 }, { 0, 1 } },
    { { 0.5, 0.5 }, { 1, 0.5 }, { 1, 1 }, { 0.5, 1 } }
  };
  switch (type)
  {
    case FacetType::P1_line:
      return line1;
    case FacetType::P2_line:
      return line2;
    case FacetType::P1_triangle:
      return triangle1;
    case FacetType::P2_triangle:
      return triangle2;
    case FacetType::Q1_quadrilateral:
      return quad1;
    case FacetType::Q2_quadrilateral:
    case FacetType::Q8_quadrilateral:
      return quad2;
  }
  throw std::logic_error("corrupt FacetType");
}

} // namespace dolfinx_mortar
