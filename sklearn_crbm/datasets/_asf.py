"""Acclaim ASF skeleton files, as written by the CMU database.

The parser gives the keyword arguments of :class:`Skeleton` (its bones and
settings), so that it needs the bones alone and not the skeleton class.
"""

import heapq
from collections import defaultdict
from pathlib import Path

import numpy as np

from ._bone import Bone
from ._channels import EULER_CHANNELS, TRANSLATION_CHANNELS
from ._parsing import bvh_hint, format_number, parse_error, parse_floats, read_lines

__all__ = ["parse_asf"]

_ASF_DOFS = EULER_CHANNELS + TRANSLATION_CHANNELS
_ONCE_PER_BONE = ("name", "direction", "length", "axis", "dof")


def content_lines(path):
    """Numbered lines with comments (``#``) removed, blank lines skipped."""
    for lineno, line in read_lines(path):
        text = line.split("#", 1)[0].strip()
        if text:
            yield lineno, text


def parse_asf(path):
    """The keyword arguments of :class:`Skeleton` read from an Acclaim ASF file;
    see :meth:`Skeleton.from_asf`."""
    return _AsfParser(path).parse()


class _AsfParser:
    """State of one ASF file being read: its sections, bones and hierarchy."""

    def __init__(self, path):
        self.path = path
        self.units = {"length": 1.0, "angle": "deg"}
        self.root = None
        self.bones = []  # dicts in file order
        self.names = {"root"}
        self.parents = {}
        self.last_line = 0

    def error(self, lineno, message):
        return parse_error(self.path, lineno, message)

    def parse(self):
        section = None
        block = None
        for lineno, text in content_lines(self.path):
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
                    lineno,
                    f"unexpected text {text!r} outside any section"
                    + bvh_hint(tokens[0]),
                )
        self._check_closed(block)
        return self._arguments()

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
            return {"line": lineno}
        if block is None:
            raise self.error(lineno, f"{tokens[0]!r} outside a begin/end bone block")
        if key == "end":
            self._finish_bone(lineno, block)
            return None
        if key in _ONCE_PER_BONE and key in block:
            raise self.error(
                lineno,
                f"a second {key!r} line in the bone block starting on line "
                f"{block['line']}; a bone has one",
            )
        if key == "name":
            block["name"] = tokens[1] if len(tokens) > 1 else ""
        elif key == "direction":
            block["direction"] = self._three_floats(lineno, tokens, "direction")
            block["direction_line"] = lineno
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
        if block["name"] in self.names:
            raise self.error(
                block["line"], f"bone name {block['name']!r} is used twice"
            )
        if not any(block["direction"]) and block["length"] != 0:
            raise self.error(
                block["direction_line"],
                f"bone {block['name']!r} has direction 0 0 0 but length "
                f"{format_number(block['length'])}; give the direction it points in",
            )
        self.names.add(block["name"])
        self.bones.append(block)

    def _hierarchy_line(self, lineno, tokens):
        if tokens[0].lower() in ("begin", "end"):
            return
        parent, children = tokens[0], tokens[1:]
        for name in [parent, *children]:
            if name not in self.names:
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
        dof = block.get("dof", [])
        if name not in self.parents:
            raise self.error(
                block["line"], f"bone {name!r} has no parent in :hierarchy"
            )
        return Bone(
            name=name,
            parent=self.parents[name],
            direction=block["direction"],
            length=block["length"],
            channels=tuple(dof),
            rotation_order="".join(c[1] for c in dof if c in EULER_CHANNELS),
            axis=self._to_degrees(block.get("axis", [0.0] * 3)),
            axis_order=block.get("axis_order", "xyz"),
        )

    def _checked(self, lineno, make_bone, *args):
        """Build a bone, turning a ValueError into one that names file and line."""
        try:
            return make_bone(*args)
        except ValueError as exc:
            if str(exc).startswith(f"{self.path}, line"):
                raise
            raise self.error(lineno, str(exc)) from None

    def _arguments(self):
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
        return {
            "bones": bones,
            "name": Path(self.path).stem,
            "up_axis": "y",
            "angle_unit": self.units["angle"],
            "length_scale": self.units["length"],
            "convention": "acclaim",
        }


def _parents_first(bones):
    """Reorder bones so parents come first, keeping file order otherwise.

    Always the earliest bone in file order whose parent is placed: a heap of
    the file positions of the bones that are ready, in time linear in the
    number of bones (up to the heap's logarithm).
    """
    waiting = defaultdict(list)
    ready = []
    for i, bone in enumerate(bones):
        if bone.parent is None:
            ready.append(i)
        else:
            waiting[bone.parent].append(i)
    heapq.heapify(ready)
    ordered = []
    while ready:
        bone = bones[heapq.heappop(ready)]
        ordered.append(bone)
        for i in waiting.pop(bone.name, ()):
            heapq.heappush(ready, i)
    if len(ordered) < len(bones):
        placed = {bone.name for bone in ordered}
        pending = [bone.name for bone in bones if bone.name not in placed]
        raise ValueError(f"Bones {pending} are not connected to the root.")
    return ordered
