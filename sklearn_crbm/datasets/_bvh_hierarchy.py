"""The HIERARCHY (skeleton) section of Biovision BVH files.

The parser gives the keyword arguments of :class:`Skeleton` (its bones and
settings), so that it needs the bones alone and not the skeleton class.
"""

import os
from pathlib import Path

import numpy as np

from ._bone import Bone
from ._channels import END_SITE_SUFFIX, EULER_CHANNELS
from ._parsing import parse_error, parse_floats, read_lines
from ._up_axis import without_up_axis_comment

__all__ = ["CHANNEL_TO_BVH", "parse_bvh_hierarchy", "split_header"]

_BVH_TO_CHANNEL = {
    f"{axis}{kind}": f"{short}{axis.lower()}"
    for axis in "XYZ"
    for kind, short in (("position", "t"), ("rotation", "r"))
}
CHANNEL_TO_BVH = {v: k for k, v in _BVH_TO_CHANNEL.items()}
OTHER_FORMAT_HINTS = {
    ".amc": "; this is an Acclaim AMC file: read it with read_amc(path, skeleton), "
    "the skeleton from Skeleton.from_asf(its ASF file)",
    ".asf": "; this is an Acclaim ASF skeleton file: read the motion of its AMC "
    "files with read_amc(amc_path, Skeleton.from_asf(this file))",
}


class _Tokens:
    """The words of a BVH header with their line numbers, read one at a time."""

    def __init__(self, path, lines):
        self.path = path
        self.items = [(n, w) for n, line in lines for w in line.split()]
        self.pos = 0
        self.last_line = lines[-1][0] if lines else 1

    def error(self, message, lineno=None):
        if lineno is None:
            lineno = (
                self.items[self.pos][0]
                if self.pos < len(self.items)
                else self.last_line
            )
        return parse_error(self.path, lineno, message)

    def next(self, what):
        if self.pos >= len(self.items):
            raise self.error(f"file ends where {what} was expected")
        item = self.items[self.pos]
        self.pos += 1
        return item

    def expect(self, word):
        lineno, token = self.next(repr(word))
        if token.lower() != word.lower():
            raise self.error(f"expected {word!r}, got {token!r}", lineno)
        return lineno

    def floats(self, count, what):
        items = [self.next(what) for _ in range(count)]
        return parse_floats([t for _, t in items], self.path, items[0][0], what)


def _parse_hierarchy(tokens):
    """Bones of the HIERARCHY, in file order, with end sites as channel-less bones."""
    lineno, first = tokens.next("'HIERARCHY'")
    if first.upper() != "HIERARCHY":
        raise tokens.error(
            f"expected 'HIERARCHY' at the start of the file, got {first!r}", lineno
        )
    tokens.expect("ROOT")
    bones = []
    try:
        _parse_joint(tokens, None, bones, set())
    except RecursionError:
        raise tokens.error(
            "joints are nested too deeply (or a '}' is missing)", lineno
        ) from None
    if tokens.pos < len(tokens.items):
        lineno, token = tokens.items[tokens.pos]
        raise tokens.error(
            f"unexpected {token!r} after the ROOT joint (only one ROOT is supported)",
            lineno,
        )
    return bones


def _parse_joint(tokens, parent, bones, names):
    lineno, name = tokens.next("a joint name")
    if name in names or name + END_SITE_SUFFIX in names:
        raise tokens.error(f"joint name {name!r} is used twice", lineno)
    names.add(name)
    tokens.expect("{")
    offset, channels, index = None, None, len(bones)
    bones.append(None)  # placeholder: children come after their parent
    while True:
        lineno, word = tokens.next("'}'")
        key = word.upper()
        if key in ("OFFSET", "CHANNELS"):
            if (offset if key == "OFFSET" else channels) is not None:
                raise tokens.error(
                    f"a second {key} line in joint {name!r}; a joint has one", lineno
                )
        if key == "OFFSET":
            offset = np.array(tokens.floats(3, "OFFSET value"))
        elif key == "CHANNELS":
            channels = _parse_channels(tokens)
        elif key == "JOINT":
            _parse_joint(tokens, name, bones, names)
        elif key == "END":
            tokens.expect("Site")
            tokens.expect("{")
            tokens.expect("OFFSET")
            end = np.array(tokens.floats(3, "OFFSET value"))
            tokens.expect("}")
            names.add(name + END_SITE_SUFFIX)
            bones.append(
                _checked_bone(tokens, lineno, name + END_SITE_SUFFIX, name, end, ())
            )
        elif key == "}":
            break
        else:
            raise tokens.error(f"unexpected {word!r} in joint {name!r}", lineno)
    if offset is None:
        raise tokens.error(f"joint {name!r} has no OFFSET", lineno)
    bones[index] = _checked_bone(tokens, lineno, name, parent, offset, channels or ())


def _checked_bone(tokens, lineno, *args):
    """:func:`_bvh_bone`, its ValueError (a repeated channel, a huge offset)
    turned into one that names the file and line."""
    try:
        return _bvh_bone(*args)
    except ValueError as exc:
        raise tokens.error(str(exc), lineno) from None


def _parse_channels(tokens):
    lineno, count = tokens.next("the number of channels")
    if not (count.isascii() and count.isdigit()):
        raise tokens.error(f"bad number of channels {count!r}", lineno)
    channels = []
    for _ in range(int(count)):
        lineno, word = tokens.next("a channel name")
        if word not in _BVH_TO_CHANNEL:
            raise tokens.error(
                f"unknown channel {word!r}; expected one of {list(_BVH_TO_CHANNEL)}",
                lineno,
            )
        channels.append(_BVH_TO_CHANNEL[word])
    return tuple(channels)


def _bvh_bone(name, parent, offset, channels):
    rotation_axes = [c[1] for c in channels if c in EULER_CHANNELS]
    return Bone.from_offset(
        name,
        parent,
        offset,
        channels=channels,
        rotation_order="".join(reversed(rotation_axes)),
    )


def split_header(path):
    """``(header lines, motion lines)``, split at the line that starts with MOTION."""
    lines = read_lines(path)
    for i, (_, text) in enumerate(lines):
        if text.strip().upper().startswith("MOTION"):
            return lines[:i], lines[i:]
    lineno = lines[-1][0] if lines else 1
    hint = OTHER_FORMAT_HINTS.get(Path(os.fspath(path)).suffix.lower(), "")
    raise parse_error(
        path, lineno, f"no 'MOTION' section before the end of the file{hint}"
    )


def parse_bvh_hierarchy(path, header=None):
    """The keyword arguments of :class:`Skeleton` read from the HIERARCHY of a
    BVH file (its ``header`` lines if already split off); see
    :meth:`Skeleton.from_bvh`."""
    if header is None:
        header, _ = split_header(path)
    header = without_up_axis_comment(header)
    return {
        "bones": _parse_hierarchy(_Tokens(path, header)),
        "name": Path(path).stem,
        "up_axis": "y",
        "angle_unit": "deg",
        "convention": "bvh",
    }
