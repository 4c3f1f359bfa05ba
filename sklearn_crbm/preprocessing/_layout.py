"""Which columns of a motion array belong to which bone.

Raw motion-capture channels are named ``"{bone}_{channel}"`` (``root_tx``,
``lfemur_rx``).  The helpers here find the Euler-angle blocks of each bone,
either from a skeleton or from the names alone, and work out the column
layout after each bone's Euler block is replaced by its exponential map.
"""

import re
from dataclasses import dataclass

import numpy as np
from sklearn.utils import check_array

_EULER_CHANNEL = re.compile(r"^(?P<bone>.+)_r(?P<axis>[xyz])$")
_EULER_CHANNELS = {"rx": "x", "ry": "y", "rz": "z"}
EXPMAP_SUFFIXES = ("ex", "ey", "ez")


@dataclass(frozen=True)
class EulerBlock:
    """The Euler channels of one bone.

    Attributes
    ----------
    bone : str
        Bone name.
    columns : tuple of int
        Input columns of the angles, in the order the rotations are applied.
    axes : str
        Axis of each of ``columns``, first applied first.
    """

    bone: str
    columns: tuple
    axes: str

    @property
    def first_column(self):
        return min(self.columns)


def check_skeleton(skeleton):
    """The skeleton, or a TypeError when it is not one (a path, a list...)."""
    if not hasattr(skeleton, "bones"):
        raise TypeError(
            "skeleton must be a sklearn_crbm.datasets.Skeleton (e.g. "
            "Skeleton.from_asf(path) or load_cmu35().skeleton) or None, got "
            f"{type(skeleton).__name__} {skeleton!r}."
        )
    return skeleton


def _skeleton_rotation_orders(skeleton):
    """Map feature name -> (bone, channel) and bone -> Euler axes, from a skeleton."""
    check_skeleton(skeleton)
    channel_of = {}
    orders = {}
    for bone in skeleton.bones:
        euler_axes = "".join(
            _EULER_CHANNELS[ch.lower()]
            for ch in bone.channels
            if ch.lower() in _EULER_CHANNELS
        )
        order = getattr(bone, "rotation_order", None)
        if order:
            order = "".join(a for a in str(order).lower() if a in euler_axes)
        if not order or sorted(order) != sorted(euler_axes):
            order = euler_axes
        orders[bone.name] = order
        for ch in bone.channels:
            channel_of[f"{bone.name}_{ch}"] = (bone.name, ch.lower())
    return channel_of, orders


def skeleton_feature_names(skeleton):
    """The raw feature names of a skeleton, ``"{bone}_{channel}"`` in order."""
    check_skeleton(skeleton)
    names = getattr(skeleton, "feature_names", None)
    if names is None:
        names = [f"{b.name}_{ch}" for b in skeleton.bones for ch in b.channels]
    return np.asarray(list(names), dtype=object)


def find_euler_blocks(feature_names, skeleton=None):
    """Group the Euler-angle columns of ``feature_names`` by bone.

    Parameters
    ----------
    feature_names : sequence of str
        Names of the input columns.
    skeleton : Skeleton or None
        With a skeleton every name must be one of the skeleton's channels
        and each bone's angles are composed in the bone's rotation order.
        Without one, names ending in ``_rx``, ``_ry``, ``_rz`` are Euler
        channels, composed in the order the columns appear.

    Returns
    -------
    blocks : list of EulerBlock
        In the order of each bone's first column.

    Raises
    ------
    ValueError
        On names the skeleton does not know, on a bone whose rotation
        channels are only partly present, and on repeated channels.
    """
    names = [str(n) for n in feature_names]
    seen = {}
    for j, name in enumerate(names):
        if name in seen:
            raise ValueError(f"Feature name {name!r} occurs more than once.")
        seen[name] = j
    columns = {}  # bone -> {axis: column}
    if skeleton is not None:
        channel_of, orders = _skeleton_rotation_orders(skeleton)
        unknown = [n for n in names if n not in channel_of]
        if unknown:
            shown = ", ".join(repr(n) for n in unknown[:5])
            more = f" and {len(unknown) - 5} more" if len(unknown) > 5 else ""
            raise ValueError(
                f"Unknown channels {shown}{more}: they are not '{{bone}}_{{channel}}' "
                "names of the skeleton's bones (see skeleton.feature_names)."
            )
        for j, name in enumerate(names):
            bone, ch = channel_of[name]
            if ch in _EULER_CHANNELS:
                columns.setdefault(bone, {})[_EULER_CHANNELS[ch]] = j
    else:
        orders = {}
        for j, name in enumerate(names):
            match = _EULER_CHANNEL.match(name)
            if match is None:
                continue
            bone, axis = match.group("bone"), match.group("axis")
            axes = columns.setdefault(bone, {})
            axes[axis] = j
            orders[bone] = orders.get(bone, "") + axis
    blocks = []
    for bone, by_axis in columns.items():
        order = orders[bone]
        missing = [a for a in order if a not in by_axis]
        if missing:
            raise ValueError(
                f"Bone {bone!r} has rotation channels "
                f"{['r' + a for a in order]} but X lacks "
                f"{[f'{bone}_r{a}' for a in missing]}; pass all of a bone's "
                "Euler channels or none."
            )
        blocks.append(
            EulerBlock(bone=bone, columns=tuple(by_axis[a] for a in order), axes=order)
        )
    blocks.sort(key=lambda b: b.first_column)
    return blocks


