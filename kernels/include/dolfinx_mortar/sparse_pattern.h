// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#pragma once

#include <concepts>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <vector>

namespace dolfinx_mortar
{

/// Where each entry of the sparse pattern `inner` lies in the pattern
/// `outer`. Both are compressed by rows (row pointers and columns, each
/// row's columns ascending, as PETSc's AIJ blocks keep them) with the same
/// number of rows. Returns, for each entry of `inner` in order, its index
/// in `outer`'s column array, or nothing if some entry of `inner` is not in
/// `outer`. One merge per row that `inner` has entries in: the cost is the
/// length of those rows of `outer`, not a search over all of it. Used to add
/// the contact stiffness into the Newton matrix's value array in place.
template<std::integral I, std::integral J, std::integral K>
std::optional<std::vector<std::int64_t>>
positions_in_pattern(std::span<const I> outer_rows,
                     std::span<const I> outer_columns,
                     std::span<const J> inner_rows,
                     std::span<const K> inner_columns)
{
  if (outer_rows.size() != inner_rows.size() or outer_rows.empty())
    throw std::invalid_argument(
      "the two patterns must have the same number of rows");
  if (static_cast<std::size_t>(outer_rows.back()) != outer_columns.size() or
      static_cast<std::size_t>(inner_rows.back()) != inner_columns.size())
    throw std::invalid_argument(
      "a pattern's last row pointer must be its number of entries");
  std::vector<std::int64_t> positions(inner_columns.size());
  for (std::size_t row = 0; row + 1 < inner_rows.size(); ++row)
  {
    std::int64_t p = outer_rows[row];
    const std::int64_t end = outer_rows[row + 1];
    for (auto e = inner_rows[row]; e < inner_rows[row + 1]; ++e)
    {
      const auto column = static_cast<std::int64_t>(inner_columns[e]);
      while (p < end and static_cast<std::int64_t>(outer_columns[p]) < column)
        ++p;
      if (p == end or static_cast<std::int64_t>(outer_columns[p]) != column)
        return std::nullopt;
      positions[e] = p;
    }
  }
  return positions;
}

} // namespace dolfinx_mortar
