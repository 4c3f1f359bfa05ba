"""Small synthetic motion for fast tests and examples (no files needed)."""

import numbers

import numpy as np
from sklearn.utils import Bunch, check_random_state

from ._bone import Bone
from ._skeleton import Skeleton

__all__ = ["make_oscillations", "make_walker", "walker_skeleton"]

FRAME_RATE = 30.0


def _check_count(value, name):
    if not isinstance(value, numbers.Integral) or isinstance(value, bool) or value < 1:
        raise ValueError(f"{name} must be a positive integer, got {value!r}.")
    return int(value)


def make_oscillations(
    n_sequences=4, n_frames=50, n_features=6, *, noise=0.05, random_state=None
):
    """Phase-coupled sinusoids: a tiny stand-in for motion data.

    Every column oscillates at the sequence's own frequency with a fixed
    phase lag behind the column before it, like joint angles of a periodic
    gait, so that the past frames predict the next one.  Each sequence has a
    random frequency (a period of 16 to 24 frames) and a random start phase.
    Columns are roughly zero-mean with unit variance.

    Parameters
    ----------
    n_sequences : int, default=4
        Number of sequences.
    n_frames : int, default=50
        Frames per sequence.
    n_features : int, default=6
        Number of columns.
    noise : float, default=0.05
        Standard deviation of the Gaussian noise added to every value.
    random_state : int, RandomState instance or None, default=None
        Seed for the frequencies, phases and noise.

    Returns
    -------
    X : ndarray of shape (n_sequences * n_frames, n_features)
        The sequences stacked in long format, float64.
    sequence_ids : ndarray of shape (n_sequences * n_frames,)
        The sequence (0 to ``n_sequences - 1``) of every frame.

    Examples
    --------
    >>> from sklearn_crbm.datasets import make_oscillations
    >>> X, sequence_ids = make_oscillations(n_sequences=2, n_frames=30, random_state=0)
    >>> X.shape, sequence_ids.shape
    ((60, 6), (60,))
    >>> sequence_ids[[0, 29, 30, 59]]
    array([0, 0, 1, 1])
    """
    n_sequences = _check_count(n_sequences, "n_sequences")
    n_frames = _check_count(n_frames, "n_frames")
    n_features = _check_count(n_features, "n_features")
    if not isinstance(noise, numbers.Real) or not 0 <= noise < np.inf:
        raise ValueError(f"noise must be a non-negative number, got {noise!r}.")
    rng = check_random_state(random_state)
    lags = 2.0 * np.pi * np.arange(n_features) / n_features
    t = np.arange(n_frames, dtype=np.float64)[:, None]
    blocks = []
    for _ in range(n_sequences):
        omega = 2.0 * np.pi / rng.uniform(16.0, 24.0)
        start = rng.uniform(0.0, 2.0 * np.pi)
        blocks.append(np.sqrt(2.0) * np.sin(omega * t + start - lags))
    X = np.concatenate(blocks) + noise * rng.standard_normal(
        (n_sequences * n_frames, n_features)
    )
    sequence_ids = np.repeat(np.arange(n_sequences), n_frames)
    return X, sequence_ids


def make_styled_oscillations(
    n_sequences=8, n_frames=60, n_features=6, *, switching=False, random_state=None
):
    """Oscillations in two styles: a tiny stand-in for a labelled corpus.

    The frames of :func:`make_oscillations`, whose first column tells the
    style: about +1 in style ``"high"``, about -1 in style ``"low"`` (plus
    noise of standard deviation 0.1).  Odd sequences are ``"high"``, even
    ones ``"low"``; with ``switching`` the style is drawn anew for every
    frame instead, so that only a frame's label, not its past, tells its
    style.

    Parameters
    ----------
    n_sequences : int, default=8
        Number of sequences.
    n_frames : int, default=60
        Frames per sequence.
    n_features : int, default=6
        Number of columns.
    switching : bool, default=False
        Draw every frame's style at random (equal odds).
    random_state : int, RandomState instance or None, default=None
        Seed for the oscillations, the styles and the noise.

    Returns
    -------
    X : ndarray of shape (n_sequences * n_frames, n_features)
    sequence_ids : ndarray of shape (n_sequences * n_frames,)
    styles : ndarray of str of shape (n_sequences * n_frames,)
        ``"high"`` or ``"low"``, frame by frame.

    Examples
    --------
    >>> from sklearn_crbm.datasets import make_styled_oscillations
    >>> X, ids, styles = make_styled_oscillations(n_sequences=2, random_state=0)
    >>> styles[[0, 60]]
    array(['low', 'high'], dtype='<U4')
    >>> bool(X[60:, 0].mean() > 0.5)
    True
    """
    rng = check_random_state(random_state)
    X, ids = make_oscillations(n_sequences, n_frames, n_features, random_state=rng)
    high = rng.random_sample(len(ids)) < 0.5 if switching else ids % 2 == 1
    X[:, 0] = np.where(high, 1.0, -1.0) + 0.1 * rng.standard_normal(len(ids))
    return X, ids, np.where(high, "high", "low")


