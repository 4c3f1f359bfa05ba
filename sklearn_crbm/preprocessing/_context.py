"""Per-frame control signals from motion: forward speed, turning rate."""

from numbers import Real

import numpy as np
from sklearn.base import BaseEstimator, TransformerMixin, _fit_context
from sklearn.utils._param_validation import Interval, StrOptions
from sklearn.utils.validation import (
    _check_feature_names_in,
    check_is_fitted,
    validate_data,
)

from ..metrics._generation import frame_forward_speed
from ..utils._persistence import VersionedPickleMixin
from ..utils._sequences import check_sequence_ids
from ._expmap import ExpMapEncoder
from ._layout import input_names, moving_root, skeleton_feature_names
from ._root import RootRelativeEncoder

__all__ = ["MotionContext"]

# Each signal: the RootRelativeEncoder delta it is the rate of.
_SIGNALS = {
    "forward_speed": "dforward",
    "turning_rate": "dheading",
    "sideways_speed": "dsideways",
}
# Column of each delta in a plain array of deltas.
_DELTA_COLUMNS = {"dforward": 0, "dheading": 1, "dsideways": 2}
_ROOT_CHANNELS = ("tx", "ty", "tz", "ex", "ey", "ez")


def centred_moving_average(values, sequences, half_width):
    """Mean of ``values`` over ``2 * half_width + 1`` frames centred on each frame.

    The window never crosses a sequence boundary: near the ends of a
    sequence it is cut to the frames inside it (and the mean taken over
    those), so a constant stays constant and a linear ramp stays exact away
    from the ends.

    Parameters
    ----------
    values : ndarray of shape (n_frames, n_columns)
    sequences : Sequences
        From :func:`~sklearn_crbm.utils.check_sequence_ids`.
    half_width : int
        Frames on each side; 0 returns a copy.

    Returns
    -------
    smoothed : ndarray of shape (n_frames, n_columns)
    """
    smoothed = np.empty_like(values)
    for start, stop in zip(sequences.starts, sequences.stops, strict=True):
        n = stop - start
        sums = np.zeros((n + 1, values.shape[1]))
        np.cumsum(values[start:stop], axis=0, out=sums[1:])
        frame = np.arange(n)
        low = np.maximum(frame - half_width, 0)
        high = np.minimum(frame + half_width + 1, n)
        smoothed[start:stop] = (sums[high] - sums[low]) / (high - low)[:, None]
    return smoothed


