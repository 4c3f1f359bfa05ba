"""The paper's baseline: fill each frame from its nearest training frame."""

import numpy as np
from sklearn.base import _fit_context

from ..utils._array_api import array_ops
from ..utils._fitting import unfitted_on_error
from ._base import BaseMotionImputer, to_numpy

# Distances computed at once: bounds memory to about 32 MB of float64.
_MAX_DISTANCES = 1 << 22


class NearestNeighborImputer(BaseMotionImputer):
    """Fill missing channels from the nearest training frame (paper §4.4 baseline).

    For each frame, the Euclidean distance over that frame's observed
    channels is computed to every training frame, and the frame's missing
    channels are copied from the closest one.  This is the nearest-neighbour
    interpolation Taylor, Hinton & Roweis (2006) compare their model with:
    frames are matched independently, so the filled channels carry no
    temporal continuity.  Each frame may miss any set of channels; frames
    that miss the same set are matched together, in chunks that bound
    memory.

    Parameters
    ----------
    missing_values : int, float, str, np.nan or None, default=np.nan
        The placeholder for missing values; all its occurrences are filled.

    Attributes
    ----------
    mean_ : ndarray of shape (`n_features_in_`,)
        Mean training frame: the fill of wholly missing frames that have no
        filled frame before them in their sequence.
    n_features_in_ : int
        Number of features seen during :term:`fit`.
    feature_names_in_ : ndarray of shape (`n_features_in_`,)
        Names of features seen during :term:`fit`. Defined only when `X`
        has feature names that are all strings.

    See Also
    --------
    CRBMImputer : Fills in on-line with a conditional RBM.
    sklearn.impute.KNNImputer : Averages ``k`` neighbours, over the channels
        observed in both frames.

    Notes
    -----
    A frame with no observed channel has no nearest neighbour; it takes the
    previous (filled) frame of its sequence, and the training mean when it
    is the first frame of its sequence or follows only wholly missing
    frames.  Only wholly missing frames depend on ``sequence_ids``.  Ties
    between equally close training frames go to the earliest one.

    *Array API.*  With ``sklearn.set_config(array_api_dispatch=True)``,
    ``fit`` and ``transform`` take the arrays of any array API namespace
    (PyTorch, CuPy, ...) and compute the distances on their device; the
    fitted attributes live there too, and ``transform`` wants ``X`` in the
    namespace and on the device it was fitted on.  Only the missing-value
    pattern and the index of each nearest frame pass through the host.

    References
    ----------
    G. W. Taylor, G. E. Hinton and S. Roweis. Modeling Human Motion Using
    Binary Latent Variables. NIPS 19, 2006, Section 4.4.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.impute import NearestNeighborImputer
    >>> X_train = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 10.0], [2.0, 2.0, 20.0]])
    >>> X = np.array([[0.9, 1.2, np.nan], [np.nan, 2.1, np.nan]])
    >>> NearestNeighborImputer().fit(X_train).transform(X)
    array([[ 0.9,  1.2, 10. ],
           [ 2. ,  2.1, 20. ]])
    """

    _fitted_attribute = "_fit_X"

    def __init__(self, *, missing_values=np.nan):
        self.missing_values = missing_values

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None, *, sequence_ids=None):
        """Keep the complete training frames.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Training frames; those with a missing value are left out.
        y : None
            Ignored.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.
            Checked, then unused: frames are matched independently.

        Returns
        -------
        self : NearestNeighborImputer
            The fitted imputer.
        """
        with unfitted_on_error(self):
            X, _, _ = self._complete_frames(X, sequence_ids)
            ops = array_ops(X)
            self._fit_X = X
            self._squared_norms = ops.einsum("ij,ij->i", X, X)
            self.mean_ = ops.mean(X, axis=0)
        return self

    def transform(self, X, *, sequence_ids=None):
        """Fill every missing value of ``X`` from the nearest training frame.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Frames with missing values.  Observed values come back unchanged.
        sequence_ids : array-like of shape (n_frames,), default=None
            Integer sequence id of every frame; ``None`` means one sequence.
            Used only for wholly missing frames (see Notes).

        Returns
        -------
        X_filled : ndarray of shape (n_frames, n_features)
            ``X`` with no missing value left.
        """
        X, mask, sequences = self._check_transform_input(X, sequence_ids)
        ops = array_ops(X)
        mask = to_numpy(mask)
        empty = mask.all(axis=1)
        partial = np.flatnonzero(mask.any(axis=1) & ~empty)
        if len(partial):
            # every partial frame's nearest training frame, then one fill
            nearest = np.zeros(X.shape[0], dtype=np.int64)
            patterns, which = np.unique(mask[partial], axis=0, return_inverse=True)
            groups = _split(partial, which.ravel())
            for pattern, rows in zip(patterns, groups, strict=True):
                nearest[rows] = self._nearest(X, rows, pattern)
            fill = ops.take(self._fit_X, nearest, axis=0)
            in_partial = np.zeros(X.shape[0], dtype=bool)
            in_partial[partial] = True
            X = ops.where(ops.asarray(mask & in_partial[:, None]), fill, X)
        if empty.any():
            X = _hold_previous(X, empty, sequences.frame_starts(), self.mean_)
        return X

    def _nearest(self, X, rows, missing):
        """The nearest training frame of each of ``X[rows]``, which miss ``missing``."""
        ops = array_ops(X)
        observed, missing = np.flatnonzero(~missing), np.flatnonzero(missing)
        train = ops.take(self._fit_X, observed, axis=1)
        # ||x - t||^2 = ||x||^2 - 2 x.t + ||t||^2; ||x||^2 does not change argmin.
        dropped = ops.take(self._fit_X, missing, axis=1)
        train_norms = self._squared_norms - ops.einsum("ij,ij->i", dropped, dropped)
        step = max(1, _MAX_DISTANCES // train.shape[0])
        nearest = []
        for lo in range(0, len(rows), step):
            queries = ops.take(X, rows[lo : lo + step], axis=0)
            queries = ops.take(queries, observed, axis=1)
            distances = ops.matmul(queries, train.T)
            distances *= -2
            distances += train_norms
            nearest.append(to_numpy(ops.argmin(distances, axis=1)))
        return np.concatenate(nearest)


def _split(rows, groups):
    """Split ``rows`` into one array per group label (labels 0 .. k-1)."""
    order = np.argsort(groups, kind="stable")
    bounds = np.flatnonzero(np.diff(groups[order])) + 1
    return np.split(rows[order], bounds)


def _hold_previous(X, empty, frame_starts, fallback):
    """Give each wholly missing frame the last frame before it in its sequence.

    ``X`` must already be filled everywhere else.  A wholly missing frame
    with no other frame before it in its sequence takes ``fallback``.
    Returns the filled ``X`` (a new array), in its namespace.
    """
    index = np.arange(len(empty))
    last_filled = np.maximum.accumulate(np.where(empty, -1, index))
    source = np.where(last_filled >= frame_starts, last_filled, -1)
    # every frame's source row: itself, the frame it holds, or the fallback
    source = np.where(empty, source, index)
    source[source < 0] = len(empty)
    ops = array_ops(X)
    rows = ops.concatenate((X, ops.reshape(fallback, (1, -1))))
    return ops.take(rows, source, axis=0)
