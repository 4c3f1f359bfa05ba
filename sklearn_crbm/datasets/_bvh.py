"""Biovision BVH files: reading (HIERARCHY parsed by ``_bvh_hierarchy``) and writing."""

import numpy as np

from ..utils._rotations import matrix_to_euler
from ._bone import Bone
from ._bvh_hierarchy import CHANNEL_TO_BVH, parse_bvh_hierarchy, split_header
from ._channels import END_SITE_SUFFIX, EULER_CHANNELS, TRANSLATION_CHANNELS
from ._frame_rate import check_rate, rate_of_frame_time
from ._parsing import check_bone_names, format_number, parse_error, parse_floats
from ._skeleton import Skeleton
from ._up_axis import UP_AXIS_COMMENT, declared_up_axis, settle_up_axis

__all__ = ["read_bvh", "write_bvh"]


# ------------------------------------------------------------------ reading
def read_bvh(path):
    """Read a BVH motion file.

    Parameters
    ----------
    path : path-like
        The ``.bvh`` file.

    Returns
    -------
    skeleton : Skeleton
        From the HIERARCHY, ``convention="bvh"``; end sites are bones named
        ``"{parent}_end"`` without channels.  Its ``up_axis`` is the one the
        file declares (:func:`write_bvh` writes it in a comment on the first
        line), else
        the one the motion stands along (:meth:`Skeleton.detect_up_axis`):
        the axis to give Blender's importer as *Up*.  A file whose declared
        axis is not the one its motion stands along gets a warning.
    data : ndarray of shape (n_frames, n_features)
        The MOTION values, positions in file units and angles in degrees.
    feature_names : ndarray of str
        ``skeleton.feature_names``: ``"{joint}_{channel}"`` with channels
        ``tx``, ``ty``, ``tz`` (``Xposition`` ...) and ``rx``, ``ry``, ``rz``
        (``Xrotation`` ...), in file order.
    frame_rate : float
        ``1 / Frame Time``, taken as a whole number of frames per second
        when the ``Frame Time`` written is that number's, rounded to the
        digits written: 60.0 for ``0.0166667``, not 59.9999 (see
        :func:`resample_frames` for the same tolerance).  Other rates are
        ``1 / Frame Time`` exactly (29.97 for ``0.0333667``).

    Raises
    ------
    ValueError
        If the file is malformed (no HIERARCHY or MOTION, a bad number, a
        frame with the wrong number of values, fewer frames than announced);
        the message names the file and line.

    Examples
    --------
    >>> import tempfile, os
    >>> import numpy as np
    >>> from sklearn_crbm.datasets import make_walker, read_bvh, write_bvh
    >>> walker = make_walker(n_sequences=1, n_frames=3, random_state=0)
    >>> path = os.path.join(tempfile.mkdtemp(), "walk.bvh")
    >>> write_bvh(path, walker.data, walker.skeleton, walker.frame_rate)
    >>> skeleton, data, names, frame_rate = read_bvh(path)
    >>> data.shape, frame_rate  # three rotation channels per joint
    ((3, 57), 30.0)
    """
    header, motion = split_header(path)
    skeleton = Skeleton(**parse_bvh_hierarchy(path, header))
    n_channels = len(skeleton.feature_names)
    n_frames, frame_rate, rows = _parse_motion_header(path, motion)
    data = _parse_rows(path, rows, n_channels, n_frames, motion[-1][0])
    settle_up_axis(skeleton, path, declared_up_axis(header), data)
    return skeleton, data, skeleton.feature_names, frame_rate


def _parse_motion_header(path, motion):
    """``(n_frames, frame_rate, data lines)`` from the lines after MOTION."""
    lines = [(n, t.strip()) for n, t in motion[1:] if t.strip()]
    end_line = motion[-1][0]
    n_frames, _ = _labelled_number(path, lines, 0, "Frames:", end_line)
    if n_frames < 0 or not n_frames.is_integer():
        raise parse_error(
            path, lines[0][0], f"expected a whole number of frames, got {n_frames!r}"
        )
    frame_time, written = _labelled_number(path, lines, 1, "Frame Time:", end_line)
    if not (frame_time > 0 and np.isfinite(1.0 / frame_time)):
        raise parse_error(
            path, lines[1][0], f"expected a positive frame time, got {frame_time!r}"
        )
    return int(n_frames), rate_of_frame_time(frame_time, written), lines[2:]


