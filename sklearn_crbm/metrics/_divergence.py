"""How different sequences generated from one seed are from each other."""

import numpy as np
from sklearn.utils import check_array

from ..utils._sequences import check_sequence_ids

__all__ = ["divergence"]


def _as_sequences(X, sequence_ids):
    """``X`` as a float array of shape (n_sequences, n_frames, n_features)."""
    if getattr(X, "ndim", np.ndim(X)) == 3:
        if sequence_ids is not None:
            raise ValueError(
                "A 3-D X holds one sequence per row already; pass sequence_ids "
                "only with a 2-D X in long format."
            )
        X = check_array(X, dtype=np.float64, allow_nd=True)
        if X.shape[0] < 2:
            raise ValueError(
                f"divergence compares sequences: X holds {X.shape[0]}, it needs "
                "at least 2."
            )
        return X
    X = check_array(X, dtype=np.float64)
    sequences = check_sequence_ids(sequence_ids, X.shape[0])
    if len(sequences.lengths) < 2:
        raise ValueError(
            "divergence compares sequences: X holds one; pass the sequence_ids "
            "of the sequences stacked in X (long format), or a 3-D array "
            "(n_sequences, n_frames, n_features)."
        )
    if (sequences.lengths != sequences.lengths[0]).any():
        raise ValueError(
            "divergence compares the sequences frame by frame: they must have "
            f"the same number of frames, got {sorted(set(sequences.lengths))}."
        )
    order = np.argsort(sequences.starts, kind="stable")
    starts = sequences.starts[order]
    length = int(sequences.lengths[0])
    return np.stack([X[start : start + length] for start in starts])


def _frame_rows(frames, n_frames):
    """The frames of every sequence that are compared, as indices."""
    if frames is None:
        return np.arange(n_frames)
    if isinstance(frames, slice):
        rows = np.arange(n_frames)[frames]
    else:
        rows = np.asarray(frames)
        if rows.ndim != 1 or not np.issubdtype(rows.dtype, np.integer):
            raise ValueError(
                "frames must be a slice or a 1-D array of frame indices, got "
                f"{frames!r}."
            )
        if ((rows < -n_frames) | (rows >= n_frames)).any():
            raise ValueError(
                f"frames holds indices beyond the sequences' {n_frames} frames."
            )
        rows = rows % n_frames
    if len(rows) < 2:
        raise ValueError(
            f"divergence needs at least 2 frames to compare, got {len(rows)}."
        )
    return rows


def divergence(X, *, sequence_ids=None, frames=None, features=None):
    """How different sequences are from each other, frame by frame.

    Meant for sequences generated from one seed: 0 when they are copies of
    each other, about 1 when they are as different as unrelated stretches
    of the same motion.  With ``x_s[t, c]`` sequence ``s``'s value of
    channel ``c`` at frame ``t`` (only the ``frames`` given),

    .. math::

        D^2 = \\frac{\\operatorname{mean}_{s < r, t, c}
              (x_s[t, c] - x_r[t, c])^2}{2 \\operatorname{mean}_c \\sigma_c^2}

    where the numerator averages over every pair of sequences and
    :math:`\\sigma_c^2` is channel ``c``'s variance over the frames within
    each sequence, averaged over the sequences.  The divergence is the
    root-mean-square difference of two sequences over :math:`\\sqrt 2`
    times their own standard deviation.  Two independent stretches of the
    same stationary motion differ by :math:`\\sqrt 2\\,\\sigma` on average,
    hence 1; the same cycle a quarter period apart also gives 1, half a
    period apart (opposite phase) :math:`\\sqrt 2`.  Channels are pooled
    by their variance (a ratio of sums, not a mean of ratios), so channels
    that barely move weigh little: compare in units where channels are
    alike, for example the standardised channels a model generates.

    Parameters
    ----------
    X : array-like of shape (n_frames, n_features) or \
(n_sequences, n_frames, n_features)
        The sequences, of equal length: in long format with
        ``sequence_ids`` (what ``sample`` returns, with
        ``np.repeat(np.arange(n_sequences), n_samples)``), or as a 3-D
        array.
    sequence_ids : array-like of shape (n_frames,), default=None
        Sequence id of every frame of a 2-D ``X`` (at least two sequences).
    frames : slice or array-like of int, default=None
        The frames of each sequence compared (for example ``slice(300,
        600)``, after the sequences have had time to part); ``None`` means
        all.
    features : array-like of int, default=None
        The columns compared; ``None`` means all.

    Returns
    -------
    divergence : float
        Non-negative; 0 for copies, about 1 for unrelated motion.

    See Also
    --------
    liveliness : How much each sequence moves against real motion.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.metrics import divergence
    >>> t = np.arange(400)
    >>> wave = np.column_stack([np.sin(t / 5), np.cos(t / 5)])
    >>> divergence(np.stack([wave, wave]))                      # copies
    0.0
    >>> rng = np.random.default_rng(0)
    >>> noise = rng.standard_normal((4, 400, 2))                # unrelated
    >>> round(divergence(noise), 1)
    1.0
    >>> later = np.column_stack([np.sin(t / 5 + np.pi / 2), np.cos(t / 5 + np.pi / 2)])
    >>> round(divergence(np.stack([wave, later])), 2)           # a quarter period
    1.0
    >>> ids = np.repeat([0, 1], 400)                            # long format
    >>> round(divergence(np.vstack([wave, -wave]), sequence_ids=ids), 2)
    1.41
    """
    X = _as_sequences(X, sequence_ids)
    if features is not None:
        columns = np.asarray(features)
        if columns.ndim != 1 or not np.issubdtype(columns.dtype, np.integer):
            raise ValueError(
                f"features must be a 1-D array of column indices, got {features!r}."
            )
        if ((columns < -X.shape[2]) | (columns >= X.shape[2])).any():
            raise ValueError(
                f"features holds columns beyond X's {X.shape[2]} features."
            )
        X = X[:, :, columns]
    X = X[:, _frame_rows(frames, X.shape[1]), :]
    n_sequences = X.shape[0]
    # mean over pairs s < r of (x_s - x_r)^2 = 2 n / (n - 1) var across s
    between = X.var(axis=0).mean() * n_sequences / (n_sequences - 1)
    within = X.var(axis=1).mean()
    if not within > 0:
        raise ValueError(
            "The sequences do not move over the frames compared: their "
            "divergence is undefined."
        )
    return float(np.sqrt(between / within))
