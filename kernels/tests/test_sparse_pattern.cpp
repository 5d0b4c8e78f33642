// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#include <dolfinx_mortar/sparse_pattern.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>
#include <vector>

using namespace dolfinx_mortar;

namespace
{
// rows {0, 2, 5}, {}, {1, 3}, {0, 1, 2, 3}
const std::vector<std::int32_t> outer_rows{ 0, 3, 3, 5, 9 };
const std::vector<std::int32_t> outer_columns{ 0, 2, 5, 1, 3, 0, 1, 2, 3 };
} // namespace

TEST(SparsePattern, FindsEachEntryOfASubPattern)
{
  const std::vector<std::int64_t> rows{ 0, 2, 2, 3, 5 };
  const std::vector<std::int64_t> columns{ 0, 5, 3, 1, 3 };
  auto found = positions_in_pattern(std::span(outer_rows),
                                    std::span(outer_columns),
                                    std::span(rows),
                                    std::span(columns));
  ASSERT_TRUE(found.has_value());
  EXPECT_EQ(*found, (std::vector<std::int64_t>{ 0, 2, 4, 6, 8 }));
}

TEST(SparsePattern, AnEntryOutsideGivesNothing)
{
  // column 4 of row 0, and an entry in the empty row 1
  for (const auto& [rows, columns] :
       { std::pair{ std::vector<std::int64_t>{ 0, 2, 2, 2, 2 },
                    std::vector<std::int64_t>{ 2, 4 } },
         std::pair{ std::vector<std::int64_t>{ 0, 0, 1, 1, 1 },
                    std::vector<std::int64_t>{ 0 } } })
  {
    EXPECT_FALSE(positions_in_pattern(std::span(outer_rows),
                                      std::span(outer_columns),
                                      std::span(rows),
                                      std::span(columns))
                   .has_value());
  }
}

TEST(SparsePattern, PatternsOfOtherShapesAreRefused)
{
  const std::vector<std::int64_t> rows{ 0, 1 };
  const std::vector<std::int64_t> columns{ 0 };
  EXPECT_THROW(positions_in_pattern(std::span(outer_rows),
                                    std::span(outer_columns),
                                    std::span(rows),
                                    std::span(columns)),
               std::invalid_argument);
}
