"""Acclaim AMC motion files, as written by the CMU database (skeletons: ``_asf``)."""

import os

import numpy as np

from ._asf import content_lines
from ._channels import frame_columns
from ._parsing import (
    bvh_hint,
    check_bone_names,
    format_number,
    parse_error,
    parse_floats,
)
from ._skeleton import Skeleton
from ._up_axis import check_up_axis

__all__ = ["read_amc", "write_amc"]


# --------------------------------------------------------------------- AMC
def read_amc(path, skeleton):
    """Read an Acclaim AMC motion file.

    Parameters
    ----------
    path : path-like
        The ``.amc`` file.
    skeleton : Skeleton or path-like
        Its skeleton, or the path of the ASF file.

    Returns
    -------
    data : ndarray of shape (n_frames, n_features)
        Raw channels in the skeleton's units, in the order of ``feature_names``.
    feature_names : ndarray of str
        ``skeleton.feature_names``.

    Raises
    ------
    ValueError
        If the file is malformed: a bad number, a bone the skeleton does not
        have, a bone with the wrong number of values, a frame that lacks
        bones (e.g. a truncated file), no frame at all (an empty file).  The
        message names the file and line.
    TypeError
        If ``skeleton`` is neither a Skeleton nor a path.

    Warns
    -----
    UserWarning
        If the motion stands along another axis than ``skeleton.up_axis``
        (see :meth:`Skeleton.detect_up_axis`).

    Examples
    --------
    >>> from sklearn_crbm.datasets import read_amc
    >>> data, names = read_amc("35_01.amc", "35.asf")  # doctest: +SKIP
    >>> data.shape  # doctest: +SKIP
    (358, 62)
    """
    skeleton = _check_skeleton(skeleton, "read_amc", allow_path=True)
    layout = _amc_layout(skeleton)
    n_features = len(skeleton.feature_names)
    frames, frame, lineno = [], None, 1
    for lineno, text in content_lines(path):
        tokens = text.split()
        if tokens[0].startswith(":"):
            if frames or frame is not None:
                raise parse_error(
                    path, lineno, f"header line {text!r} after the first frame"
                )
            _check_amc_unit(path, lineno, tokens[0], skeleton)
            continue
        if len(tokens) == 1 and _is_frame_number(tokens[0]):
            number = int(tokens[0])
            if frame is not None:
                frames.append(_finish_frame(path, frame, layout))
                _check_frame_number(path, lineno, number, frame["number"])
            frame = {
                "line": lineno,
                "number": number,
                "row": np.full(n_features, np.nan),
                "seen": set(),
            }
            continue
        if frame is None:
            raise parse_error(
                path,
                lineno,
                f"expected a frame number, got {text!r}" + bvh_hint(tokens[0]),
            )
        _amc_bone_line(path, lineno, tokens, frame, layout)
    if frame is not None:
        frames.append(_finish_frame(path, frame, layout))
    if not frames:
        raise parse_error(
            path,
            lineno,
            "no frames: an AMC file holds a frame number, then one line per bone "
            "(empty or truncated file?)",
        )
    data = np.array(frames, dtype=np.float64).reshape(len(frames), n_features)
    check_up_axis(
        skeleton.up_axis, skeleton.detect_up_axis(data), f"{path}: its skeleton has"
    )
    return data, skeleton.feature_names


_AMC_UNITS = {":degrees": "deg", ":radians": "rad"}


def _check_amc_unit(path, lineno, keyword, skeleton):
    """An AMC ``:DEGREES`` or ``:RADIANS`` header must agree with the skeleton."""
    unit = _AMC_UNITS.get(keyword.lower())
    if unit is not None and unit != skeleton.angle_unit:
        raise parse_error(
            path,
            lineno,
            f"the file's angles are in {keyword[1:].lower()} but the skeleton's "
            f"(angle_unit={skeleton.angle_unit!r}) are not; read it with the "
            "skeleton of its own ASF file",
        )


def _check_skeleton(skeleton, function, allow_path=False):
    """The skeleton itself, read from an ASF path if allowed, or a TypeError."""
    if isinstance(skeleton, Skeleton):
        return skeleton
    if allow_path and isinstance(skeleton, (str, os.PathLike)):
        return Skeleton.from_asf(skeleton)
    what = "a Skeleton or the path of an ASF file" if allow_path else "a Skeleton"
    raise TypeError(
        f"{function} needs {what}, got {type(skeleton).__name__} {skeleton!r}; "
        "read one with sklearn_crbm.datasets.Skeleton.from_asf(path)."
    )


