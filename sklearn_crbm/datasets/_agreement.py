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

The outcome does not depend on the order of the files (their names): ties
between as many files one way as the other are broken by what the files
hold, never by which comes first.
"""

import warnings
from collections import Counter
from pathlib import Path

import numpy as np

from ..utils._rotations import matrix_to_euler
from ._channels import TRANSLATION_CHANNELS
from ._frame_rate import RATIO_TOLERANCE, frame_step

__all__ = ["check_agreement", "travelling_joint"]


def check_agreement(sequences, frame_rate):
    """``sequences`` (``(path, skeleton, data, rate)``) of one folder, with the
    travel of odd files moved to the folder's travelling joint; a ValueError
    naming the odd file when the skeletons, up axes or (``frame_rate`` None)
    rates differ, a warning naming the files that ``frame_rate`` resamples
    when their rates differ."""
    first_path, first = sequences[0][:2]
    for path, skeleton, _, _ in sequences[1:]:
        _check_same_skeleton(path, skeleton, first_path, first)
    _check_common(sequences, lambda s: s[1].up_axis, "stands along the up axis")
    if frame_rate is None:
        _check_rates(sequences)
    else:
        _check_target_rate(sequences, frame_rate)
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


def _files(paths, limit=3):
    """The names of ``paths`` for a message: ``"a.bvh, b.bvh and 4 more"``."""
    names = [Path(path).name for path in paths]
    if len(names) > limit:
        return f"{', '.join(names[:limit])} and {len(names) - limit} more"
    return ", ".join(names[:-2] + [" and ".join(names[-2:])])


def _check_common(sequences, value, what):
    """A ValueError naming a file whose ``value`` is not the most common one
    (of values as common, the smallest)."""
    values = [value(s) for s in sequences]
    counts = Counter(values)
    common = min(counts, key=lambda v: (-counts[v], v))
    for (path, *_), v in zip(sequences, values, strict=True):
        if v != common:
            agree = _files(
                p for (p, *_), w in zip(sequences, values, strict=True) if w == common
            )
            raise ValueError(
                f"{path} {what} {v!r} but {counts[common]} of the {len(values)} "
                f"files stand along {common!r} ({agree}); a folder becomes one data "
                "set, so its files must agree. Read that file separately, or export "
                "it as the others."
            )


def _rate_groups(sequences):
    """``{rate: [path, ...]}``: the files by frame rate, rates within
    :data:`RATIO_TOLERANCE` of each other as one, slowest first."""
    groups = {}
    for path, _, _, rate in sorted(sequences, key=lambda s: s[3]):
        close = [r for r in groups if abs(rate - r) <= RATIO_TOLERANCE * r]
        groups.setdefault(close[0] if close else rate, []).append(path)
    return groups


def _check_rates(sequences):
    """A ValueError naming the files whose rate is not that of most files
    (of rates as common, the slowest), and what a common rate does to them."""
    groups = _rate_groups(sequences)
    if len(groups) == 1:
        return
    common = max(groups, key=lambda rate: (len(groups[rate]), -rate))
    odd = "; ".join(
        f"{_files(paths)} {'has' if len(paths) == 1 else 'have'} {rate:g} frames "
        "per second"
        for rate, paths in groups.items()
        if rate != common
    )
    others = len(groups[common])
    target = min(groups)
    raise ValueError(
        f"The files do not share one frame rate: {odd}, but "
        f"{'the other file' if others == 1 else f'the other {others} files'} "
        f"({_files(groups[common])}) {'has' if others == 1 else 'have'} "
        f"{common:g}. A folder becomes one data set at one rate: "
        f"frame_rate={target:g} brings every file to {target:g} frames per second "
        f"by dropping frames: {_resampling(groups, target)}."
    )


def _check_target_rate(sequences, frame_rate):
    """A ValueError naming the slowest file if ``frame_rate`` is faster; a
    warning naming the files it resamples when the files' rates differ."""
    groups = _rate_groups(sequences)
    slowest = min(groups)
    if frame_rate > slowest * (1 + RATIO_TOLERANCE):
        raise ValueError(
            f"Cannot bring {slowest:g} frames per second up to {frame_rate:g} by "
            f"dropping frames: {_files(groups[slowest])} "
            f"{'has' if len(groups[slowest]) == 1 else 'have'} {slowest:g}. "
            f"Choose a rate of at most {slowest:g}, the slowest file's."
        )
    if len(groups) > 1:
        warnings.warn(
            f"The files do not share one frame rate; brought to {frame_rate:g} "
            f"frames per second by dropping frames: {_resampling(groups, frame_rate)}.",
            UserWarning,
            stacklevel=5,
        )