def _labelled_number(path, lines, k, label, end_line):
    """``(number, its text)`` on line ``k`` of ``lines``, which must read
    ``label number``."""
    if k >= len(lines) or not lines[k][1].startswith(label):
        lineno = lines[k][0] if k < len(lines) else end_line
        raise parse_error(path, lineno, f"expected '{label} ...' after MOTION")
    lineno, text = lines[k]
    tokens = text[len(label) :].split()
    if len(tokens) != 1:
        raise parse_error(path, lineno, f"expected one number after {label!r}")
    return parse_floats(tokens, path, lineno, label)[0], tokens[0]


def _parse_rows(path, rows, n_channels, n_frames, last_line):
    if n_channels == 0 and not rows:
        # every frame line is empty, and blank lines are not counted
        return np.empty((n_frames, 0))
    if len(rows) < n_frames:
        raise parse_error(
            path,
            last_line,
            f"the file has {len(rows)} frames but 'Frames:' announced "
            f"{n_frames} (truncated file?)",
        )
    if len(rows) > n_frames:
        raise parse_error(
            path,
            rows[n_frames][0],
            f"more frames than the {n_frames} announced by 'Frames:'",
        )
    data = np.empty((n_frames, n_channels))
    for i, (lineno, text) in enumerate(rows):
        tokens = text.split()
        if len(tokens) != n_channels:
            raise parse_error(
                path, lineno, f"frame has {len(tokens)} values, expected {n_channels}"
            )
        data[i] = parse_floats(tokens, path, lineno)
    return data


