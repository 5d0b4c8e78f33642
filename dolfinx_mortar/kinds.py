"""Names of the six mortar basis kinds and their properties.

The C++ kernels own the canonical names and aliases; this module only gives
them a Python face. Names are matched exactly (case included): "LcLs" was
once taken for LcLS, though it is as near to LcLS*, so a near miss is refused
with the valid names.
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

#: The documented aliases and the kinds they stand for.
KIND_ALIASES: dict[str, str] = {"standard": "LmLS*", "weighted": "LmLS", "dual": "LcLS*"}


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
        For any other string, also one that differs from a valid name in case
        only; the message lists the valid names.
    """
    if isinstance(kind, BasisKind):
        return kind
    if not isinstance(kind, str):
        raise TypeError(f"basis kind must be a string, not {type(kind).__name__}")
    if kind not in KIND_NAMES and kind not in KIND_ALIASES:
        # the kernels match without case; exactness is this layer's rule
        # a starred and an unstarred kind differ by one character: name both
        near = [name for name in (*KIND_NAMES, *KIND_ALIASES)
                if name.lower().rstrip("*") == kind.strip().lower().rstrip("*")]
        hint = (f" (did you mean {' or '.join(repr(n) for n in near)}? case matters)"
                if near else "")
        aliases = ", ".join(f"{a!r} ({k})" for a, k in KIND_ALIASES.items())
        raise ValueError(f"unknown mortar basis kind {kind!r}{hint}; valid kinds are "
                         f"{', '.join(repr(k) for k in KIND_NAMES)} and the aliases {aliases}")
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


def dual_partner(kind: KindLike) -> BasisKind:
    """The dual kind with the same ∫M_A: LcLS* for LmLS* (W_A), LcLS for LmLS (1)."""
    return BasisKind.LcLS_star if is_partition_of_unity(kind) else BasisKind.LcLS


def kind_name(kind: KindLike) -> str:
    """Canonical name of a kind or alias (``"dual"`` → ``"LcLS*"``)."""
    return _kernels.to_string(parse_kind(kind))