def _resampling(groups, target):
    """What bringing each group of files to ``target`` does to it, in words."""
    kept, whole = [], []
    for rate, paths in groups.items():
        step = frame_step(rate, target)
        if step == 1:
            whole.extend(paths)
            continue
        part = (
            f"every {_ordinal(int(step))} frame"
            if step.is_integer()
            else f"{1 / step:.0%} of the frames"
        )
        kept.append(f"{part} of {_files(paths)} ({rate:g} per second)")
    if whole:
        kept.append(f"{_files(whole)} whole")
    return "it keeps " + ", ".join(kept[:-2] + [" and ".join(kept[-2:])])


def _ordinal(n):
    """``"2nd"``, ``"3rd"``, ``"4th"``, ``"21st"``..."""
    if n % 100 in (11, 12, 13):
        return f"{n}th"
    return f"{n}{ {1: 'st', 2: 'nd', 3: 'rd'}.get(n % 10, 'th') }"


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
    skeleton = sequences[0][1]
    # the joint most files travel with; of joints as common, the lowest in the
    # skeleton, since travel can only move down into a joint: so the outcome
    # does not depend on which file comes first
    common = max(counts, key=lambda j: (counts[j], *_depth_and_index(skeleton, j)))
    references = [s for s, j in zip(sequences, joints, strict=True) if j == common]
    out = []
    for sequence, joint in zip(sequences, joints, strict=True):
        if joint in (None, common):
            out.append(sequence)
            continue
        path, skeleton, data, rate = sequence
        why = (
            f"{path}: the body travels with joint {joint!r}, but with {common!r} "
            f"in {len(references)} of the {len(sequences)} files "
            f"({_files(p for p, *_ in references)})"
        )
        data, reference = _moved_travel(skeleton, data, joint, common, references, why)
        warnings.warn(
            f"{why}. Its {joint!r} was set still, as in {reference.name}, and the "
            f"travel moved into {common!r}; every joint below {joint!r} keeps its "
            "positions.",
            UserWarning,
            stacklevel=5,
        )
        out.append((path, skeleton, data, rate))
    return out


def _depth_and_index(skeleton, name):
    depth, parent = 0, skeleton.bone(name).parent
    while parent is not None:
        depth, parent = depth + 1, skeleton.bone(parent).parent
    return depth, skeleton._index[name]


def _moved_travel(skeleton, data, joint, target, references, why):
    """``(data, reference path)``: ``data`` with the joints from ``joint``
    down to ``target``'s parent as still as in the ``references`` (the
    values most of them hold, of values as common the smallest), and
    ``target`` carrying the global travel."""
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
    held = [
        (tuple(d[0, still]), str(p))
        for p, _, d, _ in references
        if len(d) and np.ptp(d[:, still], axis=0).max(initial=0) == 0
    ]
    if not held:
        raise refuse
    counts = Counter(values for values, _ in held)
    values, reference = min(held, key=lambda vp: (-counts[vp[0]], vp))
    positions, rotations = skeleton._global_transforms(data, None)
    moved = data.copy()
    moved[:, still] = values
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
    return moved, Path(reference)


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