# ------------------------------------------------------------------ writing
def write_bvh(
    path,
    data,
    skeleton,
    frame_rate,
    feature_names=None,
    *,
    root=None,
    channels="portable",
):
    """Write motion as a BVH file for animation tools.

    The file opens in Blender, pybvh, bvhio and bvhtoolbox, and their joint
    positions are those of ``skeleton.forward_kinematics(data)``.  With
    ``channels="source"`` a skeleton read from a BVH file keeps its own
    channels (six per joint in the Bandai Namco files, any order and number
    of rotation channels), and :func:`read_bvh` gives back exactly ``data``
    and the skeleton.  With ``channels="portable"`` (the default) every
    joint has three rotation channels (Blender's importer reads no other
    number): a bone of a BVH skeleton, or of an ASF skeleton without
    ``axis`` pre-rotation, keeps its Euler channels and values (angles in
    degrees), and the axes it lacks are added as zero channels after them.
    Other rotations cannot be written as the same channels: bones with an
    ASF ``axis`` pre-rotation (most limbs of the CMU skeletons), exponential
    maps (MIT data) and joints without rotation channels are written as
    ``Zrotation Yrotation Xrotation`` holding the bone's rotation relative
    to its parent, ``C @ M @ C^-1`` (zero for a joint without rotation).
    A joint with any position channel gets ``Xposition Yposition
    Zposition``, holding its offset as every BVH reader uses it, so an ASF
    root ``position`` is added to the root's translation channels (see
    :meth:`Skeleton.local_offsets`).  Position channels of a joint other
    than the root that hold the same offset in every frame (as in the Bandai
    Namco files) are written as the joint's OFFSET instead: pybvh and
    bvhtoolbox read position channels on the root only.  A joint other than
    the root that really moves keeps its channels (Blender and bvhio read
    them); ``root=`` that joint writes it as the root instead.

    For an ASF skeleton every bone becomes a joint at the *start* of the
    bone, and leaf bones get an end site at their end; so the ASF position of
    a bone (its end) is the BVH position of its children, or of its end site
    ``"{bone}_end"``.  MIT offset channels (``ox``, ``oy``, ``oz``) are not
    written: the joint offsets hold them.  Positions are written in the
    skeleton's own axes (z up for MIT data).  BVH has no up axis: the first
    line, ``HIERARCHY # sklearn_crbm up_axis {axis}``, declares
    ``skeleton.up_axis`` in a comment that :func:`read_bvh` reads back and
    other readers (Blender, pybvh, bvhio, bvhtoolbox) skip.

    Parameters
    ----------
    path : path-like
        The file to write.
    data : array-like of shape (n_frames, n_features)
        Raw channels.
    skeleton : Skeleton
        The skeleton the channels belong to.
    frame_rate : float
        Frames per second; the file holds ``Frame Time: 1 / frame_rate``.
    feature_names : array-like of str, default=None
        Name of each column of ``data``; default ``skeleton.feature_names``.
    root : str, default=None
        Write only this joint and the joints below it, the joint as the
        ROOT with its global position and rotation in every frame (BVH
        skeletons only).  For files whose own root is a ground marker above
        a moving hip joint, such as the Bandai Namco files:
        ``root="Hips"`` gives a file that every BVH tool reads, with the
        same positions for every joint it keeps.  None: the skeleton's root.
    channels : {"portable", "source"}, default="portable"
        ``"portable"``: the layout described above, which every BVH tool
        reads.  ``"source"``: the skeleton's own channels, in its order, each
        joint's values as they are in ``data`` (BVH skeletons only; not with
        ``root=``), for tools that expect the layout of the original file.

    Raises
    ------
    ValueError
        If a channel of the skeleton is missing, a value is not finite, a
        bone name is not one word, or the skeleton cannot be written as BVH
        (several roots, translation channels on an ASF bone other than the
        root, ``root=`` not a joint of a BVH skeleton, ``channels="source"``
        for a skeleton not read from a BVH file).

    Examples
    --------
    >>> import tempfile, os
    >>> from sklearn_crbm.datasets import make_walker, write_bvh
    >>> walker = make_walker(n_sequences=1, n_frames=3, random_state=0)
    >>> path = os.path.join(tempfile.mkdtemp(), "walk.bvh")
    >>> write_bvh(path, walker.data, walker.skeleton, frame_rate=30.0)
    """
    if not isinstance(skeleton, Skeleton):
        raise TypeError(
            f"write_bvh needs a Skeleton, got {type(skeleton).__name__} "
            f"{skeleton!r}; read one with sklearn_crbm.datasets.Skeleton.from_asf "
            "or Skeleton.from_bvh."
        )
    frame_rate = check_rate(frame_rate, "frame_rate")
    if channels not in ("portable", "source"):
        raise ValueError(f"channels must be 'portable' or 'source', got {channels!r}.")
    check_bone_names(skeleton.bone_names, "BVH")
    _check_writable(skeleton)
    X, columns = skeleton._columns(data, feature_names)
    if not np.all(
        np.isfinite(X[:, [columns[n] for n in skeleton._required_channels()]])
    ):
        raise ValueError(
            "data contain NaN or infinite values; fill them before writing."
        )
    names = skeleton.feature_names if feature_names is None else feature_names
    try:
        if channels == "source":
            joints, values = _source_layout(skeleton, X, columns, root)
        else:
            joints, values, skeleton = _portable_layout(
                skeleton, X, names, columns, root
            )
        lines = ["HIERARCHY " + UP_AXIS_COMMENT.format(axis=skeleton.up_axis)]
        _hierarchy_lines(skeleton, joints, skeleton.bones[0].name, 0, lines)
    except RecursionError:
        raise ValueError(
            f"The skeleton nests {len(skeleton.bones)} bones too deeply to be "
            "written as a BVH file."
        ) from None
    lines += [
        "MOTION",
        f"Frames: {X.shape[0]}",
        f"Frame Time: {format_number(1.0 / frame_rate)}",
    ]
    lines += [" ".join(format_number(v) for v in row) for row in values]
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")


def _portable_layout(skeleton, X, names, columns, root):
    """``(joints, values, skeleton)`` of a file every BVH tool reads: three
    rotation channels per joint (see :func:`write_bvh`)."""
    if root is not None and root != skeleton.bones[0].name:
        skeleton, X, names = _rerooted(skeleton, X, names, root)
        columns = {name: i for i, name in enumerate(names)}
    motion = {
        "X": X,
        "columns": columns,
        "rotations": skeleton.local_rotations(X, names),
        "offsets": skeleton.local_offsets(X, names),
    }
    joints = _bvh_joints(skeleton, motion["offsets"])
    values = np.column_stack(
        [_joint_values(skeleton, joint, motion) for joint in joints.values()]
        or [np.empty((X.shape[0], 0))]
    )
    return joints, values, skeleton


