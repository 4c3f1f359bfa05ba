"""Bringing sequences to a common frame rate by dropping frames."""

import numbers
from decimal import Decimal, InvalidOperation

import numpy as np
from sklearn.utils import _safe_indexing, check_consistent_length

from ..utils._sequences import check_sequence_ids

__all__ = ["rate_of_frame_time", "resample_frames"]

# Rates read from "Frame Time: 0.008333" are 120.0048 Hz: ratios within this
# relative tolerance of a whole number are taken as that number, so the
# frames kept are exactly every k-th one however long the sequence.
RATIO_TOLERANCE = 1e-3


def check_rate(value, name):
    """``value`` as a float, or a ValueError if it is not a positive rate."""
    if (
        isinstance(value, bool)
        or not isinstance(value, numbers.Real)
        or not (0 < value < np.inf)
    ):
        raise ValueError(
            f"{name} must be positive, a number of frames per second such as "
            f"30.0, got {value!r}."
        )
    return float(value)


def rate_of_frame_time(frame_time, written):
    """Frames per second of a file's frame time, as its writer meant it.

    ``1 / frame_time``, unless ``written`` (the frame time as the file
    writes it, e.g. ``"0.0166667"``) is ``1 / n`` rounded to the digits
    written, for the whole number ``n`` nearest to that rate and within
    :data:`RATIO_TOLERANCE` of it: then ``n`` (60.0 for ``"0.0166667"``,
    120.0 for ``"0.008333"``, where ``1 / frame_time`` is 59.9999 and
    120.005).  Rates that are not whole numbers stay as written (29.97 for
    ``"0.0333667"``).
    """
    rate = 1.0 / frame_time
    whole = round(rate)
    if whole < 1 or abs(rate - whole) > RATIO_TOLERANCE * whole:
        return rate
    try:
        value = Decimal(written.strip())
    except (InvalidOperation, AttributeError):
        return rate
    if not value.is_finite():
        return rate
    half_unit = Decimal(5).scaleb(value.as_tuple().exponent - 1)
    return float(whole) if abs(1 / Decimal(whole) - value) <= half_unit else rate


def frame_step(frame_rate, target_rate):
    """Source frames per target frame, snapped to a whole number when close.

    Raises
    ------
    ValueError
        If a rate is not a positive number, or ``target_rate`` is higher than
        ``frame_rate`` (dropping frames cannot add any).
    """
    frame_rate = check_rate(frame_rate, "frame_rate")
    target_rate = check_rate(target_rate, "target_rate")
    step = frame_rate / target_rate
    whole = round(step)
    if whole >= 1 and abs(step - whole) <= RATIO_TOLERANCE * step:
        return float(whole)
    if step < 1:
        raise ValueError(
            f"Cannot bring {frame_rate:g} frames per second up to {target_rate:g} "
            "by dropping frames; choose a target rate at most the data's rate."
        )
    return step


def kept_frames(n_frames, frame_rate, target_rate):
    """Indices of the frames of one sequence kept at ``target_rate``.

    Frame ``k`` of the result is the source frame nearest to time
    ``k / target_rate``: every ``frame_rate / target_rate``-th frame from the
    first when that ratio is a whole number (the paper's 120 Hz -> 30 Hz
    keeps frames 0, 4, 8, ...), otherwise frames at uneven steps of about
    that ratio.
    """
    step = frame_step(frame_rate, target_rate)
    count = int(np.floor((n_frames - 1) / step + 1e-9)) + 1 if n_frames else 0
    return np.minimum(np.rint(np.arange(count) * step), n_frames - 1).astype(np.intp)


def resample_frames(*arrays, frame_rate, target_rate, sequence_ids=None):
    """Bring sequences to a lower frame rate by dropping frames.

    Taylor, Hinton & Roweis (2006) train at 30 Hz on 120 Hz CMU data by
    keeping every 4th frame; this does the same for any pair of rates, per
    sequence, starting from each sequence's first frame.  When
    ``frame_rate / target_rate`` is not a whole number, the frame nearest
    to each time ``k / target_rate`` is kept, so steps vary by one frame.

    Parameters
    ----------
    *arrays : sequence of array-like of shape (n_frames, ...)
        Data in long format (``X``, ``sequence_ids``, labels...), all with
        the same number of rows.
    frame_rate : float
        Frames per second of the data.
    target_rate : float
        Frames per second wanted, at most ``frame_rate``.  Rates within
        0.1% of a whole-number ratio count as that ratio (``Frame Time:
        0.008333`` is 120 Hz).
    sequence_ids : array-like of shape (n_frames,), default=None
        Sequence of every frame; each sequence is resampled from its own
        first frame.  ``None``: one sequence.

    Returns
    -------
    resampled : ndarray or list of ndarray
        The rows of each array that are kept, in the input's order; a single
        array when one array is given (as :func:`sklearn.utils.resample`).

    Raises
    ------
    ValueError
        If a rate is not positive, ``target_rate > frame_rate``, or the
        arrays have different lengths.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.datasets import resample_frames
    >>> X = np.arange(10.0).reshape(-1, 1)
    >>> ids = np.array([0] * 6 + [1] * 4)
    >>> X30, ids30 = resample_frames(X, ids, frame_rate=120, target_rate=60,
    ...                              sequence_ids=ids)
    >>> X30.ravel().tolist(), ids30.tolist()
    ([0.0, 2.0, 4.0, 6.0, 8.0], [0, 0, 0, 1, 1])
    """
    if not arrays:
        raise ValueError("resample_frames needs at least one array.")
    check_consistent_length(*arrays)
    n_frames = len(arrays[0])
    sequences = check_sequence_ids(sequence_ids, n_frames)
    frame_step(frame_rate, target_rate)  # check the rates even for no frames
    keep = np.concatenate(
        [np.empty(0, dtype=np.intp)]
        + [
            start + kept_frames(length, frame_rate, target_rate)
            for start, length in zip(sequences.starts, sequences.lengths, strict=True)
        ]
    )
    resampled = [_safe_indexing(array, keep) for array in arrays]
    return resampled[0] if len(resampled) == 1 else resampled
