"""A style judge: the style of each window of motion, and whether it moves like it."""

from numbers import Integral, Real

import numpy as np
from sklearn.base import BaseEstimator, ClassifierMixin, _fit_context
from sklearn.linear_model import LogisticRegression
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler
from sklearn.utils import Bunch
from sklearn.utils._param_validation import Interval
from sklearn.utils.multiclass import check_classification_targets
from sklearn.utils.validation import (
    check_is_fitted,
    column_or_1d,
    validate_data,
)

from ..utils._sequences import check_sequence_ids
from ._generation import motion_amplitude, step_frequency

__all__ = ["StyleJudge"]

# Windows whose features are computed at once: bounds the memory of the
# (windows, frames, channels) block.
_WINDOW_CHUNK = 512


class StyleJudge(ClassifierMixin, BaseEstimator):
    """Judge the style of motion window by window, and whether it is alive.

    A classifier of real labelled motion for judging generated motion.  Each
    sequence is cut into windows of ``window`` frames every ``stride``
    frames (and one more that ends with the sequence).  Each window is
    described by every channel's mean, standard deviation and the log
    energies of its spectrum in octave bands (bins 1, 2-3, 4-7, ... of the
    window's tapered Fourier transform), and a logistic regression on the
    standardised descriptions gives the probability of each style.

    A classifier of windows names a style even for motion that is no
    walk at all: a sequence frozen in a pose is given the style it looks
    nearest to, often with probability near 1.  So the judge also measures
    every window's liveliness against the real windows of a style: the
    amplitude of the ``legs`` channels (:func:`motion_amplitude`) and their
    dominant frequency, the gait cycle (:func:`step_frequency`), each as a
    ratio to that style's median real window.  :meth:`verdict` accepts a
    window when it is judged as the style asked for *and* both ratios are
    within their tolerances.

    Parameters
    ----------
    window : int, default=60
        Frames per window (60 is 2 seconds at 30 frames per second).
    stride : int, default=15
        Frames between the starts of successive windows; at most
        ``window``, so that every frame is in a window.
    C : float, default=1.0
        Inverse regularisation strength of the logistic regression.
    legs : array-like of int, default=None
        Column indices of the channels whose amplitude and frequency tell a
        walk from a frozen pose (the hips and knees; see
        :func:`~sklearn_crbm.datasets.bone_columns`).  ``None`` means every
        channel.
    amplitude_tolerance : float, default=0.25
        Largest relative difference of a window's leg amplitude from the
        style's for the window to count as alive.
    frequency_tolerance : float, default=0.15
        Largest relative difference of a window's step frequency from the
        style's for the window to count as alive.
    max_iter : int, default=1000
        Iterations of the logistic regression's solver.

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,)
        The styles.
    classifier_ : :class:`~sklearn.pipeline.Pipeline`
        The standard scaler and the logistic regression, fitted on the
        training windows' descriptions.
    reference_amplitude_ : ndarray of shape (n_classes,)
        Median leg amplitude of each style's training windows.
    reference_frequency_ : ndarray of shape (n_classes,)
        Median step frequency of each style's training windows, in cycles
        per frame.
    n_windows_ : int
        Number of training windows.
    n_iter_ : int
        Iterations the logistic regression's solver ran.
    n_features_in_ : int
        Number of channels seen during :meth:`fit`.
    feature_names_in_ : ndarray of shape (`n_features_in_`,)
        Names of the channels seen during :meth:`fit`, when ``X`` has
        column names that are all strings.

    See Also
    --------
    sklearn_crbm.metrics.gait_statistics : Forward speed and gait frequency
        of whole sequences.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.metrics import StyleJudge
    >>> t = np.arange(240)[:, None]
    >>> slow, fast = np.sin(2 * np.pi * t / 30), np.sin(2 * np.pi * t / 20)
    >>> X = np.vstack([slow, fast])
    >>> y = np.repeat(["slow", "fast"], 240)
    >>> ids = np.repeat([0, 1], 240)
    >>> judge = StyleJudge(window=60, stride=30).fit(X, y, sequence_ids=ids)
    >>> judge.predict(X, sequence_ids=ids, per="sequence")
    array(['slow', 'fast'], dtype='<U4')
    >>> judge.score(X, y, sequence_ids=ids)
    1.0
    >>> frozen = np.zeros((120, 1))
    >>> bool(judge.verdict(frozen, "slow").alive.any())
    False
    """

    _parameter_constraints: dict = {
        "window": [Interval(Integral, 1, None, closed="left")],
        "stride": [Interval(Integral, 1, None, closed="left")],
        "C": [Interval(Real, 0, None, closed="neither")],
        "legs": ["array-like", None],
        "amplitude_tolerance": [Interval(Real, 0, None, closed="left")],
        "frequency_tolerance": [Interval(Real, 0, None, closed="left")],
        "max_iter": [Interval(Integral, 1, None, closed="left")],
    }

    def __init__(
        self,
        *,
        window=60,
        stride=15,
        C=1.0,
        legs=None,
        amplitude_tolerance=0.25,
        frequency_tolerance=0.15,
        max_iter=1000,
    ):
        self.window = window
        self.stride = stride
        self.C = C
        self.legs = legs
        self.amplitude_tolerance = amplitude_tolerance
        self.frequency_tolerance = frequency_tolerance
        self.max_iter = max_iter

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y, *, sequence_ids=None):
        """Learn the styles from labelled real motion.

        Windows whose frames carry more than one label (they straddle a
        change of style) are left out.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Real motion, all sequences stacked in long format.
        y : array-like of shape (n_frames,)
            The style of every frame.
        sequence_ids : array-like of shape (n_frames,), default=None
            Sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        self : StyleJudge
            The fitted judge.
        """
        if self.stride > self.window:
            raise ValueError(
                f"stride={self.stride} is larger than window={self.window}: frames "
                "between windows would not be judged. Use stride <= window."
            )
        X, y = validate_data(self, X, y, dtype=np.float64)
        check_classification_targets(y)
        self.classes_, codes = np.unique(y, return_inverse=True)
        if len(self.classes_) < 2:
            raise ValueError(
                f"StyleJudge tells styles apart, but y has only one class "
                f"({self.classes_[0]!r}); give motion of at least two styles."
            )
        self._check_legs()
        starts, _ = self._windows(check_sequence_ids(sequence_ids, len(X)))
        starts, window_codes = self._labelled_windows(starts, codes)
        missing = np.setdiff1d(np.arange(len(self.classes_)), window_codes)
        if missing.size:
            raise ValueError(
                f"No window of {self.window} frames within one sequence has only "
                f"the label(s) {self.classes_[missing].tolist()}: give longer "
                "sequences of them, or a smaller window."
            )
        self.classifier_ = make_pipeline(
            StandardScaler(), LogisticRegression(C=self.C, max_iter=self.max_iter)
        ).fit(self._describe(X, starts), window_codes)
        self.n_iter_ = int(self.classifier_[-1].n_iter_.max())
        amplitude, frequency = self._amplitude_and_frequency(X, starts)
        self.reference_amplitude_ = np.array(
            [np.median(amplitude[window_codes == k]) for k in range(len(self.classes_))]
        )
        self.reference_frequency_ = np.array(
            [
                _nanmedian(frequency[window_codes == k])
                for k in range(len(self.classes_))
            ]
        )
        self.n_windows_ = len(starts)
        return self

    def predict_proba(self, X, *, sequence_ids=None, per="frame"):
        """Probability of each style, per frame, window or sequence.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Motion, all sequences stacked in long format; every sequence at
            least ``window`` frames long.
        sequence_ids : array-like of shape (n_frames,), default=None
            Sequence id of every frame; ``None`` means one sequence.
        per : {"frame", "window", "sequence"}, default="frame"
            ``"frame"``: one row per row of ``X``, the mean over the windows
            that hold the frame; ``"window"``: one row per window, in the
            order of :meth:`verdict`; ``"sequence"``: one row per sequence
            in order of appearance, the mean over its windows.

        Returns
        -------
        proba : ndarray of shape (n_frames, n_classes), (n_windows, n_classes) \
or (n_sequences, n_classes)
            Columns in the order of :attr:`classes_`.
        """
        if per not in ("frame", "window", "sequence"):
            raise ValueError(
                f"per must be 'frame', 'window' or 'sequence', got {per!r}."
            )
        check_is_fitted(self)
        X = validate_data(self, X, dtype=np.float64, reset=False)
        sequences = check_sequence_ids(sequence_ids, len(X))
        starts, window_sequence = self._windows(sequences)
        proba = self.classifier_.predict_proba(self._describe(X, starts))
        if per == "window":
            return proba
        if per == "sequence":
            return _group_means(proba, window_sequence, sequences.n_sequences)
        return self._frame_means(proba, starts, X.shape[0])

    def predict(self, X, *, sequence_ids=None, per="frame"):
        """The most probable style, per frame, window or sequence.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Motion, all sequences stacked in long format.
        sequence_ids : array-like of shape (n_frames,), default=None
            Sequence id of every frame; ``None`` means one sequence.
        per : {"frame", "window", "sequence"}, default="frame"
            See :meth:`predict_proba`.

        Returns
        -------
        styles : ndarray of shape (n_frames,), (n_windows,) or (n_sequences,)
            Elements of :attr:`classes_`.
        """
        proba = self.predict_proba(X, sequence_ids=sequence_ids, per=per)
        return self.classes_[np.argmax(proba, axis=1)]

    def score(self, X, y, *, sequence_ids=None, sample_weight=None):
        """Fraction of windows judged as the style of their frames.

        Windows whose frames carry more than one label are left out.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Motion, all sequences stacked in long format.
        y : array-like of shape (n_frames,)
            The true style of every frame.
        sequence_ids : array-like of shape (n_frames,), default=None
            Sequence id of every frame; ``None`` means one sequence.
        sample_weight : None
            Not supported (windows, not frames, are counted); must be None.

        Returns
        -------
        score : float
            Accuracy over the windows.
        """
        if sample_weight is not None:
            raise ValueError(
                "StyleJudge.score counts windows; sample_weight is not supported."
            )
        check_is_fitted(self)
        X = validate_data(self, X, dtype=np.float64, reset=False)
        y = column_or_1d(y, warn=True)
        if y.shape[0] != X.shape[0]:
            raise ValueError(
                f"y has {y.shape[0]} labels but X has {X.shape[0]} frames; give "
                "one label per frame."
            )
        _, codes = np.unique(y, return_inverse=True)
        starts, _ = self._windows(check_sequence_ids(sequence_ids, len(X)))
        starts, _ = self._labelled_windows(starts, codes)
        if len(starts) == 0:
            raise ValueError(
                "No window has one label for all its frames: nothing to score."
            )
        predicted = self.classes_[
            np.argmax(self.classifier_.predict_proba(self._describe(X, starts)), axis=1)
        ]
        return float(np.mean(predicted == y[starts]))

    def verdict(self, X, style=None, *, sequence_ids=None):
        """Judge every window: its style, its liveliness, and both together.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Motion, for example generated, all sequences stacked in long
            format; every sequence at least ``window`` frames long.
        style : label or array-like of shape (n_frames,), default=None
            The style asked for: one of :attr:`classes_` for every frame, or
            one per frame (a transition), in which case a window is asked
            for the style of its last frame.  ``None`` judges liveliness
            against the style each window is judged as.
        sequence_ids : array-like of shape (n_frames,), default=None
            Sequence id of every frame; ``None`` means one sequence.

        Returns
        -------
        verdict : :class:`~sklearn.utils.Bunch`
            One entry per window, sequence by sequence, earliest first:

            sequence_ids : ndarray of shape (n_windows,)
                The id of the window's sequence.
            starts : ndarray of shape (n_windows,)
                The window's first frame, counted from the start of its
                sequence.
            proba : ndarray of shape (n_windows, n_classes)
                Probability of each style.
            predicted : ndarray of shape (n_windows,)
                The style the window is judged as.
            requested : ndarray of shape (n_windows,)
                The style asked for (``predicted`` when ``style`` is None).
            amplitude_ratio : ndarray of shape (n_windows,)
                Leg amplitude over the requested style's
                (:attr:`reference_amplitude_`).
            frequency_ratio : ndarray of shape (n_windows,)
                Step frequency over the requested style's
                (:attr:`reference_frequency_`); ``nan`` for a window
                without motion.
            correct : ndarray of bool
                Judged as the requested style.
            alive : ndarray of bool
                Both ratios within ``1 +- amplitude_tolerance`` and
                ``1 +- frequency_tolerance``.
            accepted : ndarray of bool
                ``correct & alive``: judged as the style and alive.
        """
        check_is_fitted(self)
        X = validate_data(self, X, dtype=np.float64, reset=False)
        sequences = check_sequence_ids(sequence_ids, X.shape[0])
        starts, window_sequence = self._windows(sequences)
        proba = self.classifier_.predict_proba(self._describe(X, starts))
        predicted = np.argmax(proba, axis=1)
        if style is None:
            requested = predicted
        else:
            requested = self._style_codes(style, X.shape[0])[starts + self.window - 1]
        amplitude, frequency = self._amplitude_and_frequency(X, starts)
        with np.errstate(divide="ignore", invalid="ignore"):
            amplitude_ratio = amplitude / self.reference_amplitude_[requested]
            frequency_ratio = frequency / self.reference_frequency_[requested]
        alive = (np.abs(amplitude_ratio - 1) <= self.amplitude_tolerance) & (
            np.abs(frequency_ratio - 1) <= self.frequency_tolerance
        )
        correct = predicted == requested
        return Bunch(
            sequence_ids=sequences.ids[window_sequence],
            starts=starts - sequences.starts[window_sequence],
            proba=proba,
            predicted=self.classes_[predicted],
            requested=self.classes_[requested],
            amplitude_ratio=amplitude_ratio,
            frequency_ratio=frequency_ratio,
            correct=correct,
            alive=alive,
            accepted=correct & alive,
        )

    # ------------------------------------------------------------- helpers

    def _windows(self, sequences):
        """First frame (row of ``X``) and sequence index of every window."""
        short = sequences.lengths < self.window
        if short.any():
            k = int(np.flatnonzero(short)[0])
            name = sequences.ids[k].item()
            raise ValueError(
                f"Sequence {name!r} has {sequences.lengths[k]} frames, "
                f"fewer than a window of {self.window}: give longer sequences or "
                "a smaller window."
            )
        starts, owners = [], []
        for k, (start, length) in enumerate(
            zip(sequences.starts, sequences.lengths, strict=True)
        ):
            last = length - self.window
            offsets = np.arange(0, last + 1, self.stride)
            if offsets[-1] != last:
                offsets = np.append(offsets, last)
            starts.append(start + offsets)
            owners.append(np.full(len(offsets), k))
        return np.concatenate(starts), np.concatenate(owners)

    def _labelled_windows(self, starts, codes):
        """The windows whose frames all carry one label, with that label."""
        changes = np.concatenate(([0], np.cumsum(codes[1:] != codes[:-1])))
        pure = changes[starts + self.window - 1] == changes[starts]
        return starts[pure], codes[starts[pure]]

    def _describe(self, X, starts):
        """Each window's channel means, standard deviations and band energies."""
        offsets = np.arange(self.window)
        taper = np.hanning(self.window + 2)[1:-1]  # Hann without its zero ends
        bands = _octave_bands(self.window // 2 + 1)
        described = []
        for first in range(0, len(starts), _WINDOW_CHUNK):
            block = X[starts[first : first + _WINDOW_CHUNK, None] + offsets]
            mean = block.mean(axis=1)
            centred = block - mean[:, None, :]
            spectrum = np.fft.rfft(centred * taper[:, None], axis=1)
            power = np.square(np.abs(spectrum)) / np.square(taper).sum()
            energies = [np.log1p(power[:, lo:hi].mean(axis=1)) for lo, hi in bands]
            described.append(
                np.concatenate([mean, centred.std(axis=1)] + energies, axis=1)
            )
        return np.concatenate(described)

    def _check_legs(self):
        if self.legs is None:
            return
        legs = np.asarray(self.legs)
        if (
            legs.ndim != 1
            or legs.size == 0
            or legs.dtype.kind not in "iu"
            or legs.min() < 0
            or legs.max() >= self.n_features_in_
        ):
            raise ValueError(
                "legs must be column indices of X (integers in [0, "
                f"{self.n_features_in_})), at least one; got {self.legs!r}. "
                "sklearn_crbm.datasets.bone_columns finds them by bone name."
            )

    def _amplitude_and_frequency(self, X, starts):
        """Leg amplitude and step frequency (cycles per frame) of every window."""
        legs = slice(None) if self.legs is None else np.asarray(self.legs)
        frames = (starts[:, None] + np.arange(self.window)).ravel()
        windows = X[frames][:, legs]
        ids = np.repeat(np.arange(len(starts)), self.window)
        amplitude = motion_amplitude(windows, sequence_ids=ids)
        frequency = step_frequency(windows, sequence_ids=ids, frame_rate=1.0)
        return amplitude, frequency

    def _style_codes(self, style, n_frames):
        """Code of the style asked for at every frame."""
        if np.ndim(style) == 0:
            style = np.full(n_frames, style, dtype=object)
        style = np.asarray(style)
        if style.shape != (n_frames,):
            raise ValueError(
                f"style must be one label or one label per frame ({n_frames}), got "
                f"shape {style.shape}."
            )
        index = {label: code for code, label in enumerate(self.classes_.tolist())}
        unknown = [label for label in style.tolist() if label not in index]
        if unknown:
            raise ValueError(
                f"style {unknown[0]!r} is not one of the judge's styles "
                f"{self.classes_.tolist()}."
            )
        return np.array([index[label] for label in style.tolist()], dtype=np.intp)

    def _frame_means(self, proba, starts, n_frames):
        """Mean of the window rows over the windows that hold each frame."""
        frames = (starts[:, None] + np.arange(self.window)).ravel()
        return _group_means(np.repeat(proba, self.window, axis=0), frames, n_frames)

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = False
        return tags


def _octave_bands(n_bins):
    """``(lo, hi)`` bin ranges 1, 2-3, 4-7, ... of a spectrum of ``n_bins`` bins."""
    bands, low = [], 1
    while low < n_bins:
        bands.append((low, min(2 * low, n_bins)))
        low *= 2
    return bands


def _group_means(rows, groups, n_groups):
    total = np.zeros((n_groups, rows.shape[1]))
    np.add.at(total, groups, rows)
    return total / np.bincount(groups, minlength=n_groups)[:, None]


def _nanmedian(values):
    """Median of the finite values; nan when there are none (without a warning)."""
    finite = values[np.isfinite(values)]
    return float(np.median(finite)) if finite.size else np.nan
