"""Result files that are either complete or absent.

Every result is written to a temporary file in the target folder and renamed
into place, so an interrupted run never leaves a truncated JSON, CSV or PNG.
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