class MotionContext(VersionedPickleMixin, TransformerMixin, BaseEstimator):
    """Control signals of every frame: forward speed and turning rate.

    Derives, frame by frame, how fast the body moves forward, sideways and
    how fast it turns, smoothed over a window of ``window`` seconds: the
    real-valued control signals (the per-frame *context*) a generative
    motion model can be trained on and steered by (Taylor, Hinton & Roweis,
    2011, conditioned on speed and stride this way).  The signals are the
    rates of :class:`RootRelativeEncoder`'s per-frame deltas:

    ``forward_speed``
        ``{root}_dforward * frame_rate``: ground distance along the body's
        heading per second, in the length units of the data (ASF or BVH
        units for raw channels).
    ``turning_rate``
        ``{root}_dheading * frame_rate``: change of heading, radians per
        second, positive when the body turns to its left (about the up
        axis).
    ``sideways_speed``
        ``{root}_dsideways * frame_rate``: ground distance to the body's
        right per second.

    Each signal is the mean over a centred window of ``2 * round(window *
    frame_rate / 2) + 1`` frames (31 for one second at 30 fps), cut to the
    frames of the frame's own sequence near its ends: the window never
    crosses a sequence boundary (see ``sequence_ids``).  One row comes out
    per frame; the last frame of each sequence has the deltas of the frame
    before (as in :class:`RootRelativeEncoder`).

    The input is one of:

    - raw channels, with ``skeleton``: the skeleton's channels (a plain
      array in the order of ``skeleton.feature_names``, or a DataFrame with
      those names) as :func:`~sklearn_crbm.datasets.load_cmu35` and the file
      readers give them; :class:`ExpMapEncoder` and
      :class:`RootRelativeEncoder` derive the deltas from the root's
      position and Euler angles;
    - the output of :class:`RootRelativeEncoder`, before any scaling, as a
      DataFrame with its column names (``"{root}_dforward"``, ...; e.g. the
      first two steps of :func:`make_motion_preprocessor` with
      ``set_output(transform="pandas")``);
    - a plain array of the deltas themselves, without a skeleton: column 0
      ``dforward``, column 1 ``dheading``, column 2 ``dsideways`` (as many
      as ``signals`` needs; later columns are ignored).

    Parameters
    ----------
    skeleton : Skeleton or None, default=None
        The skeleton of raw channels: a plain array must then hold exactly
        ``skeleton.feature_names``, in order.  Also gives the up axis and
        the angle unit.
    signals : list of str, default=("forward_speed", "turning_rate")
        The output columns, in order, from ``"forward_speed"``,
        ``"turning_rate"`` and ``"sideways_speed"``.
    window : float, default=1.0
        Smoothing window in seconds; 0 leaves every frame's rate as it is.
    frame_rate : float, default=30.0
        Frames per second of ``X`` (``load_cmu35().frame_rate``).
    up_axis : {"x", "y", "z"} or None, default=None
        Vertical axis of raw channels; None takes the skeleton's (``"y"``
        without one).  See :class:`RootRelativeEncoder`.
    root : str or None, default=None
        Name of the root bone in the feature names; None finds it as
        :class:`RootRelativeEncoder` does (for the encoder's output: the one
        feature named ``"{root}_dforward"``).
    angle_unit : {"deg", "rad"} or None, default=None
        Unit of raw Euler channels; None takes ``skeleton.angle_unit``
        (degrees without one).

    Attributes
    ----------
    source_ : {"raw", "root_relative", "deltas"}
        What the input was taken to be (see above).
    root_ : str or None
        The root bone whose motion is measured (None for plain deltas).
    window_frames_ : int
        Frames in each smoothing window.
    n_features_in_ : int
        Number of features seen during :term:`fit`.
    feature_names_in_ : ndarray of shape (`n_features_in_`,)
        Names of features seen during :term:`fit`. Defined only when `X`
        has feature names that are all strings.

    See Also
    --------
    RootRelativeEncoder : The per-frame deltas these signals are rates of.
    sklearn_crbm.metrics.forward_speed : Mean forward displacement of each sequence.

    Notes
    -----
    The signals describe the frames' own motion, so the centred window
    looks half a window ahead: that is right for labelling training frames
    with what they do, and a model steered by a requested signal at
    generation time is given that signal directly.

    References
    ----------
    .. [1] G. W. Taylor, G. E. Hinton and S. T. Roweis, "Two Distributed-State
       Models For Generating High-Dimensional Time Series", JMLR 12, 2011.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.datasets import make_walker
    >>> from sklearn_crbm.preprocessing import MotionContext
    >>> walker = make_walker(n_sequences=2, n_frames=90, random_state=0)
    >>> context = MotionContext(walker.skeleton, frame_rate=walker.frame_rate)
    >>> C = context.fit_transform(walker.data, sequence_ids=walker.sequence_ids)
    >>> C.shape
    (180, 2)
    >>> context.get_feature_names_out()
    array(['forward_speed', 'turning_rate'], dtype=object)

    A body that moves 0.5 units forward and turns 0.01 radians left per
    frame, at 30 frames per second, given as plain deltas:

    >>> deltas = np.tile([0.5, 0.01], (20, 1))
    >>> MotionContext().fit_transform(deltas)[:2]
    array([[15. ,  0.3],
           [15. ,  0.3]])

    The control signals of CMU subject 35's walks and jogs, to train a model
    on ``(cmu.data, context)`` (inside a Pipeline, with
    ``sklearn.set_config(enable_metadata_routing=True)``, ``sequence_ids``
    reaches it like the other sequence-aware steps):

    >>> from sklearn_crbm.datasets import load_cmu35
    >>> cmu = load_cmu35(subset="train")  # doctest: +SKIP
    >>> speed = MotionContext(cmu.skeleton)  # doctest: +SKIP
    >>> context = speed.fit_transform(
    ...     cmu.data, sequence_ids=cmu.sequence_ids
    ... )  # doctest: +SKIP
    """

    __metadata_request__fit = {"sequence_ids": True}
    __metadata_request__transform = {"sequence_ids": True}

    _parameter_constraints: dict = {
        "skeleton": "no_validation",
        "signals": [list, tuple],
        "window": [Interval(Real, 0, None, closed="left")],
        "frame_rate": [Interval(Real, 0, None, closed="neither")],
        "up_axis": [StrOptions({"x", "y", "z"}), None],
        "root": [str, None],
        "angle_unit": [StrOptions({"deg", "rad"}), None],
    }

    def __init__(
        self,
        skeleton=None,
        *,
        signals=("forward_speed", "turning_rate"),
        window=1.0,
        frame_rate=30.0,
        up_axis=None,
        root=None,
        angle_unit=None,
    ):
        self.skeleton = skeleton
        self.signals = signals
        self.window = window
        self.frame_rate = frame_rate
        self.up_axis = up_axis
        self.root = root
        self.angle_unit = angle_unit

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None, *, sequence_ids=None):
        """Locate the channels the signals are measured from.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Raw channels, :class:`RootRelativeEncoder` output, or deltas
            (see the class).
        y : None
            Ignored.
        sequence_ids : array-like of shape (n_frames,), default=None
            Accepted for a uniform interface (and checked); nothing is
            learned from the values.

        Returns
        -------
        self : MotionContext
            The fitted transformer.
        """
        deltas = self._check_signals()
        X = validate_data(self, X, dtype=np.float64)
        check_sequence_ids(sequence_ids, X.shape[0])
        names = input_names(
            self,
            X.shape[1],
            skeleton_feature_names,
            "the skeleton has {} channels (skeleton.feature_names)",
        )
        if names is None:
            self._fit_plain_deltas(X, deltas)
        elif self.skeleton is None and _dforward_root(names, self.root) is not None:
            self._fit_root_relative(names, deltas)
        else:
            self._fit_raw(X, names, deltas)
        half = round(self.window * self.frame_rate / 2)
        self.window_frames_ = 2 * half + 1
        return self

    def _check_signals(self):
        """The deltas the signals are rates of, or a ValueError."""
        signals = [str(s) for s in self.signals]
        unknown = [s for s in signals if s not in _SIGNALS]
        if unknown or not signals or len(set(signals)) < len(signals):
            raise ValueError(
                f"signals must name distinct signals from {list(_SIGNALS)}, got "
                f"{list(self.signals)}."
            )
        return [_SIGNALS[s] for s in signals]

    def _fit_plain_deltas(self, X, deltas):
        columns = [_DELTA_COLUMNS[d] for d in deltas]
        if X.shape[1] <= max(columns):
            raise ValueError(
                f"X has {X.shape[1]} feature(s), but a plain array without a "
                f"skeleton holds the deltas dforward, dheading, dsideways in its "
                f"first columns and signals={list(self.signals)} needs "
                f"{max(columns) + 1} of them. Pass skeleton= for raw channels, or "
                "a DataFrame with RootRelativeEncoder's column names."
            )
        self.source_, self.root_ = "deltas", None
        self._delta_columns = columns

    def _fit_root_relative(self, names, deltas):
        root = _dforward_root(names, self.root)
        columns, missing = _find(names, [f"{root}_{d}" for d in deltas])
        if missing:
            raise ValueError(
                f"X lacks the columns {missing} that signals="
                f"{list(self.signals)} are measured from (RootRelativeEncoder's "
                "output; a root without rotation channels has no dheading)."
            )
        self.source_, self.root_ = "root_relative", root
        self._delta_columns = columns

    def _fit_raw(self, X, names, deltas):
        if self.skeleton is None:
            raise ValueError(
                "X has no column named '{root}_dforward' (RootRelativeEncoder's "
                "output): for raw channels pass skeleton= (e.g. "
                "load_cmu35().skeleton), which says how the root's Euler angles "
                "compose."
            )
        channels = skeleton_feature_names(self.skeleton)
        self._raw_columns, missing = _find(names, channels)
        if missing:
            raise ValueError(
                f"X lacks the skeleton's channels {missing[:5]}"
                f"{' ...' if len(missing) > 5 else ''}: raw channels must hold "
                "every channel of skeleton.feature_names."
            )
        X = X[:, self._raw_columns]
        angle_unit = self.angle_unit or getattr(self.skeleton, "angle_unit", None)
        self._expmap = ExpMapEncoder(self.skeleton, angle_unit=angle_unit or "deg")
        encoded_names = self._expmap.fit(X).get_feature_names_out()
        root = self.root or moving_root(channels, X, self.skeleton)
        wanted = [f"{root}_{c}" for c in _ROOT_CHANNELS]
        self._root_columns, missing = _find(encoded_names, wanted)
        if missing:
            raise ValueError(
                f"The skeleton's root {root!r} lacks the channels {missing} (after "
                "ExpMapEncoder): its motion needs tx, ty, tz and rx, ry, rz. Pass "
                "root= to name another bone."
            )
        up_axis = self.up_axis or getattr(self.skeleton, "up_axis", None) or "y"
        self._root_encoder = RootRelativeEncoder(up_axis=up_axis).fit(
            self._expmap.transform(X)[:, self._root_columns]
        )
        encoded = [str(n) for n in self._root_encoder.get_feature_names_out()]
        self._delta_columns = [encoded.index(f"root_{d}") for d in deltas]
        self.source_, self.root_ = "raw", root

    def fit_transform(self, X, y=None, *, sequence_ids=None):
        """Fit to ``X`` and return its control signals; see :meth:`transform`.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Raw channels, :class:`RootRelativeEncoder` output, or deltas.
        y : None
            Ignored.
        sequence_ids : array-like of shape (n_frames,), default=None
            Sequence of each frame (``None``: one sequence).

        Returns
        -------
        context : ndarray of shape (n_frames, n_signals)
            The signals of every frame.
        """
        return self.fit(X, sequence_ids=sequence_ids).transform(
            X, sequence_ids=sequence_ids
        )

    def transform(self, X, *, sequence_ids=None):
        """The smoothed control signals of every frame.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            In the layout seen in :meth:`fit`.
        sequence_ids : array-like of shape (n_frames,), default=None
            Sequence of each frame (``None``: one sequence).  Neither the
            deltas nor the smoothing cross a sequence boundary.

        Returns
        -------
        context : ndarray of shape (n_frames, n_signals)
            Columns as given by :meth:`get_feature_names_out`: length units
            per second and radians per second.
        """
        check_is_fitted(self)
        X = validate_data(self, X, reset=False, dtype=np.float64)
        sequences = check_sequence_ids(sequence_ids, X.shape[0])
        if self.source_ == "raw":
            raw = X[:, self._raw_columns]
            root = self._expmap.transform(raw)[:, self._root_columns]
            X = self._root_encoder.transform(root, sequence_ids=sequence_ids)
        per_frame = [
            frame_forward_speed(X, column)
            if signal == "forward_speed"
            else X[:, column]
            for signal, column in zip(self.signals, self._delta_columns, strict=True)
        ]
        rates = np.stack(per_frame, axis=1) * self.frame_rate
        return centred_moving_average(rates, sequences, self.window_frames_ // 2)

    def get_feature_names_out(self, input_features=None):
        """Output feature names: the signals.

        Parameters
        ----------
        input_features : array-like of str or None, default=None
            Input feature names; must match ``feature_names_in_`` if that is
            defined.

        Returns
        -------
        feature_names_out : ndarray of str objects
            ``signals``, in order.
        """
        check_is_fitted(self)
        _check_feature_names_in(self, input_features)
        return np.asarray([str(s) for s in self.signals], dtype=object)

    def __sklearn_is_fitted__(self):
        # set last by fit: a fit that failed half-way leaves it unfitted
        return hasattr(self, "window_frames_")


def _find(names, wanted):
    """The column of each of ``wanted`` in ``names``, and those not there."""
    position = {str(n): j for j, n in enumerate(names)}
    missing = [str(w) for w in wanted if str(w) not in position]
    return [position[str(w)] for w in wanted if str(w) in position], missing


def _dforward_root(names, root):
    """The root whose ``"{root}_dforward"`` is among ``names``, or None."""
    if root is not None:
        return root if f"{root}_dforward" in {str(n) for n in names} else None
    found = [str(n)[: -len("_dforward")] for n in names if str(n).endswith("_dforward")]
    if len(found) > 1:
        raise ValueError(
            f"X has {len(found)} features named '{{root}}_dforward' "
            f"({[f + '_dforward' for f in found]}); pass root= to choose one."
        )
    return found[0] if found else None
