"""Per-bone Euler angles <-> exponential maps."""

from collections import defaultdict

import numpy as np
from sklearn.base import BaseEstimator, TransformerMixin, _fit_context
from sklearn.utils._param_validation import StrOptions
from sklearn.utils.validation import (
    _check_feature_names_in,
    check_is_fitted,
    validate_data,
)

from ..utils._persistence import VersionedPickleMixin
from ..utils._rotations import (
    euler_to_matrix,
    expmap_to_matrix,
    matrix_to_euler,
    matrix_to_expmap,
    mean_rotation,
    unwrap_expmap,
)
from ..utils._sequences import check_sequence_ids
from ._layout import (
    check_encoded,
    expmap_layout,
    find_euler_blocks,
    frame_chunks,
    input_names,
    moving_root,
    output_dtype,
    skeleton_feature_names,
)

__all__ = ["ExpMapEncoder"]


def _unwrap_rows(r, rows, sequences, previous):
    """Unwrap the maps ``r`` of frames ``rows`` in place, sequence by sequence.

    A sequence that began in an earlier chunk continues from ``previous``
    (its last map, unwrapped), so chunks give the maps of a whole pass.
    """
    starts = np.clip(sequences.starts, rows.start, rows.stop)
    stops = np.clip(sequences.stops, rows.start, rows.stop)
    for start, stop, first in zip(starts, stops, sequences.starts, strict=True):
        if start == stop:
            continue
        part = slice(start - rows.start, stop - rows.start)
        if first < start:  # the sequence's earlier frames were in the chunk before
            r[part] = unwrap_expmap(np.concatenate([previous[None], r[part]]))[1:]
        else:
            r[part] = unwrap_expmap(r[part])


