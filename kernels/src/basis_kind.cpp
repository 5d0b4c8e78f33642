// Copyright (C) 2026 dolfinx_mortar developers
// SPDX-License-Identifier: MIT
#include <dolfinx_mortar/basis_kind.h>

#include <string>

#include <stdexcept>

namespace dolfinx_mortar
{

std::string
to_string(BasisKind kind)
{
  switch (kind)
  {
    case BasisKind::GLS:
      return "GLS";
    case BasisKind::GLS_star:
      return "GLS*";
    case BasisKind::LmLS:
      return "LmLS";
    case BasisKind::LmLS_star:
      return "LmLS*";
    case BasisKind::LcLS_star:
      return "LcLS*";
    case BasisKind::LcLS:
      return "LcLS";
  }
  throw std::logic_error("corrupt BasisKind value");
}

BasisKind
basis_kind_from_string(std::string_view name)
{
  // Exact: "LcLs" is one letter from LcLS* and from LcLS, and matching
  // without case took it silently for LcLS (issue 35). The Python layer
  // names the near misses; here an unknown name is refused.
  for (BasisKind kind : all_basis_kinds)
    if (name == to_string(kind))
      return kind;
  if (name == "standard")
    return BasisKind::LmLS_star;
  if (name == "weighted")
    return BasisKind::LmLS;
  if (name == "dual")
    return BasisKind::LcLS_star;
  throw std::invalid_argument(
    "unknown mortar basis kind '" + std::string(name) +
    "'; valid kinds are GLS, GLS*, LmLS, LmLS*, LcLS*, LcLS and the "
    "aliases standard (LmLS*), weighted (LmLS), dual (LcLS*), exactly as written");
}

bool
is_partition_of_unity(BasisKind kind)
{
  return kind == BasisKind::GLS_star or kind == BasisKind::LmLS_star or
         kind == BasisKind::LcLS_star;
}

BasisKind
unstarred_partner(BasisKind kind)
{
  switch (kind)
  {
    case BasisKind::GLS_star:
      return BasisKind::GLS;
    case BasisKind::LmLS_star:
      return BasisKind::LmLS;
    case BasisKind::LcLS_star:
      return BasisKind::LcLS;
    default:
      return kind;
  }
}

bool
is_global(BasisKind kind)
{
  return kind == BasisKind::GLS or kind == BasisKind::GLS_star;
}

bool
needs_positive_weights(BasisKind kind)
{
  return kind != BasisKind::GLS and kind != BasisKind::LmLS_star;
}

} // namespace dolfinx_mortar
