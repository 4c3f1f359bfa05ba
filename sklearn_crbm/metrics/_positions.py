"""Statistics of joint positions: jitter and foot skating."""

import numpy as np

from ..utils._sequences import check_sequence_ids

__all__ = ["foot_skating", "jitter"]


def _check_positions(positions, sequence_ids):
    """Joint positions as (n_frames, n_joints, 3), and the sequences."""
    positions = np.asarray(positions, dtype=np.float64)
    if positions.ndim == 2 and positions.shape[1] % 3 == 0:
        positions = positions.reshape(positions.shape[0], -1, 3)
    if positions.ndim != 3 or positions.shape[2] != 3:
        raise ValueError(
            "positions must have shape (n_frames, n_joints, 3) (what "
            "Skeleton.forward_kinematics returns) or (n_frames, 3 * n_joints); "
            f"got shape {positions.shape}."
        )
    return positions, check_sequence_ids(sequence_ids, positions.shape[0])


def jitter(positions, *, sequence_ids=None):
    """Mean size of the third difference of joint positions in each sequence.

    The norm of ``p[t] - 3 p[t-1] + 3 p[t-2] - p[t-3]`` (the change of
    acceleration from frame to frame, in length units) of every joint,
    averaged over the joints and frames of each sequence.  Smooth motion
    has a small jerk; generated motion that shakes from frame to frame has
    a larger one than real motion of the same kind.

    Parameters
    ----------
    positions : array-like of shape (n_frames, n_joints, 3)
        Joint positions, all sequences stacked (for example
        :meth:`~sklearn_crbm.datasets.Skeleton.forward_kinematics` of raw
        channels); ``(n_frames, 3 * n_joints)`` is accepted too.
    sequence_ids : array-like of shape (n_frames,), default=None
        Sequence id of every frame; ``None`` means one sequence.

    Returns
    -------
    jitter : ndarray of shape (n_sequences,)
        Length units per frame cubed; ``nan`` for a sequence of fewer than
        4 frames.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.metrics import jitter
    >>> t = np.arange(10.0)
    >>> smooth = np.column_stack([t ** 2, 0 * t, 0 * t])[:, None, :]
    >>> shaky = smooth.copy()
    >>> shaky[:, 0, 1] = [0.0, 1.0] * 5  # up and down every other frame
    >>> jitter(np.concatenate([smooth, shaky]), sequence_ids=np.repeat([0, 1], 10))
    array([0., 4.])
    """
    positions, sequences = _check_positions(positions, sequence_ids)
    values = []
    for start, stop in zip(sequences.starts, sequences.stops, strict=True):
        third = np.diff(positions[start:stop], n=3, axis=0)
        values.append(np.linalg.norm(third, axis=2).mean() if len(third) else np.nan)
    return np.asarray(values)


def foot_skating(positions, *, feet, sequence_ids=None, up_axis=1, contact_height=3.0):
    """Horizontal speed of the feet while they touch the ground, per sequence.

    A foot is taken to touch the ground in the frames where it is within
    ``contact_height`` of its lowest height in the sequence; its horizontal
    displacement from each such frame to the next is averaged over those
    frames and over the feet.  A real foot stands still while it carries
    the body; generated walks whose feet slide along the ground score
    higher than real ones.

    Parameters
    ----------
    positions : array-like of shape (n_frames, n_joints, 3)
        Joint positions, all sequences stacked (for example
        :meth:`~sklearn_crbm.datasets.Skeleton.forward_kinematics` of raw
        channels).
    feet : list of int
        The joints (indices into the second axis) of the feet, for example
        the toes or ankles of both legs.
    sequence_ids : array-like of shape (n_frames,), default=None
        Sequence id of every frame; ``None`` means one sequence.
    up_axis : int, default=1
        The vertical axis of the positions (0, 1 or 2; 1 for Y up).
    contact_height : float, default=3.0
        How far above its lowest point a foot still touches the ground, in
        the length units of ``positions`` (3 cm for data in centimetres).

    Returns
    -------
    skating : ndarray of shape (n_sequences,)
        Length units per frame; ``nan`` for a sequence of one frame.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.metrics import foot_skating
    >>> height = np.array([0.0, 0.0, 10.0, 10.0, 0.0, 0.0])
    >>> forward = np.array([0.0, 0.0, 5.0, 10.0, 15.0, 17.0])
    >>> foot = np.column_stack([forward, height, np.zeros(6)])[:, None, :]
    >>> foot_skating(foot, feet=[0])  # moves 0, 5 (lifting off) and 2 while down
    array([2.33333333])
    """
    positions, sequences = _check_positions(positions, sequence_ids)
    if up_axis not in (0, 1, 2):
        raise ValueError(f"up_axis must be 0, 1 or 2, got {up_axis!r}.")
    feet = np.atleast_1d(np.asarray(feet, dtype=np.intp))
    horizontal = [axis for axis in range(3) if axis != up_axis]
    values = []
    for start, stop in zip(sequences.starts, sequences.stops, strict=True):
        foot = positions[start:stop][:, feet, :]
        if len(foot) < 2:
            values.append(np.nan)
            continue
        height = foot[..., up_axis]
        touching = (height - height.min(axis=0)) <= contact_height
        step = np.linalg.norm(np.diff(foot[..., horizontal], axis=0), axis=2)
        values.append(float(step[touching[:-1]].mean()))
    return np.asarray(values)
