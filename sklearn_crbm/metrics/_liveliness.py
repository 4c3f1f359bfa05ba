"""Liveliness: whether motion moves as much as real motion does.

:func:`liveliness` compares any motion with real motion, on the channels
that move most in the real one.  ``fit`` keeps
:func:`generation_statistics` of the training frames; ``sample`` judges the
last ``LIVELINESS_FRAMES`` frames of every generated sequence against them
(:func:`generated_liveliness`, :func:`lifeless_message`).
"""

from numbers import Integral

import numpy as np
from sklearn.utils import Bunch

from ..utils._array_api import to_numpy
from ._generation import (
    _check_motion,
    _check_motion_pair,
    _columns,
    _segments,
    motion_amplitude,
)

__all__ = [
    "generated_liveliness",
    "liveliness",
    "most_moving_channels",
    "generation_statistics",
    "lifeless_message",
    "merge_statistics",
    "reference_amplitude",
]

# ``sample`` judges the last frames of every generated sequence (more than a
# cycle of walking or waving at 30 frames per second) against the same
# number of frames in the middle of every training sequence: moving less than
# DEAD_FRACTION as much, it died out; beyond BLOWN_DEVIATIONS standard
# deviations of the widest channel from the training mean and BLOWN_REACH
# times as far as the channel's training frames went, it blew up (the toes
# of real walks reach 13.5 such deviations).
LIVELINESS_FRAMES = 100
DEAD_FRACTION = 0.5
BLOWN_DEVIATIONS = 10.0
BLOWN_REACH = 2.0
# Frames at a time over which fit's statistics are summed (no copy of X).
STATISTICS_CHUNK = 8192


def generation_statistics(X, sequences, labels=None):
    """What ``sample`` judges generated motion against, from the training data.

    A :class:`~sklearn.utils.Bunch`: ``mean`` (every channel's mean),
    ``scale`` (the largest channel standard deviation), ``amplitude`` (the
    :func:`~sklearn_crbm.metrics.motion_amplitude` of the middle
    ``LIVELINESS_FRAMES`` frames of every sequence, their mean weighted by
    those frames: the cycle of a take, not the rest before or after it),
    ``reach`` (every channel's largest distance from its
    mean) and ``n_frames``.  Given the frames' label weights
    ``labels`` (shape ``(n_frames, n_classes)``), also ``label_amplitude``:
    that mean for each style alone, each sequence weighted by its frames'
    weight for the style, and ``label_weight``: those weights' sums.
    """
    X = to_numpy(X)
    weights = np.minimum(sequences.lengths, LIVELINESS_FRAMES)
    # the middle frames: a take of waving raises the arms first and lowers
    # them last, and only its middle is what generation goes on with
    ends = sequences.starts + (sequences.lengths + weights) // 2
    amplitudes = _last_frames_amplitude(X, ends, weights)
    mean, scale, reach = _channel_moments(X)
    statistics = Bunch(
        mean=mean,
        scale=float(scale.max()),
        amplitude=float(np.average(amplitudes, weights=weights)),
        reach=reach,
        n_frames=X.shape[0],
    )
    if labels is not None:
        labels = to_numpy(labels)
        # each sequence's label weights summed over those frames
        sums = np.array(
            [
                np.asarray(labels[stop - n : stop], dtype=np.float64).sum(axis=0)
                for stop, n in zip(ends, weights, strict=True)
            ]
        )
        label_weight = sums.sum(axis=0)
        weighted = amplitudes @ sums
        statistics.update(
            label_amplitude=_ratio(weighted, label_weight), label_weight=label_weight
        )
    return statistics


def _last_frames_amplitude(X, stops, n_last, chunk=STATISTICS_CHUNK):
    """:func:`motion_amplitude` of the ``n_last`` frames before each stop.

    A few sequences at a time, so that at most about ``chunk`` frames are
    copied (``motion_amplitude`` works in float64).
    """
    amplitudes = []
    group_ends = np.cumsum(n_last)
    first = 0
    while first < len(stops):
        last = int(
            np.searchsorted(group_ends, group_ends[first] - n_last[first] + chunk)
        )
        last = max(last, first + 1)
        rows = np.concatenate(
            [
                np.arange(stop - n, stop)
                for stop, n in zip(stops[first:last], n_last[first:last], strict=True)
            ]
        )
        ids = np.repeat(np.arange(last - first), n_last[first:last])
        amplitudes.append(motion_amplitude(X[rows], sequence_ids=ids))
        first = last
    return np.concatenate(amplitudes)


