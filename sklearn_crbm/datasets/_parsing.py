"""Helpers shared by the text-format readers: errors that name file and line."""

import math
import os

__all__ = [
    "bvh_hint",
    "check_bone_names",
    "format_number",
    "load_mat_variables",
    "parse_error",
    "parse_floats",
    "read_lines",
]


def parse_error(path, lineno, message):
    """A ``ValueError`` whose message starts with ``"{path}, line {lineno}: "``."""
    return ValueError(f"{os.fspath(path)}, line {lineno}: {message}")


def bvh_hint(word):
    """What to tell a user who gave a BVH file to an Acclaim reader, whose
    first word is ``word``: nothing unless it is ``HIERARCHY``."""
    if word.upper() != "HIERARCHY":
        return ""
    return "; this is a BVH file: read it with read_bvh(path)"


def check_bone_names(names, file_format):
    """A ValueError for the first name its file format's reader would refuse.

    Names are single words: no whitespace (a line break would even start a
    new line of the file), not empty.  In BVH a name cannot be a brace; in
    AMC, where a line is a bone's name and its values, a name cannot start a
    header (``:``) or a comment (``#``), nor be a frame number.
    """
    for name in names:
        problem = None
        if not name or any(c.isspace() or not c.isprintable() for c in name):
            problem = "is empty or holds whitespace or unprintable characters"
        elif file_format == "BVH" and name in ("{", "}"):
            problem = "is a brace"
        elif file_format == "AMC" and (
            name.startswith(":") or "#" in name or name.lstrip("-").isdigit()
        ):
            problem = "starts with ':', holds '#' or is a number"
        if problem is not None:
            raise ValueError(
                f"Cannot write the bone name {name!r} to a {file_format} file: it "
                f"{problem}, so the file could not be read back. Build the "
                "skeleton with a one-word name for that bone."
            )


def read_lines(path):
    """The lines of a text file, numbered from 1, without line endings.

    Returns
    -------
    lines : list of (int, str)

    Raises
    ------
    TypeError
        If ``path`` is not a str, bytes or path-like object.
    OSError
        If the file cannot be read (e.g. it does not exist).
    ValueError
        If the file is empty or holds only whitespace, as a failed download
        leaves it: no motion file is.
    """
    if not isinstance(path, (str, bytes, os.PathLike)):
        raise TypeError(
            f"Expected the path of a file (str or os.PathLike), got "
            f"{type(path).__name__} {path!r}."
        )
    with open(path, encoding="utf-8", errors="replace") as f:
        lines = [(i, line.rstrip("\r\n")) for i, line in enumerate(f, start=1)]
    if not any(text.strip() for _, text in lines):
        what = "holds only blank lines" if lines else "has no content (0 bytes)"
        raise ValueError(
            f"{os.fsdecode(path)} is empty: the file {what}. A download or copy "
            "that failed? Fetch or export the file again."
        )
    return lines


def parse_floats(tokens, path, lineno, what="value"):
    """Convert tokens to floats, raising :func:`parse_error` on a bad number.

    NaN and infinity (``nan``, ``inf``, ``1e999``) are bad numbers too: no
    motion-capture file holds them, and they would poison everything
    computed from the data.
    """
    values = []
    for token in tokens:
        try:
            value = float(token)
        except ValueError:
            raise parse_error(
                path, lineno, f"bad {what} {token!r}, expected a number"
            ) from None
        if not math.isfinite(value):
            raise parse_error(
                path, lineno, f"bad {what} {token!r}, expected a finite number"
            )
        values.append(value)
    return values


def format_number(value):
    """Shortest text that reads back as exactly the same float."""
    value = float(value)
    if value.is_integer() and abs(value) < 1e15:
        return str(int(value))
    return repr(value)


def load_mat_variables(path, names, fetcher):
    """The variables ``names`` of a MATLAB file, or a ValueError if it is damaged.

    ``fetcher`` names the function that downloads the file again; the error
    message points the user at it.  A file that cannot be opened at all
    (missing, no permission) keeps its ``OSError``.
    """
    import scipy.io
    from scipy.io.matlab import MatReadError

    path = os.fspath(path)
    hint = f"Fetch it again with sklearn_crbm.datasets.{fetcher}()."
    try:
        mat = scipy.io.loadmat(path)
    except (FileNotFoundError, PermissionError, IsADirectoryError):
        raise
    except (MatReadError, OSError, ValueError, TypeError, KeyError, IndexError) as exc:
        raise ValueError(
            f"{path} is not a readable MATLAB file ({exc}); it may be truncated or "
            f"damaged. {hint}"
        ) from exc
    missing = [name for name in names if name not in mat]
    if missing:
        raise ValueError(
            f"{path} lacks the variables {missing}; it is not the expected data "
            f"file. {hint}"
        )
    return mat