# (name, parent, direction, length, dof) of the walker, ASF style: y up,
# +z forward, +x to the subject's left, lengths in CMU ASF units.
_WALKER_BONES = [
    ("lhipjoint", "root", (1.0, -0.4, 0.0), 2.5, ""),
    ("lfemur", "lhipjoint", (0.0, -1.0, 0.0), 7.5, "rx ry rz"),
    ("ltibia", "lfemur", (0.0, -1.0, 0.0), 7.9, "rx"),
    ("lfoot", "ltibia", (0.0, -0.3, 1.0), 2.4, "rx"),
    ("rhipjoint", "root", (-1.0, -0.4, 0.0), 2.5, ""),
    ("rfemur", "rhipjoint", (0.0, -1.0, 0.0), 7.5, "rx ry rz"),
    ("rtibia", "rfemur", (0.0, -1.0, 0.0), 7.9, "rx"),
    ("rfoot", "rtibia", (0.0, -0.3, 1.0), 2.4, "rx"),
    ("lowerback", "root", (0.0, 1.0, 0.0), 4.0, "rx ry rz"),
    ("thorax", "lowerback", (0.0, 1.0, 0.0), 4.0, "rx ry rz"),
    ("head", "thorax", (0.0, 1.0, 0.0), 3.5, "rx ry rz"),
    ("lclavicle", "thorax", (1.0, 0.0, 0.0), 3.5, ""),
    ("lhumerus", "lclavicle", (0.0, -1.0, 0.0), 5.0, "rx ry rz"),
    ("lradius", "lhumerus", (0.0, -1.0, 0.0), 4.0, "rx"),
    ("rclavicle", "thorax", (-1.0, 0.0, 0.0), 3.5, ""),
    ("rhumerus", "rclavicle", (0.0, -1.0, 0.0), 5.0, "rx ry rz"),
    ("rradius", "rhumerus", (0.0, -1.0, 0.0), 4.0, "rx"),
]


def walker_skeleton():
    """The 18-bone ASF-style skeleton of :func:`make_walker`.

    y is up, the subject faces +z with its left side towards +x, angles are
    in degrees and there are no ``axis`` pre-rotations.

    Returns
    -------
    skeleton : Skeleton
    """
    root = Bone(
        "root", None, np.zeros(3), 0.0, ("tx", "ty", "tz", "rx", "ry", "rz"), "xyz"
    )
    bones = [root]
    for name, parent, direction, length, dof in _WALKER_BONES:
        direction = np.asarray(direction) / np.linalg.norm(direction)
        channels = tuple(dof.split())
        order = "".join(c[1] for c in channels)
        bones.append(Bone(name, parent, direction, length, channels, order))
    return Skeleton(
        bones, name="walker", up_axis="y", angle_unit="deg", convention="acclaim"
    )


def _walk_channels(phase, t, params):
    """Channel values (degrees, ASF units) of one walk, keyed by feature name."""
    s, c = np.sin(phase), np.cos(phase)
    heading = params["heading"] + params["turn"] * t
    step = params["speed"] * np.ones_like(t)
    h = np.deg2rad(heading)
    return {
        "root_tx": params["x0"] + np.cumsum(step * np.sin(h)),
        "root_ty": 17.2 + 0.4 * np.cos(2 * phase),
        "root_tz": params["z0"] + np.cumsum(step * np.cos(h)),
        "root_rx": 2.0 + 1.5 * np.sin(2 * phase),
        "root_ry": heading,
        "root_rz": 2.5 * s,
        "lfemur_rx": -22.0 * s - 5.0,
        "lfemur_ry": 3.0 * c,
        "lfemur_rz": -4.0 + 2.0 * s,
        "ltibia_rx": 22.0 - 18.0 * np.cos(phase + np.pi / 3),
        "lfoot_rx": 10.0 * np.sin(phase + 0.8),
        "rfemur_rx": 22.0 * s - 5.0,
        "rfemur_ry": -3.0 * c,
        "rfemur_rz": 4.0 + 2.0 * s,
        "rtibia_rx": 22.0 + 18.0 * np.cos(phase + np.pi / 3),
        "rfoot_rx": -10.0 * np.sin(phase + 0.8),
        "lowerback_rx": 4.0 + 1.0 * np.sin(2 * phase),
        "lowerback_ry": 5.0 * s,
        "lowerback_rz": 1.0 * c,
        "thorax_rx": 2.0 + 0.5 * np.sin(2 * phase),
        "thorax_ry": -4.0 * s,
        "thorax_rz": -1.0 * c,
        "head_rx": -3.0 + 1.0 * np.sin(2 * phase),
        "head_ry": 2.0 * s,
        "head_rz": 0.5 * c,
        "lhumerus_rx": 18.0 * s,
        "lhumerus_ry": 2.0 * c,
        "lhumerus_rz": 8.0,
        "lradius_rx": -20.0 + 8.0 * s,
        "rhumerus_rx": -18.0 * s,
        "rhumerus_ry": -2.0 * c,
        "rhumerus_rz": -8.0,
        "rradius_rx": -20.0 - 8.0 * s,
    }


