"""Helpers for the demo scripts (command lines); not part of the library core."""
