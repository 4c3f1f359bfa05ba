"""What the files of one folder must share, and the one difference reconciled.

A folder becomes one data set, so its files must have the same skeleton
(joints, parents, channels), the same up axis and, unless a common rate is
asked for, the same frame rate: an odd file gets an error that names it.

Which joint carries the body's travel may differ too, and is reconciled.  In
the Bandai Namco files the pelvis ``Hips`` travels below a still ground joint
``joint_Root``, but in ``dataset-1_dash_normal_001.bvh`` ``joint_Root``
travels and ``Hips`` stays: read beside the others, the preprocessing took
``joint_Root`` as the root of every file.  Such a file is rewritten so that
the folder's travelling joint carries the travel, the joints above it still,
with every joint below in the same place; a warning names the file.
"""

import warnings
from collections import Counter

import numpy as np

from ..utils._rotations import matrix_to_euler
from ._channels import TRANSLATION_CHANNELS
from ._frame_rate import RATIO_TOLERANCE

__all__ = ["check_agreement", "travelling_joint"]


def check_agreement(sequences, frame_rate):
    """``sequences`` (``(path, skeleton, data, rate)``) of one folder, with the
    travel of odd files moved to the folder's travelling joint; a ValueError
    naming the odd file when the skeletons, up axes or (``frame_rate`` None)
    rates differ."""
    first_path, first = sequences[0][:2]
    for path, skeleton, _, _ in sequences[1:]:
        _check_same_skeleton(path, skeleton, first_path, first)
    _check_common(sequences, lambda s: s[1].up_axis, "stands along the up axis")
    if frame_rate is None:
        _check_rates(sequences)
    return _reconciled_travel(sequences)


def _check_same_skeleton(path, skeleton, first_path, first):
    if list(skeleton.feature_names) != list(first.feature_names):
        differ = sorted(set(skeleton.feature_names) ^ set(first.feature_names))
        raise ValueError(
            f"{path} and {first_path} have different channels "
            f"({differ[:6] or 'the same ones in another order'}); read "
            "files of different skeletons separately."
        )
    parents = {bone.name: bone.parent for bone in first.bones}
    for bone in skeleton.bones:
        if parents.get(bone.name, bone.parent) != bone.parent or len(parents) != len(
            skeleton.bones
        ):
            raise ValueError(
                f"{path} and {first_path} have the same channels but another "
                f"skeleton: bone {bone.name!r} hangs from {bone.parent!r} in one and "
                f"from {parents.get(bone.name)!r} in the other; read files of "
                "different skeletons separately."
            )


def _check_common(sequences, value, what):
    """A ValueError naming the first file whose ``value`` is not the most
    common one."""
    values = [value(s) for s in sequences]
    common, count = Counter(values).most_common(1)[0]
    for (path, *_), v in zip(sequences, values, strict=True):
        if v != common:
            raise ValueError(
                f"{path} {what} {v!r} but {count} of the {len(values)} files stand "
                f"along {common!r}; a folder becomes one data set, so its files must "
                "agree. Read that file separately, or export it as the others."
            )


def _check_rates(sequences):
    first_path, _, _, first = sequences[0]
    for path, _, _, rate in sequences[1:]:
        if abs(rate - first) > RATIO_TOLERANCE * first:
            raise ValueError(
                f"{path} has {rate:g} frames per second but {first_path} has "
                f"{first:g}; pass frame_rate= to bring every file to a common rate "
                "by dropping frames."
            )


def travelling_joint(skeleton, data):
    """The first joint whose three translation channels change, or None."""
    columns = {name: i for i, name in enumerate(skeleton.feature_names)}
    for bone in skeleton.bones:
        if all(c in bone.channels for c in TRANSLATION_CHANNELS):
            T = data[:, [columns[f"{bone.name}_{c}"] for c in TRANSLATION_CHANNELS]]
            if len(T) and np.ptp(T, axis=0).max() > 0:
                return bone.name
    return None


def _reconciled_travel(sequences):
    joints = [travelling_joint(skeleton, data) for _, skeleton, data, _ in sequences]
    counts = Counter(joint for joint in joints if joint is not None)
    if len(counts) < 2:
        return sequences
    common, count = counts.most_common(1)[0]
    reference = sequences[joints.index(common)]
    out = []
    for sequence, joint in zip(sequences, joints, strict=True):
        if joint in (None, common):
            out.append(sequence)
            continue
        path, skeleton, data, rate = sequence
        why = (
            f"{path}: the body travels with joint {joint!r}, but in {count} of the "
            f"{len(sequences)} files with {common!r}"
        )
        data = _moved_travel(skeleton, data, joint, common, reference, why)
        warnings.warn(
            f"{why}. Its {joint!r} was set still, as in {reference[0]}, and the "
            f"travel moved into {common!r}; every joint below {joint!r} keeps its "
            "positions.",
            UserWarning,
            stacklevel=5,
        )
        out.append((path, skeleton, data, rate))
    return out


def _moved_travel(skeleton, data, joint, target, reference, why):
    """``data`` with the joints from ``joint`` down to ``target``'s parent as
    still as in ``reference``, and ``target`` carrying the global travel."""
    refuse = ValueError(
        f"{why}, and its travel cannot be moved into {target!r}; read it "
        "separately, or export it as the others."
    )
    above = _joints_between(skeleton, joint, target)
    bone = skeleton.bone(target)
    if (
        above is None
        or skeleton.convention != "bvh"
        or len(bone.channels) != 6
        or bone.rotation_type != "euler"
    ):
        raise refuse
    columns = {name: i for i, name in enumerate(skeleton.feature_names)}
    still = [columns[n] for n in columns if n.rsplit("_", 1)[0] in above]
    reference_data = reference[2]
    if np.ptp(reference_data[:, still], axis=0).max(initial=0) > 0:
        raise refuse
    positions, rotations = skeleton._global_transforms(data, None)
    moved = data.copy()
    moved[:, still] = reference_data[0, still]
    parent_positions, parent_rotations = skeleton._global_transforms(moved, None)
    i, parent = skeleton._index[target], skeleton._index[bone.parent]
    inverse = parent_rotations[:, parent].swapaxes(-1, -2)
    offset = np.einsum(
        "nij,nj->ni", inverse, positions[:, i] - parent_positions[:, parent]
    )
    angles = matrix_to_euler(inverse @ rotations[:, i], bone.rotation_order)
    if skeleton.angle_unit == "deg":
        angles = np.rad2deg(angles)
    for k, c in enumerate(TRANSLATION_CHANNELS):
        moved[:, columns[f"{target}_{c}"]] = offset[:, k]
    for k, axis in enumerate(bone.rotation_order):
        moved[:, columns[f"{target}_r{axis}"]] = angles[:, k]
    kept = [skeleton._index[name] for name in skeleton.descendants(target)]
    after = skeleton.forward_kinematics(moved)[:, kept]
    scale = max(1.0, float(np.abs(positions[:, kept]).max(initial=0)))
    if not np.allclose(after, positions[:, kept], rtol=0, atol=1e-9 * scale):
        raise refuse
    return moved


def _joints_between(skeleton, joint, target):
    """The joints from ``joint`` down to ``target``'s parent, each with no
    other child that has channels; None if ``joint`` is not above ``target``."""
    chain, below = [], target
    name = skeleton.bone(target).parent
    while name is not None:
        chain.append(name)
        if any(
            child != below and skeleton.bone(child).channels
            for child in skeleton.children(name)
        ):
            return None
        if name == joint:
            return chain
        below, name = name, skeleton.bone(name).parent
    return None
