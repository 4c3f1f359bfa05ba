"""Windows of consecutive real frames, to seed generation."""

from numbers import Integral

import numpy as np
from sklearn.utils.validation import check_array

from ._sequences import check_sequence_ids

__all__ = ["random_windows"]


def random_windows(
    X, *, sequence_ids=None, width, n_windows=1, sequences=None, random_state=None
):
    """Windows of ``width`` consecutive frames from randomly chosen sequences.

    For each window a sequence is drawn uniformly from ``sequences`` (those
    at least ``width`` frames long), then a start frame uniformly within it.
    The result is the ``history`` that seeds
    :meth:`ConditionalRBM.sample <sklearn_crbm.ConditionalRBM.sample>` or
    :meth:`StackedCRBM.sample <sklearn_crbm.StackedCRBM.sample>` with real
    motion of a chosen kind: pass the ids of the walks (or the jogs) as
    ``sequences`` to generate from walk (or jog) seeds, as the paper's
    first demonstration does (§4.1).

    Parameters
    ----------
    X : array-like of shape (n_frames, n_features)
        Motion in long format, in the representation the model was trained
        on.
    sequence_ids : array-like of shape (n_frames,), default=None
        Sequence id of every frame; ``None`` means one sequence.
    width : int
        Frames per window (at least the model's ``order``).
    n_windows : int, default=1
        Number of windows.
    sequences : array-like, default=None
        The ids (values of ``sequence_ids``) of the sequences to draw from;
        ``None`` means every sequence.
    random_state : int, numpy.random.Generator or None, default=None
        Seed, or a generator to draw from (successive calls with one
        generator continue its stream).

    Returns
    -------
    windows : ndarray of shape (n_windows, width, n_features)
        Oldest frame first.

    Raises
    ------
    ValueError
        If none of ``sequences`` has ``width`` frames, or an id is not in
        ``sequence_ids``.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.utils import random_windows
    >>> X = np.arange(20.0).reshape(10, 2)
    >>> ids = np.repeat([0, 1], 5)
    >>> windows = random_windows(X, sequence_ids=ids, width=3, n_windows=2,
    ...                          sequences=[1], random_state=0)
    >>> windows.shape
    (2, 3, 2)
    >>> bool(np.all(windows[:, :, 0] >= 10))  # frames of sequence 1 only
    True
    """
    X = check_array(X, dtype=None, input_name="X")
    for value, name in ((width, "width"), (n_windows, "n_windows")):
        if isinstance(value, bool) or not isinstance(value, Integral) or value < 1:
            raise ValueError(f"{name} must be a positive integer, got {value!r}.")
    check_sequence_ids(sequence_ids, X.shape[0])
    ids = np.zeros(X.shape[0], dtype=int) if sequence_ids is None else sequence_ids
    ids = np.asarray(ids)
    candidates = np.unique(ids) if sequences is None else np.asarray(sequences)
    unknown = np.setdiff1d(candidates, ids)
    if unknown.size:
        raise ValueError(f"sequences holds ids not in sequence_ids: {unknown}.")
    lengths = {s: np.count_nonzero(ids == s) for s in candidates.tolist()}
    candidates = np.array([s for s in candidates.tolist() if lengths[s] >= width])
    if candidates.size == 0:
        raise ValueError(
            f"No sequence to draw from has {width} frames; the longest has "
            f"{max(lengths.values(), default=0)}."
        )
    rng = np.random.default_rng(random_state)
    windows = []
    for _ in range(n_windows):
        rows = np.flatnonzero(ids == rng.choice(candidates))
        start = rng.integers(0, len(rows) - width + 1)
        windows.append(X[rows[start : start + width]])
    return np.stack(windows)
