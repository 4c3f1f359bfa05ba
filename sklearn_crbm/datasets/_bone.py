"""One bone (or joint) of a skeleton: its place, length and channels."""

import math
from dataclasses import dataclass, field

import numpy as np

from ._channels import EULER_CHANNELS, EXPMAP_CHANNELS, KNOWN_CHANNELS

__all__ = ["Bone"]


@dataclass
class Bone:
    """One bone (or joint) of a :class:`Skeleton`.

    Parameters
    ----------
    name : str
        Bone name, unique within its skeleton (``"lfemur"``).
    parent : str or None
        Name of the parent bone; ``None`` for the root.
    direction : array-like of shape (3,)
        Direction of the bone offset, normalised to a unit vector (ASF files
        print it to about six digits).  ASF: the global direction of the bone
        at rest.  BVH and MIT: ``offset / |offset|`` in the parent's frame.
    length : float
        Length of the offset.
    channels : tuple of str
        The bone's values, in the order they appear in the data: ``"tx"``,
        ``"ty"``, ``"tz"`` (translation), ``"rx"``, ``"ry"``, ``"rz"`` (Euler
        angles), ``"ex"``, ``"ey"``, ``"ez"`` (exponential map) and ``"ox"``,
        ``"oy"``, ``"oz"`` (per-frame copies of the offset, MIT data only; forward
        kinematics uses ``length * direction`` instead).
    rotation_order : str, default=""
        The axes of the Euler channels in the order they are *applied* to a
        vector (first applied first): ASF ``dof rx ry rz`` is ``"xyz"``; BVH
        ``Zrotation Xrotation Yrotation`` (``R = Rz Rx Ry``) is ``"yxz"``.
        Empty when the bone has no Euler channels.
    axis : array-like of shape (3,), default=(0, 0, 0)
        ASF ``axis`` pre-rotation in degrees (for an ASF root, its
        ``orientation``); zeros for BVH and MIT.
    axis_order : str, default="xyz"
        Order in which the ``axis`` angles are applied.
    """

    name: str
    parent: str | None
    direction: np.ndarray
    length: float
    channels: tuple[str, ...] = ()
    rotation_order: str = ""
    axis: np.ndarray = field(default_factory=lambda: np.zeros(3))
    axis_order: str = "xyz"

    def __post_init__(self):
        direction = _vector3(self.direction, self.name, "direction")
        norm = _norm(direction)
        self.direction = direction / norm if norm > 0 else direction
        length = _finite_number(self.length, self.name, "length")
        if length < 0:
            raise ValueError(
                f"Bone {self.name!r}: length must be >= 0, got {length!r}; give the "
                "direction the sign instead."
            )
        self.length = length
        if isinstance(self.channels, str):
            raise TypeError(
                f"Bone {self.name!r}: channels must be a sequence of channel names "
                f"such as ('rx', 'ry', 'rz'), got the string {self.channels!r}."
            )
        self.channels = tuple(str(c) for c in self.channels)
        self.rotation_order = str(self.rotation_order).lower()
        self.axis = _vector3(self.axis, self.name, "axis")
        self.axis_order = str(self.axis_order).lower()
        if sorted(self.axis_order) != ["x", "y", "z"]:
            raise ValueError(
                f"Bone {self.name!r}: axis_order must hold each of 'x', 'y', 'z' "
                f"once (e.g. 'xyz'), got {self.axis_order!r}."
            )
        _check_bone_channels(self)

    @classmethod
    def from_offset(cls, name, parent, offset, **kwargs):
        """A bone given by its offset vector rather than direction and length.

        Parameters
        ----------
        name, parent : str
            As for :class:`Bone` (``parent=None`` for a root).
        offset : array-like of shape (3,)
            ``length * direction``; a zero offset gives a bone of length 0.
        **kwargs
            The other fields of :class:`Bone` (``channels``, ...).

        Examples
        --------
        >>> from sklearn_crbm.datasets import Bone
        >>> bone = Bone.from_offset("Spine", "Hips", [0, 10, 0], channels=("rx",),
        ...                         rotation_order="x")
        >>> bone.length, bone.direction.tolist()
        (10.0, [0.0, 1.0, 0.0])
        """
        offset = _vector3(offset, name, "offset")
        return cls(name, parent, direction=offset, length=_norm(offset), **kwargs)

    @property
    def offset(self):
        """``length * direction``, shape (3,)."""
        return self.length * self.direction

    @property
    def rotation_type(self):
        """``"euler"``, ``"expmap"`` or ``""`` (no rotation channels)."""
        if any(c in EULER_CHANNELS for c in self.channels):
            return "euler"
        if any(c in EXPMAP_CHANNELS for c in self.channels):
            return "expmap"
        return ""


def _vector3(value, name, what):
    """Three finite floats, or a ValueError naming the bone and the field."""
    try:
        vector = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(
            f"Bone {name!r}: {what} must be three numbers, got {value!r}."
        ) from None
    if vector.size != 3:
        raise ValueError(
            f"Bone {name!r}: {what} must be three numbers, got shape {vector.shape}."
        )
    if not all(map(math.isfinite, vector.flat)):
        raise ValueError(f"Bone {name!r}: {what} must be finite, got {vector}.")
    return vector.reshape(3)


def _finite_number(value, name, what):
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(
            f"Bone {name!r}: {what} must be a number, got {value!r}."
        ) from None
    if not np.isfinite(number):
        raise ValueError(f"Bone {name!r}: {what} must be finite, got {number!r}.")
    return number


def _norm(vector):
    """Euclidean norm without overflow for huge components (e.g. 1e300)."""
    return math.hypot(*vector.tolist())


def _check_bone_channels(bone):
    unknown = [c for c in bone.channels if c not in KNOWN_CHANNELS]
    if unknown:
        raise ValueError(
            f"Bone {bone.name!r} has unknown channels {unknown}; known channels "
            f"are {list(KNOWN_CHANNELS)}."
        )
    if len(set(bone.channels)) != len(bone.channels):
        raise ValueError(f"Bone {bone.name!r} repeats a channel: {bone.channels}.")
    euler_axes = sorted(c[1] for c in bone.channels if c in EULER_CHANNELS)
    if sorted(bone.rotation_order) != euler_axes:
        raise ValueError(
            f"Bone {bone.name!r}: rotation_order {bone.rotation_order!r} must name "
            f"exactly the axes of its Euler channels {euler_axes}."
        )
    expmap = [c for c in bone.channels if c in EXPMAP_CHANNELS]
    if expmap and (euler_axes or len(expmap) != 3):
        raise ValueError(
            f"Bone {bone.name!r}: an exponential map needs all of ex, ey, ez and "
            "no Euler channels."
        )
