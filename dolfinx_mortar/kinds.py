"""Names of the six mortar basis kinds and their properties.

The C++ kernels own the canonical names and aliases; this module only gives
them a Python face.
"""
from __future__ import annotations

from typing import Union

from dolfinx_mortar import _kernels

BasisKind = _kernels.BasisKind

#: Canonical names in the paper's order.
KIND_NAMES: tuple[str, ...] = tuple(_kernels.to_string(k) for k in _kernels.all_basis_kinds())

KindLike = Union[str, BasisKind]

#: The dual (biorthogonal) kinds: element-wise, discontinuous, negative in part.
DUAL_KINDS = (BasisKind.LcLS_star, BasisKind.LcLS)


def parse_kind(kind: KindLike) -> BasisKind:
    """Return the :class:`BasisKind` for a name, an alias or a kind.

    Parameters
    ----------
    kind
        ``"GLS"``, ``"GLS*"``, ``"LmLS"``, ``"LmLS*"``, ``"LcLS*"``, ``"LcLS"``,
        or an alias ``"standard"`` (LmLS*), ``"weighted"`` (LmLS), ``"dual"``
        (LcLS*).

    Raises
    ------
    ValueError
        For an unknown name; the message lists the valid ones.
    """
    if isinstance(kind, BasisKind):
        return kind
    if not isinstance(kind, str):
        raise TypeError(f"basis kind must be a string, not {type(kind).__name__}")
    return _kernels.basis_kind_from_string(kind)


def is_partition_of_unity(kind: KindLike) -> bool:
    """True for the starred kinds (Σ_A M_A = 1)."""
    return _kernels.is_partition_of_unity(parse_kind(kind))


def is_global(kind: KindLike) -> bool:
    """True for GLS and GLS*, whose functions have global support."""
    return _kernels.is_global(parse_kind(kind))


def unstarred_partner(kind: KindLike) -> BasisKind:
    """The kind with ∫M_A = 1 of which ``kind`` is a column scaling by W."""
    return _kernels.unstarred_partner(parse_kind(kind))


def kind_name(kind: KindLike) -> str:
    """Canonical name of a kind or alias (``"dual"`` → ``"LcLS*"``)."""
    return _kernels.to_string(parse_kind(kind))
