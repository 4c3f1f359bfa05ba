"""The skeleton of Graham Taylor's MIT walking data (``skel`` with ``type='mit'``).

The MIT data (Hsu, Pulli & Popovic 2005) has 18 nodes of 6 columns each:
three exponential-map values and three offset values, except the root whose
last three columns are its position.  z is up and the subject walks along +x,
so +y is the subject's left.  The nodes, numbered as in ``skel.tree``:

====  ===========  ==========================================
node  bone name    what it is
====  ===========  ==========================================
1     root         pelvis; its columns 4-6 are the position
2     lhip         left hip (offset +y from the root)
3     lknee        left knee (1 DOF, ``ey``)
4     lankle       left ankle
5     ltoe         left toe (1 DOF, ``ey``)
6     rhip         right hip (offset -y)
7     rknee        right knee
8     rankle       right ankle
9     rtoe         right toe
10    spine        lower back, parent of both arm chains
11    lcollar      base of the neck, start of the left arm chain
12    lshoulder    left shoulder (offset +y)
13    lelbow       left elbow
14    lwrist       left wrist
15    rcollar      base of the neck, start of the right arm chain
16    rshoulder    right shoulder (offset -y)
17    relbow       right elbow
18    rwrist       right wrist
====  ===========  ==========================================
"""

import os

import numpy as np

from ._bone import Bone
from ._channels import EXPMAP_CHANNELS, OFFSET_CHANNELS, TRANSLATION_CHANNELS
from ._parsing import load_mat_variables

__all__ = ["MIT_BONE_NAMES", "parse_mit_skeleton"]

MIT_BONE_NAMES = (
    "root", "lhip", "lknee", "lankle", "ltoe", "rhip", "rknee", "rankle", "rtoe",
    "spine", "lcollar", "lshoulder", "lelbow", "lwrist",
    "rcollar", "rshoulder", "relbow", "rwrist",
)  # fmt: skip


def _field(struct, name):
    """A field of a MATLAB struct from ``loadmat``, in either of its layouts."""
    if isinstance(struct, (np.ndarray, np.void)):
        value = struct[name]
        while (
            isinstance(value, np.ndarray) and value.dtype == object and value.size == 1
        ):
            value = value.flat[0]
        return value
    return getattr(struct, name)


def _indices(value):
    """1-based MATLAB indices as a list of 0-based ints."""
    return [int(i) - 1 for i in np.asarray(value).ravel()]


def load_mit_mat(path):
    """``(skel, motions)`` from one of Taylor's MIT ``.mat`` files."""
    mat = load_mat_variables(path, ("skel", "Motion"), "fetch_mit_walk")
    return mat["skel"], [np.asarray(m, dtype=np.float64) for m in mat["Motion"].flat]


def parse_mit_skeleton(skel, offsets=None):
    """The keyword arguments of :class:`Skeleton` from Taylor's MIT ``skel``;
    see :meth:`Skeleton.from_mit`."""
    if isinstance(skel, (str, os.PathLike)):
        skel, motions = load_mit_mat(skel)
        if offsets is None:
            offsets = motions[0][0]
    try:
        kind = str(np.asarray(_field(skel, "type")).ravel()[0])
    except (AttributeError, IndexError, KeyError, TypeError, ValueError):
        raise TypeError(
            "skel must be the 'skel' struct of Taylor's MIT data as loaded by "
            "scipy.io.loadmat, or the path of its .mat file; got "
            f"{type(skel).__name__}."
        ) from None
    if kind != "mit":
        raise ValueError(f"Expected a skel of type 'mit', got type {kind!r}.")
    nodes = list(np.asarray(_field(skel, "tree")).flat)
    if len(nodes) != len(MIT_BONE_NAMES):
        raise ValueError(f"Expected an MIT skel with 18 nodes, got {len(nodes)}.")
    if offsets is not None:
        offsets = np.asarray(offsets, dtype=np.float64).ravel()
        if offsets.shape != (6 * len(nodes),) or not np.all(np.isfinite(offsets)):
            raise ValueError(
                f"offsets must be one frame of MIT data: {6 * len(nodes)} finite "
                f"values, got shape {offsets.shape}."
            )
    bones, column = [], 0
    for k, node in enumerate(nodes):
        rotation, offset_cols = (
            _indices(_field(node, "or")),
            _indices(_field(node, "offset")),
        )
        parents = _indices(_field(node, "parent"))
        if rotation + offset_cols != list(range(column, column + 6)):
            raise ValueError(
                f"MIT node {k + 1} uses columns {rotation + offset_cols} (0-based); "
                "expected the next six columns in node order."
            )
        column += 6
        is_root = not parents
        offset = np.zeros(3)
        if offsets is not None and not is_root:
            offset = offsets[offset_cols]
        bones.append(
            Bone.from_offset(
                MIT_BONE_NAMES[k],
                None if is_root else MIT_BONE_NAMES[parents[0]],
                offset,
                channels=EXPMAP_CHANNELS
                + (TRANSLATION_CHANNELS if is_root else OFFSET_CHANNELS),
            )
        )
    return {
        "bones": bones,
        "name": "mit",
        "up_axis": "z",
        "angle_unit": "rad",
        "convention": "bvh",
    }