def _amc_layout(skeleton):
    """``bone -> (first column, number of channels)`` for bones with channels."""
    layout, start = {}, 0
    for bone in skeleton.bones:
        if bone.channels:
            layout[bone.name] = (start, len(bone.channels))
            start += len(bone.channels)
    return layout


def _amc_bone_line(path, lineno, tokens, frame, layout):
    name = tokens[0]
    if name not in layout:
        raise parse_error(
            path,
            lineno,
            f"unknown bone {name!r} (not a bone with channels in the skeleton)",
        )
    if name in frame["seen"]:
        raise parse_error(path, lineno, f"bone {name!r} appears twice in one frame")
    start, count = layout[name]
    if len(tokens) - 1 != count:
        raise parse_error(
            path,
            lineno,
            f"bone {name!r} has {len(tokens) - 1} values, expected {count}",
        )
    frame["row"][start : start + count] = parse_floats(tokens[1:], path, lineno)
    frame["seen"].add(name)


def _is_frame_number(token):
    return len(token) < 19 and token.isascii() and token.lstrip("-").isdigit()


def _check_frame_number(path, lineno, number, previous):
    """Frames are numbered one by one: a gap, a repeat or a step back means
    frames are missing or out of order, and reading on would shift time."""
    if number != previous + 1:
        raise parse_error(
            path,
            lineno,
            f"frame {number} follows frame {previous}; AMC frames are numbered "
            f"one by one, so frame {previous + 1} was expected (frames missing, "
            "repeated or out of order?)",
        )


def _finish_frame(path, frame, layout):
    missing = [name for name in layout if name not in frame["seen"]]
    if missing:
        raise parse_error(
            path,
            frame["line"],
            f"the frame starting here lacks bones {missing} (truncated file?)",
        )
    return frame["row"]


def write_amc(path, data, skeleton, feature_names=None):
    """Write raw channels as an Acclaim AMC file that :func:`read_amc` reads back.

    Numbers are written with the shortest text that reads back as the same
    float, so a round trip is exact.

    Parameters
    ----------
    path : path-like
        The file to write.
    data : array-like of shape (n_frames, n_features)
        Raw channels, e.g. the ``inverse_transform`` of generated frames.
    skeleton : Skeleton
        The skeleton the channels belong to (usually from an ASF file).
    feature_names : array-like of str, default=None
        Name of each column of ``data``; default ``skeleton.feature_names``.

    Raises
    ------
    ValueError
        If a channel of the skeleton is missing or a value is not finite.

    Examples
    --------
    >>> import tempfile, os
    >>> import numpy as np
    >>> from sklearn_crbm.datasets import make_walker, read_amc, write_amc
    >>> walker = make_walker(n_sequences=1, n_frames=3, random_state=0)
    >>> path = os.path.join(tempfile.mkdtemp(), "walk.amc")
    >>> write_amc(path, walker.data, walker.skeleton)
    >>> data, names = read_amc(path, walker.skeleton)
    >>> np.array_equal(data, walker.data)
    True
    """
    skeleton = _check_skeleton(skeleton, "write_amc")
    check_bone_names(skeleton.bone_names, "AMC")
    X = _ordered_channels(data, skeleton, feature_names)
    unit = ":DEGREES" if skeleton.angle_unit == "deg" else ":RADIANS"
    lines = [
        f"# written by sklearn_crbm for skeleton {skeleton.name}",
        ":FULLY-SPECIFIED",
        unit,
    ]
    layout = _amc_layout(skeleton)
    for i, row in enumerate(X, start=1):
        lines.append(str(i))
        for name, (start, count) in layout.items():
            values = " ".join(format_number(v) for v in row[start : start + count])
            lines.append(f"{name} {values}")
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")


def _ordered_channels(data, skeleton, feature_names):
    """``data`` as floats with its columns in ``skeleton.feature_names`` order."""
    names = skeleton.feature_names if feature_names is None else feature_names
    wanted = list(skeleton.feature_names)
    X, columns = frame_columns(data, names, wanted)
    X = X[:, [columns[name] for name in wanted]]
    if X.shape[0] == 0:
        raise ValueError(
            f"data has no frames; an AMC file needs at least one (shape {X.shape})."
        )
    if not np.all(np.isfinite(X)):
        raise ValueError(
            "data contain NaN or infinite values; fill them before writing."
        )
    return X
