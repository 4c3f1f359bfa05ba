"""Which axis is up: detected from a skeleton's poses, or declared in a file.

A body stands along the vertical: seen from the pelvis (the first joint where
the skeleton branches), the legs hang below it and the spine rises above it,
while the two legs sit side by side.  So along the up axis the centroids of
the pelvis's branches (each leg, the upper body) lie far apart, along the
other axes close together, in a T-pose as in a walk.  Every frame votes for
the axis along which they spread most; a skeleton that does not branch
votes for the axis along which it is longest.

BVH files do not say which axis is up; :func:`write_bvh` declares it in a
comment after the first word of the file, ``HIERARCHY # sklearn_crbm
up_axis z``, which the package's reader understands and other readers skip.
It cannot stand on a line of its own: bvhio refuses any line between
``HIERARCHY`` and ``ROOT``, and Blender's importer reads every line after the
frames as a frame.  Blender 5.0's importer, pybvh 0.9, bvhio 1.5 and
bvhtoolbox 0.1.3 give the same joint positions with and without it.
"""

import re
import warnings

import numpy as np

__all__ = [
    "UP_AXIS_COMMENT",
    "check_up_axis",
    "declared_up_axis",
    "detect_up_axis",
    "settle_up_axis",
    "without_up_axis_comment",
]

# Frames a detection looks at, evenly spaced over the motion.
MAX_FRAMES = 200
# Spreads below this fraction of the largest coordinate are no evidence.
_DEGENERATE = 1e-9

UP_AXIS_COMMENT = "# sklearn_crbm up_axis {axis}"
_COMMENT = re.compile(r"#\s*sklearn_crbm\s+up_axis\s+([xyzXYZ])\s*$")


def declared_up_axis(lines):
    """The axis of an up-axis comment among ``(lineno, text)`` lines, or None."""
    for _, text in lines:
        match = _COMMENT.search(text)
        if match:
            return match.group(1).lower()
    return None


def without_up_axis_comment(lines):
    """``(lineno, text)`` lines with the up-axis comment cut out."""
    return [(n, _COMMENT.sub("", text)) for n, text in lines]


def detect_up_axis(skeleton, data=None, feature_names=None):
    """The axis the body stands along, or None when the poses cannot tell.

    See :meth:`Skeleton.detect_up_axis`.
    """
    if data is None:
        data = np.zeros((1, len(skeleton.feature_names)))
        feature_names = None
    data = np.asarray(data, dtype=np.float64)
    if data.ndim != 2 or data.shape[0] == 0:
        return None
    rows = np.unique(np.linspace(0, len(data) - 1, MAX_FRAMES).round().astype(int))
    positions = skeleton.forward_kinematics(data[rows], feature_names)
    positions = positions[np.all(np.isfinite(positions), axis=(1, 2))]
    if len(positions) == 0:
        return None
    hub = _branching_bone(skeleton)
    if hub is None:
        spread = positions.max(axis=1) - positions.min(axis=1)
    else:
        spread = _branch_spread(skeleton, positions, hub)
    scale = max(float(np.abs(positions).max()), 1.0)
    evidence = spread.max(axis=1) > _DEGENERATE * scale
    if not evidence.any():
        return None
    votes = np.bincount(np.argmax(spread[evidence], axis=1), minlength=3)
    return "xyz"[int(np.argmax(votes))]


def _branching_bone(skeleton):
    """The first bone down from the root with two or more children, or None."""
    name = skeleton.bones[0].name
    while len(children := skeleton.children(name)) == 1:
        name = children[0]
    return name if children else None


def _branch_spread(skeleton, positions, hub):
    """Per frame and axis, how far apart the centroids of ``hub``'s branches lie."""
    index = {name: i for i, name in enumerate(skeleton.bone_names)}
    branch = {child: k for k, child in enumerate(skeleton.children(hub))}
    members = []  # (bone index, branch) of every bone below the hub
    for bone in skeleton.bones[index[hub] + 1 :]:
        if bone.name not in branch and bone.parent in branch:
            branch[bone.name] = branch[bone.parent]
        if bone.name in branch:
            members.append((index[bone.name], branch[bone.name]))
    bones, groups = np.array(members).T
    n_branches = groups.max() + 1
    sums = np.zeros((len(positions), n_branches, 3))
    np.add.at(sums, (slice(None), groups), positions[:, bones])
    counts = np.bincount(groups, minlength=n_branches)[None, :, None]
    centroids = sums / counts - positions[:, index[hub]][:, None]
    return centroids.max(axis=1) - centroids.min(axis=1)


def settle_up_axis(skeleton, source, declared=None, data=None):
    """Set ``skeleton.up_axis``: the declared axis, else the detected one, else y.

    Detects from ``data``, else from the rest pose.  Warns when a declared
    axis is not the one the motion stands along (a rest pose is no evidence
    against a declaration: a file's root rotation may stand it on any axis).
    """
    if declared is None:
        skeleton.up_axis = detect_up_axis(skeleton, data) or "y"
        return skeleton
    if data is not None:
        detected = detect_up_axis(skeleton, data)
        check_up_axis(declared, detected, f"{source} declares", stacklevel=5)
    skeleton.up_axis = declared
    return skeleton


def check_up_axis(setting, detected, who, stacklevel=3):
    """Warn when an explicit up axis is not the one the body stands along."""
    if detected is None or setting == detected:
        return
    warnings.warn(
        f"{who} up axis {setting!r}, but the body stands along the {detected} axis "
        f"(its legs below and its spine above the pelvis). With the wrong up axis "
        f"heights and headings mean nothing and figures lie flat; use "
        f"up_axis={detected!r} unless you are sure.",
        UserWarning,
        stacklevel=stacklevel,
    )
