// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#include <dolfinx_mortar/geometric_tolerance.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace dolfinx_mortar
{

double
length_scale(std::span<const double> x, int gdim)
{
  if (gdim < 1 or gdim > 3 or x.size() % gdim != 0)
    throw std::invalid_argument("length_scale: x must have shape (points, "
                                "gdim) with gdim 1, 2 or 3");
  if (x.empty())
    return 0.0;
  std::array<double, 3> lo{ x[0], gdim > 1 ? x[1] : 0.0,
                            gdim > 2 ? x[2] : 0.0 },
    hi = lo;
  for (std::size_t i = 0; i < x.size(); ++i)
  {
    const int k = static_cast<int>(i % gdim);
    lo[k] = std::min(lo[k], x[i]);
    hi[k] = std::max(hi[k], x[i]);
  }
  double diagonal = 0;
  for (int k = 0; k < gdim; ++k)
    diagonal += (hi[k] - lo[k]) * (hi[k] - lo[k]);
  return std::sqrt(diagonal);
}

double
zero_length(std::span<const double> x, int gdim)
{
  return std::max(geometric_tolerance * length_scale(x, gdim),
                  std::numeric_limits<double>::min());
}

} // namespace dolfinx_mortar
