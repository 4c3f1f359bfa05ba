"""Helpers shared by the text-format readers: errors that name file and line."""

import os

__all__ = ["format_number", "parse_error", "parse_floats", "read_lines"]


def parse_error(path, lineno, message):
    """A ``ValueError`` whose message starts with ``"{path}, line {lineno}: "``."""
    return ValueError(f"{os.fspath(path)}, line {lineno}: {message}")


def read_lines(path):
    """The lines of a text file, numbered from 1, without line endings.

    Returns
    -------
    lines : list of (int, str)
    """
    with open(path, encoding="utf-8", errors="replace") as f:
        return [(i, line.rstrip("\r\n")) for i, line in enumerate(f, start=1)]


def parse_floats(tokens, path, lineno, what="value"):
    """Convert tokens to floats, raising :func:`parse_error` on a bad number."""
    values = []
    for token in tokens:
        try:
            values.append(float(token))
        except ValueError:
            raise parse_error(
                path, lineno, f"bad {what} {token!r}, expected a number"
            ) from None
    return values


def format_number(value):
    """Shortest text that reads back as exactly the same float."""
    value = float(value)
    if value.is_integer() and abs(value) < 1e15:
        return str(int(value))
    return repr(value)
