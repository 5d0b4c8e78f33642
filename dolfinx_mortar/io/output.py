"""Result files that are either complete or absent.

Every result is written to a temporary file in the target folder and renamed
into place, so an interrupted run never leaves a truncated JSON, CSV or PNG.

A file-system step that one rank does for all (:func:`on_rank0`) is a
collective decision: when it fails, every rank raises the same error, none is
left waiting for the others in a barrier.
"""
from __future__ import annotations

import json
import os
import secrets
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Callable, Iterator, Mapping, Optional, Sequence, Union

PathLike = Union[str, os.PathLike]


@contextmanager
def replacing(path: PathLike, suffix: str = "") -> Iterator[str]:
    """Yield a new temporary file next to ``path``; rename it over ``path`` on success.

    The temporary file is created as ``open`` creates files (mode 0666 less the umask), so the
    result is as readable to other users and servers as any file the user writes; ``tempfile``'s
    files are 0600. On any exception the temporary file is removed and ``path`` is untouched.

    Parameters
    ----------
    path
        Final location; its folder is created if needed.
    suffix
        Ending of the temporary name (some writers choose the format by it).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    while True:
        tmp = path.parent / f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}{suffix}"
        try:
            os.close(os.open(tmp, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o666))
            break
        except FileExistsError:
            continue
    try:
        yield str(tmp)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def on_rank0(comm: Any, action: Callable[[], None], what: str) -> None:
    """Run ``action()`` on rank 0 of ``comm``; every rank returns, or every rank raises.

    Collective: the other ranks wait until rank 0 is done (as at a barrier). An error of
    rank 0 is raised on all ranks: an ``OSError`` as the ``OSError`` of the same errno (so
    ``PermissionError``, ``NotADirectoryError``, ... with the path it names), any other
    exception as a ``RuntimeError``; the message starts with ``what``.

    Parameters
    ----------
    comm
        The mpi4py communicator of the ranks that go on together.
    action
        The file-system step.
    what
        What the step is for, naming its file, e.g. ``"XDMF series run.xdmf: index"``.
    """
    failure: Optional[BaseException] = None
    report = None
    if comm.rank == 0:
        try:
            action()
        except Exception as err:
            failure = err
            if isinstance(err, OSError) and err.errno is not None:
                report = ("os", err.errno, f"{what}: {err.strerror}", err.filename)
            else:
                report = ("other", f"{what}: {type(err).__name__}: {err}")
    report = comm.bcast(report, root=0)
    if report is None:
        return
    if report[0] == "os":
        _, number, message, filename = report
        # OSError(errno, ...) is the subclass of that errno (PermissionError, ...)
        error: Exception = (OSError(number, message, filename) if filename is not None
                            else OSError(number, message))
    else:
        error = RuntimeError(report[1])
    raise error from failure


def write_atomically(path: PathLike, write: Callable[[str], None]) -> Path:
    """Call ``write(tmp_path)`` and move the result to ``path`` (see :func:`replacing`).

    Parameters
    ----------
    path
        Final location; its folder is created if needed.
    write
        Writes the complete file at the temporary path it is given.
    """
    with replacing(path, Path(path).suffix) as tmp:
        write(tmp)
    return Path(path)


def write_json(path: PathLike, data: Any) -> Path:
    """Write ``data`` as indented JSON, atomically."""
    def write(tmp: str) -> None:
        with open(tmp, "w") as f:
            json.dump(data, f, indent=2, sort_keys=True)
            f.write("\n")
    return write_atomically(path, write)


def save_figure(path: PathLike, figure: Any, **kwargs: Any) -> Path:
    """Save a matplotlib figure atomically (format from the suffix)."""
    fmt = Path(path).suffix.lstrip(".") or "png"
    return write_atomically(path, lambda tmp: figure.savefig(tmp, format=fmt, **kwargs))


def write_csv(path: PathLike, rows: Sequence[Mapping[str, Any]],
              columns: Optional[Sequence[str]] = None) -> Path:
    """Write dict rows as CSV with a header, atomically.

    ``columns`` fixes the order (default: the keys of the first row); keys
    missing from a row are left empty.
    """
    import csv
    fields = list(columns) if columns is not None else list(rows[0]) if rows else []

    def write(tmp: str) -> None:
        with open(tmp, "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
            writer.writeheader()
            writer.writerows(rows)
    return write_atomically(path, write)