def _source_layout(skeleton, X, columns, root):
    """``(joints, values)`` of a file with the skeleton's own channels."""
    if root not in (None, skeleton.bones[0].name):
        raise ValueError(
            "root= rewrites the channels of the new root; it cannot be combined "
            "with channels='source'."
        )
    kinds = set(EULER_CHANNELS + TRANSLATION_CHANNELS)
    if skeleton.convention != "bvh" or any(
        c not in kinds for bone in skeleton.bones for c in bone.channels
    ):
        raise ValueError(
            "channels='source' writes the channels of a skeleton read from a BVH "
            f"file; {skeleton!r} has {skeleton.convention!r} bones or channels BVH "
            "does not have (exponential maps, offsets). Use channels='portable'."
        )
    joints = {}
    for bone in skeleton.bones:
        if _is_end_site(skeleton, bone):
            joints[bone.parent]["end"] = bone.offset
        else:
            joints[bone.name] = {"offset": bone.offset, "channels": bone.channels}
            joints[bone.name].setdefault("end", None)
    joints = _depth_first(skeleton, joints)
    order = [f"{name}_{c}" for name, j in joints.items() for c in j["channels"]]
    return joints, X[:, [columns[name] for name in order]]


def _is_end_site(skeleton, bone):
    """Whether the bone is what :func:`read_bvh` makes of an End Site."""
    return (
        bone.parent is not None
        and not bone.channels
        and bone.name == bone.parent + END_SITE_SUFFIX
        and not skeleton.children(bone.name)
    )


def _check_writable(skeleton):
    roots = [bone.name for bone in skeleton.bones if bone.parent is None]
    if len(roots) > 1:
        raise ValueError(f"A BVH file has one ROOT; the skeleton has roots {roots}.")
    if skeleton.convention == "acclaim":
        moving = [
            bone.name
            for bone in skeleton.bones[1:]
            if any(c in TRANSLATION_CHANNELS for c in bone.channels)
        ]
        if moving:
            raise ValueError(
                f"The ASF bones {moving} have translation channels; only an ASF "
                "root's translation can be written as BVH position channels."
            )


def _rerooted(skeleton, X, names, root):
    """``(skeleton, X, names)`` of the joints from ``root`` down, ``root`` a
    ROOT carrying its global position and rotation (see :func:`write_bvh`)."""
    if skeleton.convention != "bvh":
        raise ValueError(
            "root= needs a BVH skeleton; an ASF skeleton is written from its root."
        )
    keep = skeleton.descendants(root)
    i = skeleton.bone_names.index(root)
    position = skeleton.forward_kinematics(X, names)[:, i]
    rotation = skeleton.global_rotations(X, names)[:, i]
    angles = matrix_to_euler(rotation, "yxz")  # Zrotation Xrotation Yrotation
    if skeleton.angle_unit == "deg":
        angles = np.rad2deg(angles)
    old = skeleton.bone(root)
    bones = [
        Bone(root, None, old.direction, old.length, _ROOT_CHANNELS, "yxz"),
        *(skeleton.bone(name) for name in keep[1:]),
    ]
    new = Skeleton(
        bones,
        name=skeleton.name,
        up_axis=skeleton.up_axis,
        angle_unit=skeleton.angle_unit,
        convention="bvh",
    )
    columns = {name: k for k, name in enumerate(names)}
    values = np.column_stack(
        [position, angles[:, [2, 1, 0]]]
        + [X[:, [columns[name]]] for name in new.feature_names[6:]]
    )
    return new, values, new.feature_names


_ROOT_CHANNELS = ("tx", "ty", "tz", "rz", "rx", "ry")


def _rotation_channels(bone):
    """``(channels, baked)``: the joint's three BVH rotation channels (our short
    names, in file order), and whether they hold a rotation turned into Euler
    angles rather than the bone's own values."""
    if bone.rotation_type != "euler" or np.any(bone.axis):
        return ("rz", "ry", "rx"), True
    own = tuple(f"r{a}" for a in reversed(bone.rotation_order))
    missing = tuple(c for c in EULER_CHANNELS if c not in own)
    return own + missing, False


