"""The library's warnings: one decision of all ranks, shown once.

Every warning of dolfinx_mortar follows a decision that the ranks of a
communicator make together (a penetration reduced over the ranks, an input that
is the same on each). It is issued on every rank, so that a filter that turns
it into an error (``-W error::RuntimeWarning``, pytest's ``filterwarnings``)
raises on all ranks together instead of leaving the others waiting in the next
collective, and so that ``pytest.warns`` sees it on each. By default only the
first rank of that communicator shows it: on 16 ranks a user read each warning
16 times.
"""
from __future__ import annotations

import os
import sys
import warnings
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Iterator, Optional, Protocol

__all__ = ["ContactWarning", "ContactWarningCopy", "warn", "deciding"]


class ContactWarning(RuntimeWarning):
    """A warning of dolfinx_mortar (contact missed, a penalty too low, an
    input beyond a model's range), shown by the first rank of the
    communicator that decided it."""


class ContactWarningCopy(ContactWarning):
    """The same warning on the other ranks of that communicator: ignored by the
    default filters. Whatever asks for warnings explicitly
    (``warnings.simplefilter("always")`` or ``"error"``, ``pytest.warns``)
    sees it on every rank."""


class Communicator(Protocol):
    """What a warning needs of an MPI communicator."""

    @property
    def rank(self) -> int:
        """This process's rank in the communicator."""


_deciding: ContextVar[Optional[Communicator]] = ContextVar("deciding", default=None)


@contextmanager
def deciding(comm: Communicator) -> Iterator[None]:
    """Warnings issued in the block without a communicator belong to ``comm``
    (the checks of a term's arguments, which do not know the mesh's)."""
    token = _deciding.set(comm)
    try:
        yield
    finally:
        _deciding.reset(token)


def warn(message: str, comm: Optional[Communicator] = None) -> None:
    """Issue ``message`` as a :class:`ContactWarning` on the first rank of
    ``comm`` and as a :class:`ContactWarningCopy` on its other ranks, from the
    user's line that called into the library.

    Parameters
    ----------
    message
        The warning, the same on every rank.
    comm
        The communicator whose ranks decided to warn (None: the one of the
        enclosing :func:`deciding` block). Every rank of it must call.
    """
    comm = comm if comm is not None else _deciding.get()
    if comm is None:
        raise TypeError("a warning of the library needs the communicator that decided it")
    _keep_copies_quiet()
    category = ContactWarning if comm.rank == 0 else ContactWarningCopy
    warnings.warn(message, category, stacklevel=_first_level_outside_the_library())


#: the package's folder: a warning names the first line outside it
_LIBRARY = os.path.dirname(os.path.abspath(__file__)) + os.sep


def _first_level_outside_the_library() -> int:
    # the stacklevel, for warnings.warn in warn(), of the first caller outside
    # the package: a fixed level named a line of the library's load path, deep
    # or shallow as the call came (Python 3.12's skip_file_prefixes does this too)
    frame, level = sys._getframe(1), 1          # warn() itself
    while frame is not None and frame.f_code.co_filename.startswith(_LIBRARY):
        frame, level = frame.f_back, level + 1
    return level


def _keep_copies_quiet() -> None:
    # appended, so that any filter the user or pytest set (error, always, ignore)
    # comes first and wins; put back where a catch_warnings block dropped it
    if not any(entry[2] is ContactWarningCopy for entry in warnings.filters):
        warnings.filterwarnings("ignore", category=ContactWarningCopy, append=True)


_keep_copies_quiet()
