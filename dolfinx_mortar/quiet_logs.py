"""Keep the user's terminal quiet while FFCx compiles forms on a cold cache.

FFCx calls ``logging.basicConfig()`` and compiles through cffi/setuptools,
whose distutils layer raises the root logger to INFO: a first run printed a
page of ``INFO:root:running build_ext`` and compiler command lines per form.
A filter on the root logger drops those records below WARNING; errors still
show. ``DOLFINX_MORTAR_BUILD_LOGS=1`` keeps them.
"""
from __future__ import annotations

import logging
import os

#: set to 1 to see the FFCx/setuptools build lines
ENVIRONMENT_SWITCH = "DOLFINX_MORTAR_BUILD_LOGS"


class QuietBuildFilter(logging.Filter):
    """Drops setuptools/distutils records below WARNING."""

    def filter(self, record: logging.LogRecord) -> bool:
        if record.levelno >= logging.WARNING:
            return True
        path = record.pathname.replace("\\", "/")
        return not ("/distutils/" in path or "/setuptools/" in path)


def install() -> None:
    """Install the filter once (unless the environment asks for the logs)."""
    if os.environ.get(ENVIRONMENT_SWITCH, "0") not in ("", "0"):
        return
    root = logging.getLogger()
    if not any(isinstance(f, QuietBuildFilter) for f in root.filters):
        root.addFilter(QuietBuildFilter())