def _bvh_joints(skeleton, offsets):
    """Joints to write, in depth-first order, keyed by bone name.

    Each is a dict with the joint ``offset``, its BVH ``channels`` (our short
    names), whether its rotation is ``baked`` into Euler angles, and the
    ``end`` offset of an end site (``None`` when the joint has children).
    ``offsets`` are the per-frame offsets of :meth:`Skeleton.local_offsets`.
    """
    index = {bone.name: i for i, bone in enumerate(skeleton.bones)}
    acclaim = skeleton.convention == "acclaim"
    joints = {}
    for bone in skeleton.bones:
        children = skeleton.children(bone.name)
        if (
            not acclaim
            and not children
            and not bone.channels
            and bone.parent is not None
        ):
            continue  # a channel-less leaf of a BVH skeleton is its parent's end site
        if acclaim and bone.parent is not None:
            parent = skeleton.bones[index[bone.parent]]
            offset = np.zeros(3) if parent.parent is None else parent.offset
        else:
            offset = bone.offset
        moves = any(c in TRANSLATION_CHANNELS for c in bone.channels)
        if moves and bone.parent is not None and _still(offsets[:, index[bone.name]]):
            offset, moves = offsets[0, index[bone.name]], False
        rotation, baked = _rotation_channels(bone)
        end = None
        if not children:
            end = bone.offset if acclaim else np.zeros(3)
        joints[bone.name] = {
            "offset": offset,
            "channels": (TRANSLATION_CHANNELS if moves else ()) + rotation,
            "baked": baked,
            "end": end,
        }
    for bone in skeleton.bones:
        if bone.name not in joints:
            joints[bone.parent]["end"] = bone.offset
    return _depth_first(skeleton, joints)


def _still(offsets):
    """Whether a joint's per-frame offsets are the same in every frame, up
    to the last digits a file prints (1e-9 of their size)."""
    if not len(offsets):
        return False
    spread = np.ptp(offsets, axis=0)
    return bool(np.all(spread <= 1e-9 * np.maximum(1, abs(offsets[0]))))


def _depth_first(skeleton, joints):
    order = []

    def visit(name):
        order.append(name)
        for child in skeleton.children(name):
            if child in joints:
                visit(child)

    visit(skeleton.bones[0].name)
    return {name: dict(joints[name], name=name) for name in order}


def _joint_values(skeleton, joint, motion):
    """The joint's columns of the MOTION section, in its channel order."""
    bone = skeleton.bone(joint["name"])
    i = skeleton.bone_names.index(bone.name)
    X, columns = motion["X"], motion["columns"]
    values = dict(zip(TRANSLATION_CHANNELS, motion["offsets"][:, i].T, strict=True))
    if joint["baked"]:
        euler = np.rad2deg(matrix_to_euler(motion["rotations"][:, i], "xyz"))
        values.update(zip(EULER_CHANNELS, euler.T, strict=True))
    else:
        for channel in EULER_CHANNELS:
            if channel in bone.channels:
                angle = X[:, columns[f"{bone.name}_{channel}"]]
            else:
                angle = np.zeros(len(X))
            if skeleton.angle_unit == "rad":
                angle = np.rad2deg(angle)
            values[channel] = angle
    return np.column_stack([values[c] for c in joint["channels"]])


def _hierarchy_lines(skeleton, joints, name, depth, lines):
    joint = joints[name]
    pad = "  " * depth
    keyword = "ROOT" if depth == 0 else "JOINT"
    channels = " ".join(CHANNEL_TO_BVH[c] for c in joint["channels"])
    lines += [
        f"{pad}{keyword} {name}",
        f"{pad}{{",
        f"{pad}  OFFSET {_vector(joint['offset'])}",
        f"{pad}  CHANNELS {len(joint['channels'])} {channels}".rstrip(),
    ]
    for child in skeleton.children(name):
        if child in joints:
            _hierarchy_lines(skeleton, joints, child, depth + 1, lines)
    if joint["end"] is not None:
        lines += [
            f"{pad}  End Site",
            f"{pad}  {{",
            f"{pad}    OFFSET {_vector(joint['end'])}",
            f"{pad}  }}",
        ]
    lines.append(f"{pad}}}")


def _vector(values):
    """An offset with 12 significant digits: ``length * direction`` is only
    exact to rounding, and this keeps a read-write cycle stable."""
    return " ".join(format_number(float(f"{v:.12g}")) for v in values)
