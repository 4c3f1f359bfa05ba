"""Acclaim ASF (skeleton) and AMC (motion) files, as written by the CMU database."""

import os
from pathlib import Path

import numpy as np

from ._channels import EULER_CHANNELS, TRANSLATION_CHANNELS, as_frames, column_indices
from ._parsing import format_number, parse_error, parse_floats, read_lines
from ._skeleton import Bone, Skeleton

__all__ = ["read_amc", "read_asf", "write_amc"]

_ASF_DOFS = EULER_CHANNELS + TRANSLATION_CHANNELS


def _content_lines(path):
    """Numbered lines with comments (``#``) removed, blank lines skipped."""
    for lineno, line in read_lines(path):
        text = line.split("#", 1)[0].strip()
        if text:
            yield lineno, text


# --------------------------------------------------------------------- ASF
def read_asf(path):
    """Read an Acclaim ASF skeleton; see :meth:`Skeleton.from_asf`."""
    parser = _AsfParser(path)
    return parser.parse()


class _AsfParser:
    """State of one ASF file being read: its sections, bones and hierarchy."""

    def __init__(self, path):
        self.path = path
        self.units = {"length": 1.0, "angle": "deg"}
        self.root = None
        self.bones = []  # dicts in file order
        self.parents = {}
        self.last_line = 0

    def error(self, lineno, message):
        return parse_error(self.path, lineno, message)

    def parse(self):
        section = None
        block = None
        for lineno, text in _content_lines(self.path):
            self.last_line = lineno
            tokens = text.split()
            if tokens[0].startswith(":"):
                self._check_closed(block)
                section = self._start_section(lineno, tokens)
                continue
            if section == "units":
                self._units_line(lineno, tokens)
            elif section == "root":
                self._root_line(lineno, tokens)
            elif section == "bonedata":
                block = self._bonedata_line(lineno, tokens, block)
            elif section == "hierarchy":
                self._hierarchy_line(lineno, tokens)
            elif section in ("documentation", "other"):
                continue
            else:
                raise self.error(
                    lineno, f"unexpected text {text!r} outside any section"
                )
        self._check_closed(block)
        return self._skeleton()

    def _check_closed(self, block):
        if block is not None:
            raise self.error(block["line"], "bone block has no 'end'")

    def _start_section(self, lineno, tokens):
        keyword = tokens[0][1:].lower()
        if keyword == "root":
            self.root = {
                "line": lineno,
                "order": None,
                "axis": None,
                "position": [0.0] * 3,
                "orientation": [0.0] * 3,
            }
        if keyword in ("units", "root", "bonedata", "hierarchy", "documentation"):
            return keyword
        return "other"

    def _units_line(self, lineno, tokens):
        if len(tokens) != 2:
            raise self.error(
                lineno, f"expected 'key value' in :units, got {' '.join(tokens)!r}"
            )
        key, value = tokens[0].lower(), tokens[1]
        if key == "angle":
            unit = value.lower()[:3]
            if unit not in ("deg", "rad"):
                raise self.error(lineno, f"unknown angle unit {value!r}")
            self.units["angle"] = unit
        else:
            self.units[key] = parse_floats([value], self.path, lineno, key)[0]

    def _root_line(self, lineno, tokens):
        key = tokens[0].lower()
        if key == "order":
            self.root["order"] = [self._dof_token(lineno, t) for t in tokens[1:]]
        elif key == "axis":
            self.root["axis"] = self._axis_letters(
                lineno, tokens[1] if len(tokens) > 1 else ""
            )
        elif key in ("position", "orientation"):
            self.root[key] = self._three_floats(lineno, tokens, key)
        else:
            raise self.error(lineno, f"unknown :root keyword {tokens[0]!r}")

    def _bonedata_line(self, lineno, tokens, block):
        key = tokens[0].lower()
        if key == "begin":
            if block is not None:
                raise self.error(lineno, "'begin' inside a bone block (missing 'end')")
            return {"line": lineno, "dof": [], "axis": [0.0] * 3, "axis_order": "xyz"}
        if block is None:
            raise self.error(lineno, f"{tokens[0]!r} outside a begin/end bone block")
        if key == "end":
            self._finish_bone(lineno, block)
            return None
        if key == "name":
            block["name"] = tokens[1] if len(tokens) > 1 else ""
        elif key == "direction":
            block["direction"] = self._three_floats(lineno, tokens, "direction")
        elif key == "length":
            if len(tokens) != 2:
                raise self.error(lineno, "expected one number after 'length'")
            block["length"] = parse_floats(tokens[1:], self.path, lineno, "length")[0]
        elif key == "axis":
            if len(tokens) != 5:
                raise self.error(lineno, "expected 'axis a b c ORDER'")
            block["axis"] = parse_floats(tokens[1:4], self.path, lineno, "axis angle")
            block["axis_order"] = self._axis_letters(lineno, tokens[4])
        elif key == "dof":
            block["dof"] = [self._dof_token(lineno, t) for t in tokens[1:]]
        elif key in ("id", "limits", "bodymass", "cofmass") or key.startswith("("):
            pass
        else:
            raise self.error(lineno, f"unknown bone keyword {tokens[0]!r}")
        return block

    def _finish_bone(self, lineno, block):
        for key in ("name", "direction", "length"):
            if key not in block or block[key] == "":
                raise self.error(block["line"], f"bone block has no '{key}'")
        if block["name"] == "root" or any(
            b["name"] == block["name"] for b in self.bones
        ):
            raise self.error(
                block["line"], f"bone name {block['name']!r} is used twice"
            )
        self.bones.append(block)

    def _hierarchy_line(self, lineno, tokens):
        if tokens[0].lower() in ("begin", "end"):
            return
        parent, children = tokens[0], tokens[1:]
        known = {"root"} | {b["name"] for b in self.bones}
        for name in [parent, *children]:
            if name not in known:
                raise self.error(lineno, f"unknown bone {name!r} in :hierarchy")
        for child in children:
            if child in self.parents:
                raise self.error(lineno, f"bone {child!r} is given a second parent")
            self.parents[child] = parent

    def _dof_token(self, lineno, token):
        dof = token.lower()
        if dof not in _ASF_DOFS:
            raise self.error(
                lineno,
                f"unsupported degree of freedom {token!r}; expected one of {_ASF_DOFS}",
            )
        return dof

    def _axis_letters(self, lineno, token):
        letters = token.lower()
        if sorted(letters) != ["x", "y", "z"]:
            raise self.error(lineno, f"bad axis order {token!r}, expected e.g. 'XYZ'")
        return letters

    def _three_floats(self, lineno, tokens, what):
        if len(tokens) != 4:
            raise self.error(lineno, f"expected three numbers after {what!r}")
        return parse_floats(tokens[1:], self.path, lineno, what)

    # --------------------------------------------------------- build result
    def _to_degrees(self, angles):
        angles = np.asarray(angles, dtype=np.float64)
        return np.rad2deg(angles) if self.units["angle"] == "rad" else angles

    def _root_bone(self):
        root = self.root
        channels = tuple(root["order"] or ())
        euler_axes = "".join(c[1] for c in channels if c in EULER_CHANNELS)
        order = root["axis"] or "xyz"
        rotation_order = "".join(a for a in order if a in euler_axes)
        return Bone.from_offset(
            "root",
            None,
            root["position"],
            channels=channels,
            rotation_order=rotation_order,
            axis=self._to_degrees(root["orientation"]),
            axis_order=order,
        )

    def _bone(self, block):
        name = block["name"]
        if name not in self.parents:
            raise self.error(
                block["line"], f"bone {name!r} has no parent in :hierarchy"
            )
        return Bone(
            name=name,
            parent=self.parents[name],
            direction=block["direction"],
            length=block["length"],
            channels=tuple(block["dof"]),
            rotation_order="".join(c[1] for c in block["dof"] if c in EULER_CHANNELS),
            axis=self._to_degrees(block["axis"]),
            axis_order=block["axis_order"],
        )

    def _checked(self, lineno, make_bone, *args):
        """Build a bone, turning a ValueError into one that names file and line."""
        try:
            return make_bone(*args)
        except ValueError as exc:
            if str(exc).startswith(f"{self.path}, line"):
                raise
            raise self.error(lineno, str(exc)) from None

    def _skeleton(self):
        if self.root is None:
            raise self.error(
                self.last_line, "no ':root' section before the end of the file"
            )
        if self.bones and not self.parents:
            raise self.error(
                self.last_line, "no ':hierarchy' section before the end of the file"
            )
        bones = [self._checked(self.root["line"], self._root_bone)]
        bones += [self._checked(b["line"], self._bone, b) for b in self.bones]
        try:
            bones = _parents_first(bones)
        except ValueError as exc:
            raise self.error(self.last_line, str(exc)) from None
        return Skeleton(
            bones,
            name=Path(self.path).stem,
            up_axis="y",
            angle_unit=self.units["angle"],
            length_scale=self.units["length"],
            convention="acclaim",
        )