def make_walker(n_sequences=2, n_frames=120, *, random_state=None):
    """Synthetic walking motion on a small skeleton, shaped like ``load_cmu35``.

    The raw Euler channels of a small ASF-style skeleton (see
    :func:`walker_skeleton`) swing like a walk: legs and arms in opposition,
    knees bending, the trunk twisting, the root bobbing, moving forward and
    slowly turning.  Each sequence has its own stride period (28 to 36
    frames), phase, speed, turning rate, start heading and start position,
    and a little noise (0.3 degrees) on the joint angles.

    Parameters
    ----------
    n_sequences : int, default=2
        Number of sequences.
    n_frames : int, default=120
        Frames per sequence (at 30 Hz).
    random_state : int, RandomState instance or None, default=None
        Seed.

    Returns
    -------
    walker : :class:`~sklearn.utils.Bunch`
        With ``data`` (n_sequences * n_frames, 33), ``sequence_ids``,
        ``sequence_names``, ``motion`` (all ``"walk"``), ``feature_names``,
        ``skeleton``, ``frame_rate`` (30.0) and ``DESCR``.

    Examples
    --------
    >>> from sklearn_crbm.datasets import make_walker
    >>> walker = make_walker(n_sequences=2, n_frames=40, random_state=0)
    >>> walker.data.shape
    (80, 33)
    >>> walker.sequence_names
    array(['walk_0', 'walk_1'], dtype=object)
    >>> positions = walker.skeleton.forward_kinematics(walker.data)
    >>> positions.shape
    (80, 18, 3)
    """
    n_sequences = _check_count(n_sequences, "n_sequences")
    n_frames = _check_count(n_frames, "n_frames")
    rng = check_random_state(random_state)
    skeleton = walker_skeleton()
    names = skeleton.feature_names
    is_angle = np.array([not n.startswith("root_t") for n in names])
    t = np.arange(n_frames, dtype=np.float64)
    blocks = []
    for _ in range(n_sequences):
        params = {
            "heading": rng.uniform(-180.0, 180.0),
            "turn": rng.uniform(-0.3, 0.3),
            "speed": rng.uniform(0.5, 0.7),
            "x0": rng.uniform(-10.0, 10.0),
            "z0": rng.uniform(-10.0, 10.0),
        }
        phase = 2.0 * np.pi * t / rng.uniform(28.0, 36.0) + rng.uniform(
            0.0, 2.0 * np.pi
        )
        channels = _walk_channels(phase, t, params)
        block = np.column_stack([np.broadcast_to(channels[n], t.shape) for n in names])
        block[:, is_angle] += 0.3 * rng.standard_normal((n_frames, is_angle.sum()))
        blocks.append(block)
    return Bunch(
        data=np.concatenate(blocks),
        sequence_ids=np.repeat(np.arange(n_sequences), n_frames),
        sequence_names=np.array(
            [f"walk_{i}" for i in range(n_sequences)], dtype=object
        ),
        motion=np.array(["walk"] * n_sequences, dtype=object),
        feature_names=names,
        skeleton=skeleton,
        frame_rate=FRAME_RATE,
        DESCR=_WALKER_DESCR,
    )


_WALKER_DESCR = """\
Synthetic walker
----------------

Raw Euler channels (degrees; root translation in ASF-like length units) of an
18-bone ASF-style skeleton (y up, facing +z), swinging like a walk at 30 Hz,
made by :func:`sklearn_crbm.datasets.make_walker`.  For tests and examples
only: it has the layout of ``load_cmu35`` but none of the richness of real
motion capture.
"""
