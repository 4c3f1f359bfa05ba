"""Skeletons: bones, their channels, and forward kinematics.

A :class:`Skeleton` describes how the raw channels of a motion-capture file
(root translation, Euler angles or exponential maps per bone) turn into 3-D
joint positions.  It is built from an Acclaim ASF file, from the header of a
BVH file, or from the ``skel`` structure of Graham Taylor's MIT data.

Two conventions place the bones:

``"acclaim"`` (ASF/AMC)
    Every bone is a segment that starts where its parent ends.  Its rest
    direction is given in the global frame.  The global rotation of a bone is
    ``R = R_parent @ C @ M @ C^-1``, with ``C`` the ASF ``axis`` pre-rotation
    and ``M`` the rotation of the bone's channels, and the bone's end lies at
    ``position_parent + length * R @ direction``.

``"bvh"`` (BVH and Taylor's MIT data)
    Every bone is a joint placed at an offset from its parent, expressed in the
    parent's frame: ``position = position_parent + R_parent @ offset``, and
    ``R = R_parent @ M``.  A joint's position channels (``Xposition`` ...)
    *replace* the matching components of its offset, as pybvh, bvhio,
    bvhtoolbox and Blender read BVH files; so a root at ``OFFSET 0 90 0``
    with position channels sits where its channels say.

In ``"acclaim"`` skeletons translation channels are *added* to the offset:
the root is placed at its ASF ``position`` plus its translation channels.
"""

import numpy as np

from ..utils._rotations import euler_to_matrix, expmap_to_matrix
from ._asf import parse_asf
from ._bone import Bone
from ._bvh_hierarchy import parse_bvh_hierarchy, split_header
from ._channels import (
    EXPMAP_CHANNELS,
    OFFSET_CHANNELS,
    TRANSLATION_CHANNELS,
    frame_columns,
)
from ._mit import parse_mit_skeleton
from ._up_axis import declared_up_axis, detect_up_axis, settle_up_axis

__all__ = ["Skeleton"]

ANGLE_UNITS = ("deg", "rad")
CONVENTIONS = ("acclaim", "bvh")


