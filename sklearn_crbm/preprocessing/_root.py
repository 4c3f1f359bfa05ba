"""Global root <-> body-centred, ground-plane-invariant root."""

import warnings

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
)
from ..utils._sequences import check_sequence_ids
from ._layout import (
    check_encoded,
    check_skeleton,
    expmap_feature_names,
    moving_root,
)

__all__ = ["RootRelativeEncoder"]

_ROOT_IN = ("tx", "ty", "tz", "ex", "ey", "ez")
_ROOT_OUT = ("pitch", "roll", "dheading", "dforward", "dsideways", "height")
_AXES = {"x": 0, "y": 1, "z": 2}
# Frames whose forward axis lies within this angle of the vertical have an
# ill-defined heading; if most frames do, the up axis is probably wrong.
_STEEP_FORWARD_DEG = 30.0


def _wrap(angle):
    """Angles wrapped into ``[-pi, pi)``."""
    return (angle + np.pi) % (2.0 * np.pi) - np.pi


class RootRelativeEncoder(VersionedPickleMixin, TransformerMixin, BaseEstimator):
    """Make the root invariant to ground-plane translation and heading.

    The root's global position (``{root}_tx``, ``{root}_ty``, ``{root}_tz``)
    and orientation (exponential map ``{root}_ex``, ``{root}_ey``,
    ``{root}_ez``) become six body-centred channels, as in the paper (§3)
    and in Taylor's ``preprocess1``.  ``{root}`` is the name of the root
    bone: ``root`` for CMU ASF/AMC data (so the channels are ``root_pitch``,
    ...), ``Hips`` or ``joint_Root`` for many BVH files (``Hips_pitch``,
    ...).  The root orientation is split as ``R = R_up(heading) @
    R_left(pi/2 - pitch) @ R_forward(roll - pi/2)`` (a yaw-pitch-roll
    decomposition about the body's forward and left axes, see ``up_axis``):

    ``{root}_pitch``
        Angle (radians, ``[0, pi]``) between the body's forward axis and the
        downward vertical: pi/2 when the body is upright, less when it leans
        forward.
    ``{root}_roll``
        Rotation of the body about its forward axis, plus pi/2 (radians,
        ``(-pi/2, 3 pi/2]``): pi/2 when the left axis is horizontal, more
        when the body leans to its right, pi + pi/2 upside down.  With
        ``roll="taylor"``: the angle between the left axis and the downward
        vertical, in ``[0, pi]``, as in Taylor's code (the same for an upright
        body that does not pitch; see Notes).
    ``{root}_dheading``
        Change of heading (rotation about the vertical, radians, wrapped to
        ``[-pi, pi)``) from this frame to the next.
    ``{root}_dforward``, ``{root}_dsideways``
        Ground-plane displacement from this frame to the next, along the
        body's forward direction and to its right, in the heading of this
        frame.
    ``{root}_height``
        The root's height above the ground plane (absolute).

    The six columns stand where the first of the six root channels stood;
    every other column passes through.  One row comes out per row in: the
    *last* frame of each sequence has no next frame and repeats the deltas
    of the frame before it (as the original code does; 0 for a sequence of
    one frame).  The deltas never cross a sequence boundary.

    Parameters
    ----------
    skeleton : Skeleton or None, default=None
        Gives the root's name, the up axis (``skeleton.up_axis``) and, for a
        plain array, the column layout: the skeleton's channels after
        :class:`ExpMapEncoder` (each Euler block replaced by ``_ex, _ey,
        _ez``), in the skeleton's order.  Input with feature names (a
        DataFrame) is always located by name.  Without names and without a
        skeleton, the first six columns are taken as ``tx, ty, tz, ex, ey,
        ez`` (the ASF/BVH layout after :class:`ExpMapEncoder`).
    up_axis : {"x", "y", "z"} or None, default=None
        The vertical axis of the world frame.  None takes the skeleton's, or
        ``"y"`` (CMU, BVH) without a skeleton; Taylor's MIT data is ``"z"``.
        The body's forward axis is the next axis cyclically after the up
        axis and its left axis the one after that (z up: forward x, left y,
        as in the MIT data; y up: forward z, left x, as in CMU and most BVH
        files).  :meth:`fit` warns when the root's forward axis points
        nearly straight up or down in most frames, the sign of a wrong up
        axis (the round trip stays exact, but heading is then ill-defined).
    root : str or None, default=None
        Name of the root bone: the encoder reads ``"{root}_tx"``, ... and
        writes ``"{root}_pitch"``, ....  None takes the first bone whose
        translation channels move in the data seen in :meth:`fit`: the
        skeleton's root (its first bone), except in rigs that put a static
        bone above the moving pelvis (the Bandai Namco files: ``joint_Root``
        above ``Hips``); ``"root"`` for a plain array without a skeleton.
    roll : {"euler", "taylor"}, default="euler"
        ``"euler"`` gives every orientation, upside down included, an exact
        inverse.  ``"taylor"`` reproduces Taylor's ``preprocess1`` (the
        paper's encoding), which cannot tell an orientation from its mirror
        image once the body's up axis points below the horizon: then
        :meth:`transform` warns and names the frames.

    Attributes
    ----------
    root_ : str
        Name of the root bone used.
    root_columns_ : ndarray of shape (6,)
        Input columns of ``tx, ty, tz, ex, ey, ez``.
    up_axis_ : str
        The vertical axis used.
    n_features_in_ : int
        Number of features seen during :term:`fit`.
    feature_names_in_ : ndarray of shape (`n_features_in_`,)
        Names of features seen during :term:`fit`. Defined only when `X`
        has feature names that are all strings.

    See Also
    --------
    ExpMapEncoder : The step before: Euler angles to exponential maps.
    make_motion_preprocessor : The paper's whole preprocessing as a Pipeline.

    Notes
    -----
    :meth:`inverse_transform` integrates heading and ground position back
    from a start pose with heading 0 and ground position (0, 0) at the first
    frame of every sequence, and rebuilds the root orientation from pitch,
    roll and heading.  The result equals the original up to a rotation about
    the vertical and a ground-plane translation per sequence (the *start
    pose*), to rounding error for every orientation.  Where the forward axis
    points straight up or down (pitch 0 or pi, e.g. half-way through a flip)
    heading and roll turn about the same axis: the split between them is
    then arbitrary and they jump by pi, but their sum, and so the
    orientation, is exact.  The root exponential map comes back with
    rotation angle in ``[0, pi]``.

    With ``roll="taylor"`` the round trip is exact only while the body's up
    axis points above the horizon; for the other frames the left axis comes
    back mirrored.  The two rolls agree when the body does not pitch; on
    CMU subject 35 (pitch within 0.15 of pi/2) they differ by at most 7e-4
    radians.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.preprocessing import RootRelativeEncoder
    >>> # a root walking along +z (y up) at 2 units per frame, upright
    >>> X = np.zeros((4, 6))
    >>> X[:, 2] = [0.0, 2.0, 4.0, 6.0]        # tz
    >>> X[:, 1] = 17.0                        # ty: height
    >>> encoder = RootRelativeEncoder(up_axis="y").fit(X)
    >>> encoder.get_feature_names_out()
    array(['root_pitch', 'root_roll', 'root_dheading', 'root_dforward',
           'root_dsideways', 'root_height'], dtype=object)
    >>> encoder.transform(X).round(4)
    array([[ 1.5708,  1.5708,  0.    ,  2.    ,  0.    , 17.    ],
           [ 1.5708,  1.5708,  0.    ,  2.    ,  0.    , 17.    ],
           [ 1.5708,  1.5708,  0.    ,  2.    ,  0.    , 17.    ],
           [ 1.5708,  1.5708,  0.    ,  2.    ,  0.    , 17.    ]])
    >>> np.allclose(encoder.inverse_transform(encoder.transform(X)), X)
    True
    """

    __metadata_request__fit = {"sequence_ids": True}
    __metadata_request__transform = {"sequence_ids": True}
    __metadata_request__inverse_transform = {"sequence_ids": True}

    _parameter_constraints: dict = {
        "skeleton": "no_validation",
        "up_axis": [StrOptions({"x", "y", "z"}), None],
        "root": [str, None],
        "roll": [StrOptions({"euler", "taylor"})],
    }

    def __init__(self, skeleton=None, *, up_axis=None, root=None, roll="euler"):
        self.skeleton = skeleton
        self.up_axis = up_axis
        self.root = root
        self.roll = roll

    def _root_name(self, names, X):
        if self.root is not None:
            return self.root
        if names is None:
            return "root"
        if self.skeleton is not None:
            check_skeleton(self.skeleton)
        return moving_root(names, X, self.skeleton) or "root"

    def _layout_names(self, n_features):
        if hasattr(self, "feature_names_in_"):
            return np.asarray(self.feature_names_in_, dtype=object)
        if self.skeleton is not None:
            names = expmap_feature_names(self.skeleton)
            if len(names) != n_features:
                raise ValueError(
                    f"X has {n_features} columns but the skeleton's channels, "
                    f"after ExpMapEncoder, are {len(names)}; a plain array must "
                    "hold exactly those columns, in order (or pass a DataFrame "
                    "with column names)."
                )
            return names
        return None

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None, *, sequence_ids=None):
        """Locate the root channels.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Channels with the root position and root exponential map.
        y : None
            Ignored.
        sequence_ids : array-like of shape (n_frames,), default=None
            Accepted for a uniform interface (and checked); nothing is
            learned from the values.

        Returns
        -------
        self : RootRelativeEncoder
            The fitted encoder.
        """
        X = validate_data(self, X, dtype=np.float64, ensure_all_finite="allow-nan")
        check_sequence_ids(sequence_ids, X.shape[0])
        up = self.up_axis
        if up is None:
            up = getattr(self.skeleton, "up_axis", None) or "y"
        if up not in _AXES:
            raise ValueError(f"up_axis must be 'x', 'y' or 'z', got {up!r}.")
        self.up_axis_ = up
        names = self._layout_names(X.shape[1])
        root = self._root_name(names, X)
        wanted = [f"{root}_{c}" for c in _ROOT_IN]
        if names is None:
            if X.shape[1] < 6:
                raise ValueError(
                    f"X has {X.shape[1]} feature(s); RootRelativeEncoder needs the "
                    "six root channels (tx, ty, tz, ex, ey, ez), which without "
                    "feature names or a skeleton are the first six columns."
                )
            columns = np.arange(6)
            names = np.asarray([f"x{i}" for i in range(X.shape[1])], dtype=object)
        else:
            position = {str(n): j for j, n in enumerate(names)}
            missing = [w for w in wanted if w not in position]
            if missing:
                hint = ""
                if any(f"{root}_r{a}" in position for a in "xyz"):
                    hint = (
                        " The root still has Euler channels: apply ExpMapEncoder first."
                    )
                elif all(w[len(root) :] not in ("_ex", "_ey", "_ez") for w in missing):
                    hint = (
                        f" The root bone {root!r} needs position channels (tx, ty, "
                        "tz) as well as rotations."
                    )
                raise ValueError(
                    f"X lacks the root channels {missing}; RootRelativeEncoder "
                    f"needs {wanted} (root={root!r}: pass root= to name another "
                    f"bone).{hint}"
                )
            columns = np.array([position[w] for w in wanted])
        self.root_columns_ = columns
        self.root_ = root
        self._check_up_axis(X)
        self._names_in = np.asarray(names, dtype=object)
        others = np.setdiff1d(np.arange(X.shape[1]), columns)
        first = columns.min()
        before = others[others < first]
        after = others[others > first]
        self._pass_in = np.concatenate([before, after])
        self._pass_out = np.concatenate(
            [np.arange(len(before)), len(before) + 6 + np.arange(len(after))]
        ).astype(np.intp)
        self._root_out = len(before) + np.arange(6)
        return self

    def _check_up_axis(self, X):
        """Warn when the forward axis is steep in most frames: a wrong up axis."""
        R = self._local_rotations(X[:, self.root_columns_[3:]])
        R = R[np.all(np.isfinite(R), axis=(1, 2))]
        if len(R) == 0:
            return
        steep = np.abs(R[:, 2, 0]) > np.cos(np.deg2rad(_STEEP_FORWARD_DEG))
        if steep.mean() <= 0.5:
            return
        # the world axis that the root's up axis (taken to be the same letter
        # as the world's) points along in most frames
        u = _AXES[self.up_axis_]
        body_up = expmap_to_matrix(X[:, self.root_columns_[3:]])[:, :, u]
        best = "xyz"[int(np.argmax(np.nanmean(np.abs(body_up), axis=0)))]
        forward = "xyz"[self._permutation()[0]]
        warnings.warn(
            f"The root's forward axis ({forward}, the axis after the up axis "
            f"{self.up_axis_!r}) points within {_STEEP_FORWARD_DEG:g} degrees of "
            f"the vertical in {steep.mean():.0%} of the frames, so heading is "
            "ill-defined (the round trip stays exact). Is the up axis right? "
            + (
                f"The root's {self.up_axis_} axis points mostly along the world's "
                f"{best} axis: try up_axis={best!r}."
                if best != self.up_axis_
                else "Pass up_axis= to name the vertical axis."
            ),
            UserWarning,
            stacklevel=4,
        )

    def _local_rotations(self, expmaps):
        """Root rotations in (forward, left, up) coordinates."""
        perm = self._permutation()
        return expmap_to_matrix(expmaps)[:, perm][:, :, perm]

    def fit_transform(self, X, y=None, *, sequence_ids=None):
        """Fit to ``X`` and encode it; see :meth:`transform`.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Channels with the global root.
        y : None
            Ignored.
        sequence_ids : array-like of shape (n_frames,), default=None
            Sequence of each frame (``None``: one sequence).

        Returns
        -------
        X_out : ndarray of shape (n_frames, n_features)
            Body-centred root in place of the global one.
        """
        return self.fit(X, sequence_ids=sequence_ids).transform(
            X, sequence_ids=sequence_ids
        )

    def _permutation(self):
        """Coordinate order that puts the up axis last (a proper rotation)."""
        u = _AXES[self.up_axis_]
        return np.array([(u + 1) % 3, (u + 2) % 3, u])

    def transform(self, X, *, sequence_ids=None):
        """Replace the global root by the body-centred root.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Channels with the global root, in the layout seen in :meth:`fit`.
        sequence_ids : array-like of shape (n_frames,), default=None
            Sequence of each frame (``None``: one sequence).  The deltas of
            the last frame of each sequence repeat those of the frame before.

        Returns
        -------
        X_out : ndarray of shape (n_frames, n_features)
            Output columns as given by :meth:`get_feature_names_out`.
        """
        check_is_fitted(self)
        X = validate_data(
            self, X, reset=False, dtype=np.float64, ensure_all_finite="allow-nan"
        )
        sequences = check_sequence_ids(sequence_ids, X.shape[0])
        perm = self._permutation()
        position = X[:, self.root_columns_[:3]][:, perm]
        R = self._local_rotations(X[:, self.root_columns_[3:]])
        if self.roll == "taylor":
            pitch, roll, heading = self._taylor_angles(R)
        else:
            # R = R_z(heading) R_y(pi/2 - pitch) R_x(roll - pi/2), exactly
            angles = matrix_to_euler(R, "xyz")
            roll = angles[:, 0] + np.pi / 2
            pitch = np.pi / 2 - angles[:, 1]
            heading = angles[:, 2]

        n = X.shape[0]
        dheading = np.zeros(n)
        step = np.zeros((n, 2))
        if n > 1:
            dheading[:-1] = _wrap(np.diff(heading))
            step[:-1] = np.diff(position[:, :2], axis=0)
        cos, sin = np.cos(heading), np.sin(heading)
        dforward = cos * step[:, 0] + sin * step[:, 1]
        dsideways = sin * step[:, 0] - cos * step[:, 1]
        deltas = np.stack([dheading, dforward, dsideways], axis=1)
        last = sequences.stops - 1
        long = sequences.lengths > 1
        deltas[last[long]] = deltas[last[long] - 1]
        deltas[last[~long]] = 0.0

        out = np.empty_like(X)
        out[:, self._pass_out] = X[:, self._pass_in]
        root = np.column_stack([pitch, roll, deltas, position[:, 2]])
        out[:, self._root_out] = root
        return out

    def _taylor_angles(self, R):
        """Taylor's pitch, roll and heading; warns about frames it cannot invert."""
        forward = R[:, :, 0]
        left = R[:, :, 1]
        pitch = np.arccos(np.clip(-forward[:, 2], -1.0, 1.0))
        roll = np.arccos(np.clip(-left[:, 2], -1.0, 1.0))
        heading = np.arctan2(forward[:, 1], forward[:, 0])
        # the inverse takes the left axis on the upper side of the horizontal
        # perpendicular to the forward axis; frames on the other side come back
        # mirrored
        horizontal = np.stack(
            [-np.sin(heading), np.cos(heading), np.zeros_like(heading)], axis=1
        )
        mirrored = np.flatnonzero(np.sum(left * horizontal, axis=1) < -1e-9)
        if len(mirrored):
            shown = ", ".join(str(i) for i in mirrored[:10])
            more = f" and {len(mirrored) - 10} more" if len(mirrored) > 10 else ""
            warnings.warn(
                f"RootRelativeEncoder(roll='taylor') cannot encode frames {shown}"
                f"{more} (row numbers of X): the body's up axis points below the "
                "horizon, and inverse_transform will return those frames mirrored. "
                "Use roll='euler' (the default) for an exact round trip.",
                UserWarning,
                stacklevel=4,
            )
        return pitch, roll, heading

    def _taylor_rotations(self, pitch, roll, heading):
        """Root rotations from Taylor's angles, taking the up axis above the horizon."""
        n = len(pitch)
        ch, sh = np.cos(heading), np.sin(heading)
        cp, sp = np.cos(pitch), np.sin(pitch)
        zeros = np.zeros(n)
        h_vec = np.column_stack([ch, sh, zeros])
        g_vec = np.column_stack([-sh, ch, zeros])
        z_vec = np.column_stack([zeros, zeros, np.ones(n)])
        forward = sp[:, None] * h_vec - cp[:, None] * z_vec
        e_vec = cp[:, None] * h_vec + sp[:, None] * z_vec
        with np.errstate(divide="ignore", invalid="ignore"):
            sin_phi = np.clip(-np.cos(roll) / sp, -1.0, 1.0)
        sin_phi = np.where(sp > 0, sin_phi, 0.0)
        cos_phi = np.sqrt(np.maximum(1.0 - sin_phi**2, 0.0))
        left = cos_phi[:, None] * g_vec + sin_phi[:, None] * e_vec
        up = np.cross(forward, left)
        return np.stack([forward, left, up], axis=2)

    def inverse_transform(self, X, *, sequence_ids=None):
        """Integrate the body-centred root back to a global root.

        Every sequence starts at heading 0 and ground position (0, 0); see
        Notes of the class.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Encoded channels.
        sequence_ids : array-like of shape (n_frames,), default=None
            Sequence of each frame (``None``: one sequence).  Integration
            restarts at the first frame of each sequence.

        Returns
        -------
        X_original : ndarray of shape (n_frames, n_features)
            Channels with the global root position and exponential map.
        """
        check_is_fitted(self)
        X = check_encoded(X, self.n_features_in_, type(self).__name__)
        sequences = check_sequence_ids(sequence_ids, X.shape[0])
        root = X[:, self._root_out]
        pitch, roll, dheading, dforward, dsideways, height = root.T
        n = X.shape[0]
        heading = np.zeros(n)
        ground = np.zeros((n, 2))
        for start, stop in zip(sequences.starts, sequences.stops, strict=True):
            moves = slice(start, stop - 1)
            h = np.concatenate([[0.0], np.cumsum(dheading[moves])])
            heading[start:stop] = h
            cos, sin = np.cos(h[:-1]), np.sin(h[:-1])
            steps = np.column_stack(
                [
                    cos * dforward[moves] + sin * dsideways[moves],
                    sin * dforward[moves] - cos * dsideways[moves],
                ]
            )
            ground[start + 1 : stop] = np.cumsum(steps, axis=0)
        heading = _wrap(heading)

        if self.roll == "taylor":
            R_local = self._taylor_rotations(pitch, roll, heading)
        else:
            angles = np.column_stack([roll - np.pi / 2, np.pi / 2 - pitch, heading])
            R_local = euler_to_matrix(angles, "xyz")

        perm = self._permutation()
        inv = np.argsort(perm)
        R = R_local[:, inv][:, :, inv]
        position = np.column_stack([ground, height])[:, inv]

        out = np.empty_like(X)
        out[:, self._pass_in] = X[:, self._pass_out]
        out[:, self.root_columns_[:3]] = position
        out[:, self.root_columns_[3:]] = matrix_to_expmap(R)
        return out

    def get_feature_names_out(self, input_features=None):
        """Output feature names.

        Parameters
        ----------
        input_features : array-like of str or None, default=None
            Input feature names; must match ``feature_names_in_`` if that is
            defined.

        Returns
        -------
        feature_names_out : ndarray of str objects
            ``"{root}_pitch"``, ... in place of the six root channels; other
            names unchanged.
        """
        check_is_fitted(self)
        if input_features is None and not hasattr(self, "feature_names_in_"):
            names_in = self._names_in
        else:
            names_in = _check_feature_names_in(self, input_features)
        out = np.empty(self.n_features_in_, dtype=object)
        out[self._pass_out] = np.asarray(names_in, dtype=object)[self._pass_in]
        out[self._root_out] = [f"{self.root_}_{c}" for c in _ROOT_OUT]
        return out

    def __sklearn_is_fitted__(self):
        # set last by fit: a fit that failed half-way leaves the encoder unfitted
        return hasattr(self, "_root_out")

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = True
        return tags