def _channel_moments(X, chunk=STATISTICS_CHUNK):
    """Every channel's mean, standard deviation and largest distance from it.

    Bit for bit what ``X.astype(np.float64)``'s ``mean(axis=0)``,
    ``std(axis=0)`` and ``np.abs(X - mean).max(axis=0)`` give, without a
    float64 copy of the whole of ``X``.  numpy sums a contiguous column
    pairwise, so a column-ordered ``X`` (or a single channel) goes one column
    at a time; it sums the rows of a row-ordered array one after the other,
    so any other ``X`` goes ``chunk`` frames at a time, each chunk summed
    after the running total, put as its first row.
    """
    if X.shape[1] == 1 or (X.flags.f_contiguous and not X.flags.c_contiguous):
        chunk = max(X.shape[0], 1)
        columns = [X[:, [j]] for j in range(X.shape[1])]
    else:
        columns = [X]
    moments = [_row_chunk_moments(part, chunk) for part in columns]
    return tuple(np.concatenate(moment) for moment in zip(*moments, strict=True))


def _row_chunk_moments(X, chunk):
    """:func:`_channel_moments` of ``X`` summed ``chunk`` rows at a time."""

    def chunks():
        for start in range(0, X.shape[0], chunk):
            yield np.array(X[start : start + chunk], dtype=np.float64, order="C")

    def column_sum(rows_of):
        total = None
        for rows in chunks():
            rows = rows_of(rows)
            if total is not None:
                rows = np.concatenate([total[None], rows])
            total = np.add.reduce(rows, axis=0)
        return total

    n_frames = X.shape[0]
    mean = column_sum(lambda rows: rows) / n_frames
    square = column_sum(lambda rows: np.square(rows - mean, out=rows))
    reach = np.zeros_like(mean)
    for rows in chunks():
        np.maximum(reach, np.abs(rows - mean, out=rows).max(axis=0), out=reach)
    return mean, np.sqrt(square / n_frames), reach


