// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#include <dolfinx_mortar/basis_kind.h>
#include <gtest/gtest.h>
#include <stdexcept>

using namespace dolfinx_mortar;

TEST(BasisKind, NamesRoundTrip)
{
  for (BasisKind k : all_basis_kinds)
    EXPECT_EQ(basis_kind_from_string(to_string(k)), k);
}

TEST(BasisKind, Aliases)
{
  EXPECT_EQ(basis_kind_from_string("standard"), BasisKind::LmLS_star);
  EXPECT_EQ(basis_kind_from_string("weighted"), BasisKind::LmLS);
  EXPECT_EQ(basis_kind_from_string("dual"), BasisKind::LcLS_star);
}

TEST(BasisKind, NamesAreExact)
{
  // "LcLs" is a near miss of two kinds: refused, not taken for one of them
  for (const char* name : {"LcLs", "gls", "lcls*", "LMLS", "Dual"})
    EXPECT_THROW(basis_kind_from_string(name), std::invalid_argument) << name;
}

TEST(BasisKind, UnknownNameThrowsWithName)
{
  try
  {
    basis_kind_from_string("GLSX");
    FAIL() << "no exception";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string(e.what()).find("GLSX"), std::string::npos);
  }
}

TEST(BasisKind, StarredKindsArePartitionsOfUnity)
{
  EXPECT_TRUE(is_partition_of_unity(BasisKind::GLS_star));
  EXPECT_TRUE(is_partition_of_unity(BasisKind::LmLS_star));
  EXPECT_TRUE(is_partition_of_unity(BasisKind::LcLS_star));
  EXPECT_FALSE(is_partition_of_unity(BasisKind::GLS));
  EXPECT_FALSE(is_partition_of_unity(BasisKind::LmLS));
  EXPECT_FALSE(is_partition_of_unity(BasisKind::LcLS));
  EXPECT_EQ(unstarred_partner(BasisKind::LcLS_star), BasisKind::LcLS);
  EXPECT_EQ(unstarred_partner(BasisKind::GLS), BasisKind::GLS);
}