def _parents_first(bones):
    """Reorder bones so parents come first, keeping file order otherwise."""
    ordered, placed, pending = [], set(), list(bones)
    while pending:
        ready = [b for b in pending if b.parent is None or b.parent in placed]
        if not ready:
            raise ValueError(
                f"Bones {[b.name for b in pending]} are not connected to the root."
            )
        first = ready[0]
        ordered.append(first)
        placed.add(first.name)
        pending.remove(first)
    return ordered


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
    for lineno, text in _content_lines(path):
        tokens = text.split()
        if tokens[0].startswith(":"):
            if frames or frame is not None:
                raise parse_error(
                    path, lineno, f"header line {text!r} after the first frame"
                )
            _check_amc_unit(path, lineno, tokens[0], skeleton)
            continue
        if len(tokens) == 1 and tokens[0].lstrip("-").isdigit():
            if frame is not None:
                frames.append(_finish_frame(path, frame, layout))
            frame = {"line": lineno, "row": np.full(n_features, np.nan), "seen": set()}
            continue
        if frame is None:
            raise parse_error(path, lineno, f"expected a frame number, got {text!r}")
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
    X = as_frames(data)
    if X.ndim != 2:
        raise ValueError(
            f"data must be 2-D (n_frames, n_features), got shape {X.shape}."
        )
    names = skeleton.feature_names if feature_names is None else feature_names
    wanted = list(skeleton.feature_names)
    columns = column_indices(names, wanted, n_columns=X.shape[1])
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