class Skeleton:
    """The bones of a motion-capture subject and how channels move them.

    Parameters
    ----------
    bones : list of Bone
        The root first, every parent before its children, in the order of
        the bones' channels in the data.  (Further bones without a parent are
        allowed, e.g. for a bare list of joints; each is placed like a root.)
    name : str, default="skeleton"
        A name for the skeleton.
    up_axis : {"x", "y", "z"}, default="y"
        The vertical axis: ``"y"`` for CMU data, ``"z"`` for MIT.  The file
        readers detect it (see :meth:`detect_up_axis`).
    angle_unit : {"deg", "rad"}, default="deg"
        Unit of the Euler channels.  Exponential maps are always in radians
        and ``axis`` pre-rotations always in degrees.
    length_scale : float, default=1.0
        The file's length unit (ASF ``:units length``), kept for reference;
        lengths and positions are in the file's units.
    convention : {"acclaim", "bvh"}, default="acclaim"
        How bone offsets and rotations compose (see the module docstring):
        ``"acclaim"`` for ASF skeletons, ``"bvh"`` for BVH and MIT.

    Attributes
    ----------
    bones : list of Bone
        The bones.
    feature_names : ndarray of str
        ``"{bone}_{channel}"`` for every channel, in data order.

    Examples
    --------
    >>> from sklearn_crbm.datasets import make_walker
    >>> walker = make_walker(n_sequences=1, n_frames=5, random_state=0)
    >>> skeleton = walker.skeleton
    >>> skeleton.feature_names[:4]
    array(['root_tx', 'root_ty', 'root_tz', 'root_rx'], dtype=object)
    >>> skeleton.forward_kinematics(walker.data).shape
    (5, 18, 3)
    """

    def __init__(
        self,
        bones,
        *,
        name="skeleton",
        up_axis="y",
        angle_unit="deg",
        length_scale=1.0,
        convention="acclaim",
    ):
        self.name = str(name)
        self.bones = list(bones)
        not_bones = [b for b in self.bones if not isinstance(b, Bone)]
        if not_bones:
            raise TypeError(
                f"A skeleton is built from Bone objects, got {not_bones[0]!r} "
                f"({type(not_bones[0]).__name__}); see sklearn_crbm.datasets.Bone."
            )
        self.up_axis = str(up_axis).lower()
        self.angle_unit = str(angle_unit).lower()
        self.length_scale = float(length_scale)
        self.convention = str(convention).lower()
        self._check()
        self._index = {bone.name: i for i, bone in enumerate(self.bones)}
        self._children = {}
        for bone in self.bones:
            self._children.setdefault(bone.parent, []).append(bone.name)

    def _check(self):
        if self.up_axis not in ("x", "y", "z"):
            raise ValueError(f"up_axis must be 'x', 'y' or 'z', got {self.up_axis!r}.")
        if self.angle_unit not in ANGLE_UNITS:
            raise ValueError(
                f"angle_unit must be 'deg' or 'rad', got {self.angle_unit!r}."
            )
        if self.convention not in CONVENTIONS:
            raise ValueError(
                f"convention must be one of {CONVENTIONS}, got {self.convention!r}."
            )
        if not self.bones:
            raise ValueError("A skeleton needs at least one bone.")
        if self.bones[0].parent is not None:
            raise ValueError(
                f"The first bone must be the root (parent None), got "
                f"{self.bones[0].name!r} with parent {self.bones[0].parent!r}."
            )
        seen = set()
        for bone in self.bones:
            if bone.name in seen:
                raise ValueError(f"Bone name {bone.name!r} occurs twice.")
            if bone.parent is not None and bone.parent not in seen:
                raise ValueError(
                    f"Bone {bone.name!r} comes before its parent {bone.parent!r} "
                    "(or the parent does not exist); list parents before children."
                )
            seen.add(bone.name)

    def __repr__(self):
        return (
            f"Skeleton(name={self.name!r}, n_bones={len(self.bones)}, "
            f"n_channels={len(self.feature_names)}, up_axis={self.up_axis!r}, "
            f"angle_unit={self.angle_unit!r}, convention={self.convention!r})"
        )

    # ------------------------------------------------------------------ lookup
    def bone(self, name):
        """The bone called ``name``.

        Raises
        ------
        ValueError
            If the skeleton has no such bone.
        """
        try:
            return self.bones[self._index[name]]
        except KeyError:
            raise ValueError(
                f"Skeleton {self.name!r} has no bone {name!r}; its bones are "
                f"{self.bone_names}."
            ) from None

    @property
    def bone_names(self):
        """Names of the bones, in order."""
        return [bone.name for bone in self.bones]

    @property
    def parent_indices(self):
        """Index of each bone's parent in :attr:`bones` (``-1`` for the root)."""
        return np.array(
            [-1 if b.parent is None else self._index[b.parent] for b in self.bones],
            dtype=np.intp,
        )

    def children(self, name):
        """Names of the bones whose parent is ``name``."""
        self.bone(name)
        return list(self._children.get(name, ()))

    def descendants(self, name):
        """``name`` and every bone below it, parents before children.

        For instance ``skeleton.descendants("lowerback")`` is the whole upper
        body of a CMU skeleton, and ``descendants("lfemur")`` the left leg.
        """
        self.bone(name)
        found = [name]
        below = {name}
        for bone in self.bones[self._index[name] + 1 :]:
            if bone.parent in below:
                found.append(bone.name)
                below.add(bone.name)
        return found

    @property
    def feature_names(self):
        """``"{bone}_{channel}"`` for every channel of every bone, in data order."""
        return np.array(
            [f"{bone.name}_{c}" for bone in self.bones for c in bone.channels],
            dtype=object,
        )

    def detect_up_axis(self, data=None, feature_names=None):
        """The axis the body stands along in ``data`` (or in the rest pose).

        Seen from the pelvis (the first bone where the skeleton branches), the
        legs hang below and the spine rises above, while the legs sit side by
        side: along the up axis the centroids of the pelvis's branches lie
        farthest apart, in a T-pose as in a walk.  Each of up to 200 frames,
        evenly spaced, votes for the axis along which they spread most (for a
        skeleton that does not branch, the axis along which it is longest),
        in the world frame of the data: a file whose root rotation stands a
        y-up rest pose on the z axis is z-up.  This is the axis to give
        Blender's BVH importer as *Up* (its default is Y).

        The readers set :attr:`up_axis` with it: :func:`read_bvh` from the
        motion (unless the file declares its axis), :meth:`from_bvh` and
        :meth:`from_asf` from the rest pose, and :func:`read_amc` warns when
        the motion stands along another axis than its skeleton's.

        Parameters
        ----------
        data : array-like of shape (n_frames, n_features), default=None
            Raw channels; None takes the rest pose (every channel 0).
        feature_names : array-like of str, default=None
            Names of the columns of ``data``; default
            :attr:`feature_names`.

        Returns
        -------
        up_axis : {"x", "y", "z"} or None
            None when the poses cannot tell (every joint at one point, as in
            the rest pose of a file whose joints are all placed by position
            channels).

        Examples
        --------
        >>> from sklearn_crbm.datasets import make_walker
        >>> walker = make_walker(n_sequences=1, n_frames=20, random_state=0)
        >>> walker.skeleton.detect_up_axis(walker.data)
        'y'
        """
        return detect_up_axis(self, data, feature_names)

    # ------------------------------------------------------ forward kinematics
    def forward_kinematics(self, data, feature_names=None):
        """Joint positions from raw channels.

        Parameters
        ----------
        data : array-like of shape (n_frames, n_features)
            Raw channels: root translation in the skeleton's length unit,
            Euler angles in :attr:`angle_unit`, exponential maps in radians.
        feature_names : array-like of str, default=None
            Name of each column of ``data``; default :attr:`feature_names`.
            Columns the skeleton does not use are ignored.

        Returns
        -------
        positions : ndarray of shape (n_frames, n_bones, 3)
            For ``"acclaim"`` skeletons the root position and the *end* of
            every bone; for ``"bvh"`` skeletons the position of every joint.

        Raises
        ------
        ValueError
            If a rotation or translation channel of the skeleton is missing
            from ``feature_names`` (the message names them).
        """
        positions, _ = self._global_transforms(data, feature_names)
        return positions

    def global_rotations(self, data, feature_names=None):
        """Global rotation matrix of every bone, shape (n_frames, n_bones, 3, 3).

        Same parameters as :meth:`forward_kinematics`.
        """
        _, rotations = self._global_transforms(data, feature_names)
        return rotations

    def local_rotations(self, data, feature_names=None):
        """Rotation of every bone relative to its parent, (n_frames, n_bones, 3, 3).

        For ``"acclaim"`` skeletons this includes the ``axis`` pre-rotation,
        ``C @ M @ C^-1``; it is the rotation a BVH joint at the start of the
        bone would carry.  Same parameters as :meth:`forward_kinematics`.
        """
        X, columns = self._columns(data, feature_names)
        return self._local_rotations(X, columns)

    def local_offsets(self, data, feature_names=None):
        """Offset of every bone from its parent, per frame, (n_frames, n_bones, 3).

        The bone's ``offset`` with its translation channels applied: in
        ``"bvh"`` skeletons they replace the matching components, in
        ``"acclaim"`` skeletons they are added (see the module docstring).
        What a BVH file written with :func:`~sklearn_crbm.datasets.write_bvh`
        holds in a joint's position channels.  Same parameters as
        :meth:`forward_kinematics`.
        """
        X, columns = self._columns(data, feature_names)
        return self._local_offsets(X, columns)

    def _global_transforms(self, data, feature_names):
        """Global positions and rotations, one depth of the tree at a time."""
        X, columns = self._columns(data, feature_names)
        local = self._local_rotations(X, columns)
        offsets = self._local_offsets(X, columns)
        rotations = np.empty_like(local)
        positions = np.empty_like(offsets)
        for depth, bones in enumerate(self._depth_levels()):
            if depth == 0:
                rotations[:, bones] = local[:, bones]
                positions[:, bones] = offsets[:, bones]
                continue
            parents = self.parent_indices[bones]
            rotations[:, bones] = rotations[:, parents] @ local[:, bones]
            frame = rotations[:, bones if self.convention == "acclaim" else parents]
            positions[:, bones] = positions[:, parents] + np.einsum(
                "nkij,nkj->nki", frame, offsets[:, bones]
            )
        return positions, rotations

    def _depth_levels(self):
        """Indices of the bones at each depth below the roots (roots first)."""
        depth = []
        for parent in self.parent_indices:
            depth.append(0 if parent < 0 else depth[parent] + 1)
        levels = [[] for _ in range(max(depth) + 1)]
        for i, d in enumerate(depth):
            levels[d].append(i)
        return [np.array(level, dtype=np.intp) for level in levels]

    def _required_channels(self):
        """Feature names that forward kinematics reads (all but MIT offsets)."""
        return [
            f"{bone.name}_{c}"
            for bone in self.bones
            for c in bone.channels
            if c not in OFFSET_CHANNELS
        ]

    def _columns(self, data, feature_names):
        names = self.feature_names if feature_names is None else feature_names
        return frame_columns(data, names, self._required_channels())

    def _local_rotations(self, X, columns):
        """Rotation of every bone relative to its parent, ``C @ M @ C^-1``
        (see the module docstring), bones of one kind of channels together."""
        n_frames, n_bones = X.shape[0], len(self.bones)
        rotations = np.broadcast_to(np.eye(3), (n_frames, n_bones, 3, 3)).copy()
        groups = {}
        for i, bone in enumerate(self.bones):
            kind = bone.rotation_type
            if kind:
                groups.setdefault((kind, bone.rotation_order), []).append(i)
        for (kind, order), bones in groups.items():
            names = [f"r{a}" for a in order] if kind == "euler" else EXPMAP_CHANNELS
            angles = X[
                :,
                [[columns[f"{self.bones[i].name}_{c}"] for c in names] for i in bones],
            ]
            if kind == "expmap":
                rotations[:, bones] = expmap_to_matrix(angles)
                continue
            if self.angle_unit == "deg":
                angles = np.deg2rad(angles)
            rotations[:, bones] = euler_to_matrix(angles, order)
        axes = {}
        for i, bone in enumerate(self.bones):
            if np.any(bone.axis):
                axes.setdefault(bone.axis_order, []).append(i)
        for order, bones in axes.items():
            C = euler_to_matrix(np.deg2rad([self.bones[i].axis for i in bones]), order)
            rotations[:, bones] = C @ rotations[:, bones] @ C.swapaxes(-1, -2)
        return rotations

    def _local_offsets(self, X, columns):
        """Where every bone starts (BVH: the joint) relative to its parent, per
        frame.

        BVH position channels *replace* the matching components of the
        offset, as every BVH tool reads them (pybvh, bvhio, bvhtoolbox,
        Blender); ASF translation channels are *added* to the offset (for an
        ASF root, to its ``position``), as in the Acclaim format.
        """
        rest = np.array([bone.offset for bone in self.bones]).reshape(-1, 3)
        offsets = np.broadcast_to(rest, (X.shape[0], *rest.shape)).copy()
        for i, bone in enumerate(self.bones):
            for k, c in enumerate(TRANSLATION_CHANNELS):
                if c not in bone.channels:
                    continue
                values = X[:, columns[f"{bone.name}_{c}"]]
                if self.convention == "bvh":
                    offsets[:, i, k] = values
                else:
                    offsets[:, i, k] += values
        return offsets

    # ------------------------------------------------------------ constructors
    @classmethod
    def from_asf(cls, path):
        """Read an Acclaim ASF skeleton file (e.g. CMU ``35.asf``).

        The up axis is detected from the rest pose (see
        :meth:`detect_up_axis`); y where it cannot tell (the CMU axes).

        Raises
        ------
        ValueError
            If the file is malformed; the message names the file and line.
        """
        return settle_up_axis(cls(**parse_asf(path)), path)

    @classmethod
    def from_bvh(cls, path):
        """Read the skeleton from the HIERARCHY of a BVH file.

        End sites become bones named ``"{parent}_end"`` without channels.
        The up axis is the one the file declares (:func:`write_bvh` does),
        else the one detected from the rest pose (see :meth:`detect_up_axis`),
        else y.

        Raises
        ------
        ValueError
            If the file is malformed; the message names the file and line.
        """
        header, _ = split_header(path)
        skeleton = cls(**parse_bvh_hierarchy(path, header))
        return settle_up_axis(skeleton, path, declared_up_axis(header))

    @classmethod
    def from_mit(cls, skel, offsets=None):
        """The skeleton of Graham Taylor's MIT walking data.

        Parameters
        ----------
        skel : path-like or MATLAB struct
            A path to a ``.mat`` file with ``skel`` (and ``Motion``), or the
            ``skel`` struct as loaded by :func:`scipy.io.loadmat`.
        offsets : array-like of shape (108,), default=None
            One frame of MIT data, whose offset columns give the bone
            offsets.  Default: the first frame of ``Motion`` when ``skel`` is
            a path; otherwise the offsets are unknown (zero length) and
            :meth:`forward_kinematics` places every joint at the root.

        Returns
        -------
        skeleton : Skeleton
            ``convention="bvh"``, ``up_axis="z"``, ``angle_unit="rad"``.  See
            :func:`~sklearn_crbm.datasets.load_mit_walk` for the bone names.
        """
        return cls(**parse_mit_skeleton(skel, offsets))