def moving_root(feature_names, X, skeleton=None):
    """The bone that carries the body's position: the encoders' root.

    The first bone, in column order, with all three translation channels
    ``"{bone}_tx"``, ``"{bone}_ty"``, ``"{bone}_tz"`` whose translations
    move in ``X``.  Usually the skeleton's root; but some rigs put a static
    bone above the moving pelvis (the Bandai Namco files: ``joint_Root``,
    always at the origin, above ``Hips``), and then the pelvis is the root.
    When no translation moves (a one-frame file), the first bone with
    translation channels; without any, the skeleton's first bone (or None).
    """
    names = [str(n) for n in feature_names]
    column = {n: j for j, n in enumerate(names)}
    candidates = []
    for name in names:
        bone = name[: -len("_tx")] if name.endswith("_tx") else None
        if bone is not None and all(f"{bone}_t{a}" in column for a in "yz"):
            candidates.append(bone)
    for bone in candidates:
        T = X[:, [column[f"{bone}_t{a}"] for a in "xyz"]]
        T = T[np.all(np.isfinite(T), axis=1)]
        if len(T) and np.ptp(T, axis=0).max() > 0:
            return bone
    if candidates:
        return candidates[0]
    return skeleton.bones[0].name if skeleton is not None else None


def expmap_layout(feature_names, blocks):
    """Output names and column map after replacing Euler blocks by exp maps.

    Returns
    -------
    names_out : ndarray of object
        Each block's three ``"{bone}_ex/ey/ez"`` names stand where its first
        Euler column stood; the other columns keep their names and order.
    passthrough : ndarray of shape (n_passthrough, 2)
        ``(output column, input column)`` of every column that is copied.
    block_starts : ndarray of shape (n_blocks,)
        Output column of each block's ``_ex``.
    """
    in_block = {}
    for i, block in enumerate(blocks):
        for c in block.columns:
            in_block[c] = i
    names_out = []
    passthrough = []
    block_starts = np.zeros(len(blocks), dtype=np.intp)
    for j, name in enumerate(feature_names):
        if j not in in_block:
            passthrough.append((len(names_out), j))
            names_out.append(str(name))
        elif blocks[in_block[j]].first_column == j:
            block = blocks[in_block[j]]
            block_starts[in_block[j]] = len(names_out)
            names_out.extend(f"{block.bone}_{s}" for s in EXPMAP_SUFFIXES)
    return (
        np.asarray(names_out, dtype=object),
        np.asarray(passthrough, dtype=np.intp).reshape(-1, 2),
        block_starts,
    )


def input_names(estimator, n_features, skeleton_names, described):
    """Names of the columns an encoder is fitted on, or None when unknown.

    ``feature_names_in_`` when ``X`` had names; else, with a skeleton,
    ``skeleton_names(skeleton)``, which a plain array must match column for
    column (``described``, formatted with their number, says what they are
    in the error).
    """
    if hasattr(estimator, "feature_names_in_"):
        return np.asarray(estimator.feature_names_in_, dtype=object)
    if estimator.skeleton is None:
        return None
    names = skeleton_names(estimator.skeleton)
    if len(names) != n_features:
        raise ValueError(
            f"X has {n_features} columns but {described.format(len(names))}; a "
            "plain array must hold exactly those columns, in order (or pass a "
            "DataFrame with those column names)."
        )
    return names


def expmap_feature_names(skeleton):
    """Column names of a skeleton's raw channels once encoded as exp maps."""
    names = skeleton_feature_names(skeleton)
    return expmap_layout(names, find_euler_blocks(names, skeleton))[0]


# Frames the encoders convert at a time: the temporaries of a chunk (the
# rotation matrices of its bones, a copy of its channels) take a few MB, not
# the gigabytes of a whole corpus's.
CHUNK_FRAMES = 4096


def frame_chunks(n_frames):
    """Slices of at most ``CHUNK_FRAMES`` consecutive frames covering ``n_frames``."""
    return [
        slice(start, min(start + CHUNK_FRAMES, n_frames))
        for start in range(0, n_frames, CHUNK_FRAMES)
    ]


def output_dtype(X):
    """The dtype an encoder returns for ``X``: float32 for float32 input, else
    float64 (encoders compute in float64 either way)."""
    return np.float32 if getattr(X, "dtype", None) == np.float32 else np.float64


def check_encoded(X, n_features, name):
    """Validate the input of an ``inverse_transform``: 2-D, numeric, right width."""
    X = check_array(X, dtype=np.float64, ensure_all_finite="allow-nan")
    if X.shape[1] != n_features:
        raise ValueError(
            f"X has {X.shape[1]} features, but {name}.inverse_transform expects "
            f"{n_features} features (the output of transform)."
        )
    return X