class ExpMapEncoder(VersionedPickleMixin, TransformerMixin, BaseEstimator):
    """Encode each bone's Euler angles as an exponential map.

    Every bone with Euler-angle channels (``rx``, ``ry``, ``rz``; one, two or
    three of them) gets three columns ``"{bone}_ex"``, ``"{bone}_ey"``,
    ``"{bone}_ez"``: the exponential map (rotation axis times angle, in
    radians) of the bone's rotation.  They stand where the bone's first
    rotation channel stood; every other column (positions, channels that
    already are exponential maps) passes through unchanged.  This is the
    first step of the paper's preprocessing (Taylor et al. 2006, §3).

    Parameters
    ----------
    skeleton : Skeleton or None, default=None
        Describes the input columns.  With a skeleton, every input column
        must be one of ``skeleton.feature_names`` (``"{bone}_{channel}"``); a
        plain array must have exactly those columns in that order.  Each
        bone's angles are composed in the bone's ``rotation_order`` (the
        rotation of the first axis applied first).  Without a skeleton the
        bones are found from the feature names of ``X`` (a DataFrame):
        ``"{bone}_rx"``, ``"{bone}_ry"``, ``"{bone}_rz"``, composed in the
        order the columns appear, as in an ASF ``dof`` line.  A plain array
        without a skeleton has no named Euler channels: every column passes
        through unchanged.
    angle_unit : {"deg", "rad"}, default="deg"
        Unit of the Euler angles in ``X`` and in the output of
        :meth:`inverse_transform`.  CMU AMC and BVH files are in degrees.
        (The skeleton's ``angle_unit`` is not consulted here;
        :func:`make_motion_preprocessor` passes it on.)
    continuous : bool, default=False
        If False, each exponential map has rotation angle in ``[0, pi]``, as
        in the original code; a bone turning through pi then jumps from a
        map of length near pi to the opposite side.  If True, within each
        sequence (see ``sequence_ids``) each map is replaced, frame by frame,
        by the equivalent map ``r + 2 pi k r / |r|`` closest to the previous
        frame's, so the maps are continuous in time; the first frame of each
        sequence keeps its angle in ``[0, pi]``.
    reference : {"rest", "mean"}, default="rest"
        What each bone's rotation is measured from.  ``"rest"``: the rest
        pose (the skeleton's zero angles), as in the paper.  ``"mean"``: the
        bone's mean rotation over the data seen in :meth:`fit`, so that the
        maps stay far from a rotation of pi, where they would jump, unless a
        bone turns more than pi away from its mean (with ``"rest"``, a joint
        that sits near pi from its rest pose, such as a thigh in some BVH
        rigs, jumps back and forth).  The root is always measured from the
        rest pose, since :class:`RootRelativeEncoder` reads its global
        orientation: the first bone whose translation channels (``tx``,
        ``ty``, ``tz``) move in the data, as in :class:`RootRelativeEncoder`.

    Attributes
    ----------
    encoded_bones_ : list of str
        The bones whose Euler channels are encoded, in output order.
    reference_rotations_ : ndarray of shape (n_encoded_bones, 3, 3)
        The rotation each bone's map is measured from: the map encodes
        ``reference_rotations_[i].T @ R`` for the bone's rotation ``R``.  The
        identity for ``reference="rest"`` and for the root.
    n_features_in_ : int
        Number of features seen during :term:`fit`.
    feature_names_in_ : ndarray of shape (`n_features_in_`,)
        Names of features seen during :term:`fit`. Defined only when `X`
        has feature names that are all strings.

    See Also
    --------
    RootRelativeEncoder : The next step: a body-centred root.
    make_motion_preprocessor : The paper's whole preprocessing as a Pipeline.

    Notes
    -----
    :meth:`inverse_transform` returns Euler angles in ``(-180, 180]``
    degrees (``(-pi, pi]`` radians) for the same rotations.  For three
    channels the middle angle comes back in ``[-90, 90]``; for two channels
    the angle about the absent axis is taken to be zero, so both angles are
    recovered over the full circle.  Angles in ``X`` outside this range come
    back as their equivalents (the same rotation).

    References
    ----------
    .. [1] F. S. Grassia, "Practical parameterization of rotations using the
       exponential map", Journal of Graphics Tools 3(3), 1998.
    .. [2] G. W. Taylor, G. E. Hinton and S. Roweis, "Modeling Human Motion
       Using Binary Latent Variables", NIPS 2006.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.datasets import make_walker
    >>> from sklearn_crbm.preprocessing import ExpMapEncoder
    >>> walker = make_walker(n_sequences=1, n_frames=30, random_state=0)
    >>> list(walker.feature_names[6:11])
    ['lfemur_rx', 'lfemur_ry', 'lfemur_rz', 'ltibia_rx', 'lfoot_rx']
    >>> encoder = ExpMapEncoder(walker.skeleton).fit(walker.data)
    >>> Z = encoder.transform(walker.data)
    >>> Z.shape
    (30, 45)
    >>> list(encoder.get_feature_names_out()[6:12])
    ['lfemur_ex', 'lfemur_ey', 'lfemur_ez', 'ltibia_ex', 'ltibia_ey', 'ltibia_ez']
    >>> bool(np.allclose(encoder.inverse_transform(Z), walker.data))
    True

    A knee bent by 30 degrees about x:

    >>> from sklearn_crbm.datasets import Bone, Skeleton
    >>> knee = Skeleton([Bone("knee", None, np.zeros(3), 0.0, ("rx",), "x")])
    >>> ExpMapEncoder(knee).fit_transform([[30.0]]).round(4)
    array([[0.5236, 0.    , 0.    ]])
    """

    __metadata_request__fit = {"sequence_ids": True}
    __metadata_request__transform = {"sequence_ids": True}
    __metadata_request__inverse_transform = {"sequence_ids": True}

    _parameter_constraints: dict = {
        "skeleton": "no_validation",
        "angle_unit": [StrOptions({"deg", "rad"})],
        "continuous": ["boolean"],
        "reference": [StrOptions({"rest", "mean"})],
    }

    def __init__(
        self, skeleton=None, *, angle_unit="deg", continuous=False, reference="rest"
    ):
        self.skeleton = skeleton
        self.angle_unit = angle_unit
        self.continuous = continuous
        self.reference = reference

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None, *, sequence_ids=None):
        """Find the Euler-angle blocks of each bone.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Raw channels.  Only the column names (or the skeleton) matter.
        y : None
            Ignored.
        sequence_ids : array-like of shape (n_frames,), default=None
            Accepted for a uniform interface (and checked); not used.

        Returns
        -------
        self : ExpMapEncoder
            The fitted encoder.
        """
        X = validate_data(
            self, X, dtype=[np.float64, np.float32], ensure_all_finite="allow-nan"
        )
        check_sequence_ids(sequence_ids, X.shape[0])
        names = input_names(
            self,
            X.shape[1],
            skeleton_feature_names,
            "the skeleton has {} channels (skeleton.feature_names)",
        )
        if names is None:
            self._blocks = []
            names = np.asarray([f"x{i}" for i in range(X.shape[1])], dtype=object)
        else:
            self._blocks = find_euler_blocks(names, self.skeleton)
        self._names_out, self._passthrough, self._block_starts = expmap_layout(
            names, self._blocks
        )
        self._names_in = np.asarray(names, dtype=object)
        self.reference_rotations_ = self._fit_references(X)
        self.encoded_bones_ = [b.bone for b in self._blocks]
        return self

    def _fit_references(self, X):
        """Each block's reference rotation: identity, or the bone's mean rotation."""
        references = np.broadcast_to(np.eye(3), (len(self._blocks), 3, 3)).copy()
        if self.reference == "rest":
            return references
        root = moving_root(self._names_in, X, self.skeleton)
        for i, block in enumerate(self._blocks):
            if block.bone != root:
                angles = X[:, list(block.columns)].astype(np.float64)
                angles *= self._scale()
                references[i] = mean_rotation(euler_to_matrix(angles, block.axes))
        return references

    def _scale(self):
        """Radians per unit of the Euler channels."""
        return np.pi / 180.0 if self.angle_unit == "deg" else 1.0

    def fit_transform(self, X, y=None, *, sequence_ids=None):
        """Fit to ``X`` and encode it.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Raw channels.
        y : None
            Ignored.
        sequence_ids : array-like of shape (n_frames,), default=None
            Sequence of each frame; used when ``continuous=True``.

        Returns
        -------
        X_out : ndarray of shape (n_frames, n_features_out)
            Exponential maps in place of the Euler blocks.
        """
        return self.fit(X, sequence_ids=sequence_ids).transform(
            X, sequence_ids=sequence_ids
        )

    def _groups(self):
        """Blocks grouped by their Euler axes, for vectorised conversion."""
        groups = defaultdict(list)
        for i, block in enumerate(self._blocks):
            groups[block.axes].append(i)
        return groups

    def transform(self, X, *, sequence_ids=None):
        """Replace each bone's Euler angles by its exponential map.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Raw channels, in the layout seen in :meth:`fit`.  NaN in a bone's
            angles gives NaN in its exponential map.
        sequence_ids : array-like of shape (n_frames,), default=None
            Sequence of each frame (``None``: one sequence).  Only used when
            ``continuous=True``.

        Returns
        -------
        X_out : ndarray of shape (n_frames, n_features_out)
            Output columns as given by :meth:`get_feature_names_out`.
        """
        check_is_fitted(self)
        dtype = output_dtype(X)
        X = validate_data(
            self,
            X,
            reset=False,
            dtype=[np.float64, np.float32],
            ensure_all_finite="allow-nan",
        )
        sequences = check_sequence_ids(sequence_ids, X.shape[0])
        out = np.empty((X.shape[0], len(self._names_out)), dtype=dtype)
        out[:, self._passthrough[:, 0]] = X[:, self._passthrough[:, 1]]
        for axes, members in self._groups().items():
            cols = np.array([self._blocks[i].columns for i in members])
            columns_out = self._block_starts[members][:, None] + np.arange(3)
            reference = np.swapaxes(self.reference_rotations_[members], -1, -2)
            previous = None  # the last map of the chunk before, unwrapped
            for rows in frame_chunks(X.shape[0]):
                # in float64 whatever the dtype of X, as many frames at a time
                # as keep the rotation matrices small
                angles = X[rows][:, cols].astype(np.float64) * self._scale()
                r = matrix_to_expmap(reference @ euler_to_matrix(angles, axes))
                if self.continuous:
                    _unwrap_rows(r, rows, sequences, previous)
                    previous = r[-1]
                out[rows, columns_out] = r
        return out

    def inverse_transform(self, X, *, sequence_ids=None):
        """Euler angles back from exponential maps, in the original layout.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features_out)
            Encoded channels.
        sequence_ids : array-like of shape (n_frames,), default=None
            Accepted for a uniform interface (and checked); not needed.

        Returns
        -------
        X_original : ndarray of shape (n_frames, `n_features_in_`)
            Raw channels; angles in ``angle_unit``, within ``(-180, 180]``
            degrees (see Notes of the class).
        """
        check_is_fitted(self)
        dtype = output_dtype(X)
        X = check_encoded(X, len(self._names_out), type(self).__name__)
        check_sequence_ids(sequence_ids, X.shape[0])
        out = np.empty((X.shape[0], self.n_features_in_), dtype=np.float64)
        out[:, self._passthrough[:, 1]] = X[:, self._passthrough[:, 0]]
        for axes, members in self._groups().items():
            starts = self._block_starts[members]
            r = X[:, starts[:, None] + np.arange(3)]
            R = self.reference_rotations_[members] @ expmap_to_matrix(r)
            angles = matrix_to_euler(R, axes) / self._scale()
            cols = np.array([self._blocks[i].columns for i in members])
            out[:, cols] = angles
        return out.astype(dtype, copy=False)

    def get_feature_names_out(self, input_features=None):
        """Output feature names.

        Parameters
        ----------
        input_features : array-like of str or None, default=None
            Input feature names; must match ``feature_names_in_`` if that is
            defined.  Passthrough columns take these names.

        Returns
        -------
        feature_names_out : ndarray of str objects
            ``"{bone}_ex"``, ``"{bone}_ey"``, ``"{bone}_ez"`` for each encoded
            bone, in place of its Euler channels; other names unchanged.
        """
        check_is_fitted(self)
        names_out = self._names_out.copy()
        if input_features is None:
            return names_out
        names_in = np.asarray(
            _check_feature_names_in(self, input_features), dtype=object
        )
        if self._blocks and not np.array_equal(names_in, self._names_in):
            raise ValueError(
                "input_features do not match the channel names seen in fit "
                f"({list(self._names_in[:3])}...)."
            )
        names_out[self._passthrough[:, 0]] = names_in[self._passthrough[:, 1]]
        return names_out

    def __sklearn_is_fitted__(self):
        # set last by fit: a fit that failed half-way leaves the encoder unfitted
        return hasattr(self, "encoded_bones_")

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = True
        tags.transformer_tags.preserves_dtype = ["float64", "float32"]
        return tags