def _ratio(numerator, denominator):
    """``numerator / denominator``, NaN where the denominator is 0."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(denominator > 0, numerator / denominator, np.nan)


def merge_statistics(old, new):
    """The :func:`generation_statistics` of two calls of ``partial_fit``, joined."""
    total = old.n_frames + new.n_frames
    share = new.n_frames / total
    mean = old.mean + share * (new.mean - old.mean)
    merged = Bunch(
        mean=mean,
        scale=max(old.scale, new.scale),
        amplitude=old.amplitude + share * (new.amplitude - old.amplitude),
        n_frames=total,
    )
    if "reach" in old and "reach" in new:  # at most this far from the new mean
        merged.reach = np.maximum(
            old.reach + np.abs(old.mean - mean), new.reach + np.abs(new.mean - mean)
        )
    if "label_amplitude" in old and "label_amplitude" in new:
        weight = old.label_weight + new.label_weight
        weighted = [
            np.nan_to_num(part.label_amplitude) * part.label_weight
            for part in (old, new)
        ]
        merged.update(
            label_amplitude=_ratio(weighted[0] + weighted[1], weight),
            label_weight=weight,
        )
    return merged


def reference_amplitude(statistics, labels=None):
    """The training amplitude a generated sequence is compared with.

    Given the label weights of its last frames (``labels``, shape
    ``(n_frames, n_classes)``) and statistics of a model fitted on labels:
    the styles' amplitudes (``label_amplitude``) weighted by the mean label
    weights of the last ``LIVELINESS_FRAMES`` frames, so that a slow style is
    judged against its own training takes; otherwise ``amplitude``.
    """
    if labels is None or "label_amplitude" not in statistics:
        return statistics.amplitude
    weights = to_numpy(labels)[-LIVELINESS_FRAMES:].mean(axis=0)
    known = np.isfinite(statistics.label_amplitude)
    if not np.any(weights[known] > 0):
        return statistics.amplitude
    return float(np.average(statistics.label_amplitude[known], weights=weights[known]))


def generated_liveliness(frames, n_frames, statistics, labels=None):
    """How much every generated sequence moves at its end, against training.

    The amplitude (:func:`~sklearn_crbm.metrics.motion_amplitude`) of the
    last ``LIVELINESS_FRAMES`` frames of every sequence of ``frames`` (long
    format, ``n_frames`` each) over :func:`reference_amplitude` (the
    training sequences', or those of the styles ``labels`` ask for): 1 moves
    as much as they do; NaN where fewer frames were generated.
    """
    n_sequences = len(frames) // n_frames
    reference = reference_amplitude(statistics, labels)
    if n_frames < LIVELINESS_FRAMES or not reference > 0:
        return np.full(n_sequences, np.nan)
    amplitude = motion_amplitude(
        np.nan_to_num(frames),  # what blew up is judged as blown, not here
        sequence_ids=np.repeat(np.arange(n_sequences), n_frames),
        last_frames=LIVELINESS_FRAMES,
    )
    return amplitude / reference


def lifeless_message(
    frames, n_frames, statistics, scale=None, labels=None, label_names=None
):
    """What went wrong with generated ``frames`` (long format), or "" if nothing.

    A sequence blew up when a value is non-finite, or more than
    ``BLOWN_DEVIATIONS`` times ``scale`` (default ``statistics.scale``) from
    the training mean and ``BLOWN_REACH`` times as far as its channel's
    training values went (``statistics.reach``, where kept);
    it died out when its :func:`generated_liveliness` (against the styles
    the label weights ``labels`` ask for, if given) is below
    ``DEAD_FRACTION`` (judged only when ``LIVELINESS_FRAMES`` frames or more
    were generated).  ``label_names`` (the model's ``classes_``) names the
    styles asked for.
    """
    sequences = frames.reshape(-1, n_frames, frames.shape[1])
    with np.errstate(invalid="ignore", over="ignore"):
        scale = statistics.scale if scale is None else scale
        distance = np.abs(sequences - statistics.mean) / scale
        distance = np.where(np.isfinite(distance), distance, np.inf)
        limit = BLOWN_DEVIATIONS
        if "reach" in statistics:
            limit = np.maximum(limit, BLOWN_REACH * statistics.reach / scale)
        over = (distance > limit).any(axis=(1, 2))
    reach = distance.max(axis=(1, 2))
    blown = np.flatnonzero(over)
    liveliness = generated_liveliness(frames, n_frames, statistics, labels)
    dead = np.setdiff1d(np.flatnonzero(liveliness < DEAD_FRACTION), blown)
    compared = "the training sequences"
    if labels is not None and "label_amplitude" in statistics:
        compared += " of the style asked for" + _styles_asked(labels, label_names)
    parts = []
    if len(blown):
        parts.append(
            f"{_count(blown, len(sequences))} blew up (values up to "
            f"{reach[blown].max():.3g} training standard deviations from the "
            "training mean, beyond where the training frames went, or "
            "non-finite). Train longer (n_iter), lower "
            "learning_rate, or seed with real frames (history=)."
        )
    if len(dead):
        parts.append(
            f"{_count(dead, len(sequences))} died out: over the last "
            f"{LIVELINESS_FRAMES} frames, moving at most "
            f"{liveliness[dead].max():.2f} times as much as {compared} "
            f"(below {DEAD_FRACTION}: the motion came to rest). "
            "Train for more updates (raise n_iter) or on more frames, or seed "
            "with real frames of the motion wanted (history=); see the user "
            "guide's 'Training on your own corpus'."
        )
    return " ".join(parts)


def _styles_asked(labels, label_names):
    """``" ('fast')"``, or ``" ('fast' 0.5, 'slow' 0.5)"`` for a blend: the
    styles of the label weights of the frames judged, with their weights;
    ``" ('run', 'elderly')"`` for the whole weight of labels of several
    factors; "" without names."""
    if label_names is None:
        return ""
    weights = to_numpy(labels)[-LIVELINESS_FRAMES:].mean(axis=0)
    asked = np.flatnonzero(weights > 0)
    asked = asked[np.argsort(-weights[asked], kind="stable")]
    names = [np.asarray(label_names)[k] for k in asked]
    names = [repr(n.item() if isinstance(n, np.generic) else n) for n in names]
    if np.allclose(weights[asked], 1):
        return f" ({', '.join(names)})"
    weighted = (f"{n} {weights[k]:.2f}" for n, k in zip(names, asked, strict=True))
    return " (" + ", ".join(weighted) + ")"


def _count(indices, n_sequences):
    """``"Sequence 2 of 3"`` or ``"Sequences 0, 2 of 3"``."""
    noun = "Sequence" if len(indices) == 1 else "Sequences"
    listed = ", ".join(str(int(k)) for k in indices[:10])
    more = ", ..." if len(indices) > 10 else ""
    return f"{noun} {listed}{more} of {n_sequences}"


def _within_sequence_std(X, sequences, columns, last_frames=None):
    """Standard deviation of every chosen column within every sequence."""
    return np.array(
        [
            segment.std(axis=0)
            for segment in _segments(X, sequences, columns, last_frames)
        ]
    ).reshape(-1, len(columns))


def most_moving_channels(
    X, *, sequence_ids=None, n_channels=12, features=None, feature_names=None
):
    """The channels that move most within the sequences of ``X``, most first.

    Channels are ranked by their standard deviation within each sequence,
    averaged over the sequences (weighted by their frames): what moves
    during a take, not what differs between takes (a posture held
    throughout one take).

    Parameters
    ----------
    X : array-like of shape (n_frames, n_features)
        Motion, all sequences stacked in long format.
    sequence_ids : array-like of shape (n_frames,), default=None
        Sequence id of every frame; ``None`` means one sequence.
    n_channels : int, default=12
        How many channels (fewer if fewer are chosen from).
    features : list of str or int, default=None
        The channels to choose from, by name or column index (for example
        the joint angles alone, in one unit); ``None`` means all.
    feature_names : array-like of str, default=None
        Names of the columns of ``X``; default the columns of a DataFrame.

    Returns
    -------
    columns : ndarray of int of shape (n_channels,)
        Column indices into ``X``, the most moving first.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.metrics import most_moving_channels
    >>> t = np.arange(100)
    >>> X = np.column_stack([np.sin(t / 5), 3 * np.sin(t / 5), np.ones(100)])
    >>> most_moving_channels(X, n_channels=2)
    array([1, 0])
    """
    if isinstance(n_channels, bool) or not isinstance(n_channels, Integral):
        raise ValueError(f"n_channels must be a positive integer, got {n_channels!r}.")
    if n_channels < 1:
        raise ValueError(f"n_channels must be a positive integer, got {n_channels!r}.")
    X, sequences, names = _check_motion(X, sequence_ids, feature_names)
    columns = _columns(features, names, X.shape[1])
    spread = np.average(
        _within_sequence_std(X, sequences, columns), axis=0, weights=sequences.lengths
    )
    order = np.argsort(-spread, kind="stable")
    return columns[order[:n_channels]]


def liveliness(
    X,
    X_reference,
    *,
    sequence_ids=None,
    reference_sequence_ids=None,
    n_channels=12,
    features=None,
    feature_names=None,
    last_frames=None,
):
    """How much each sequence moves, as a fraction of how much real motion does.

    The ``n_channels`` channels that move most in the reference motion
    (:func:`most_moving_channels`) are the ones judged.  A sequence's
    liveliness is the mean, over those channels, of its standard deviation
    over its frames (only the last ``last_frames``, where given), divided
    by the same mean for the reference sequences (their within-sequence
    standard deviations, averaged weighted by frames).  1 is as lively as
    the reference; generated motion that dies out into a pose goes to 0.
    Compare in units where the channels are alike (for example the joint
    angles of the exponential maps, in radians, before standard scaling).

    Parameters
    ----------
    X : array-like of shape (n_frames, n_features)
        The motion to judge (for example generated), sequences stacked.
    X_reference : array-like of shape (n_reference_frames, n_features)
        Real motion in the same representation (for example the training
        takes).
    sequence_ids : array-like of shape (n_frames,), default=None
        Sequence id of every frame of ``X``; ``None`` means one sequence.
    reference_sequence_ids : array-like of shape (n_reference_frames,), default=None
        Sequence id of every frame of ``X_reference``.
    n_channels : int, default=12
        How many of the most moving channels are judged.
    features : list of str or int, default=None
        The channels to choose from, by name or column index; ``None``
        means all.
    feature_names : array-like of str, default=None
        Names of the columns of both arrays; default the columns of ``X``
        if it is a DataFrame.
    last_frames : int, default=None
        Judge only the last ``last_frames`` frames of each sequence of ``X``.

    Returns
    -------
    liveliness : ndarray of shape (n_sequences,)
        Non-negative; 1 is as lively as the reference.

    See Also
    --------
    motion_amplitude : The amplitude of chosen channels, in their units.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.metrics import liveliness
    >>> t = np.arange(200)
    >>> real = np.column_stack([np.sin(t / 5), np.cos(t / 5)])
    >>> fading = real * np.exp(-t / 50)[:, None]
    >>> liveliness(np.vstack([real, fading]), real, n_channels=2,
    ...            sequence_ids=np.repeat([0, 1], 200), last_frames=100).round(2)
    array([1.  , 0.07])
    """
    X, sequences, names, X_reference, reference = _check_motion_pair(
        X, X_reference, sequence_ids, reference_sequence_ids, feature_names
    )
    columns = most_moving_channels(
        X_reference,
        sequence_ids=reference.per_frame_ids(),
        n_channels=n_channels,
        features=_columns(features, names, X.shape[1]),
    )
    real = np.average(
        _within_sequence_std(X_reference, reference, columns),
        axis=0,
        weights=reference.lengths,
    ).mean()
    if not real > 0:
        raise ValueError("The reference motion does not move in the chosen channels.")
    return _within_sequence_std(X, sequences, columns, last_frames).mean(axis=1) / real
