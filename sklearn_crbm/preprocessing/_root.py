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
    frame_chunks,
    input_names,
    moving_root,
    output_dtype,
)
from ._root_path import (
    _integrate,
    _most_common_root,
    _outputs,
    _travels,
    _wrap,
)

__all__ = ["RootRelativeEncoder"]

_ROOT_IN = ("tx", "ty", "tz", "ex", "ey", "ez")
_AXES = {"x": 0, "y": 1, "z": 2}
# Frames whose forward axis lies within this angle of the vertical have an
# ill-defined heading; if most frames do, the up axis is probably wrong.
_STEEP_FORWARD_DEG = 30.0


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

    With ``channels`` a root that has only some of the six channels is
    encoded as far as it goes (see the parameter): each output needs the
    channels it is computed from, and as many columns come out as go in.

    The root's output columns stand where the first of its input channels
    stood; every other column passes through.  One row comes out per row in: the
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
        ez`` (the ASF/BVH layout after :class:`ExpMapEncoder`), or the
        first ``len(channels)`` columns, in the order of ``channels``.
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
        Sequences (``sequence_ids``) that travel with different bones give
        the bone most of them travel with, and a warning that names the
        others.
    roll : {"euler", "taylor"}, default="euler"
        ``"euler"`` gives every orientation, upside down included, an exact
        inverse.  ``"taylor"`` reproduces Taylor's ``preprocess1`` (the
        paper's encoding), which cannot tell an orientation from its mirror
        image once the body's up axis points below the horizon: then
        :meth:`transform` warns and names the frames.
    channels : sequence of str or None, default=None
        The root channels the data holds, from ``"tx", "ty", "tz", "ex",
        "ey", "ez"``; None means all six.  For a root that is a point or a
        ground vehicle rather than a body (a marker, a pedestrian track, a
        robot's ``(x, z, yaw)``), or a rig whose root lacks some channels.
        Writing ``"t<up>"`` and ``"e<up>"`` for the channels along the up
        axis (``"ty"``, ``"ey"`` when y is up) and "ground" for the two
        other translations, the outputs are:

        - ``{root}_pitch``, ``{root}_roll``: with all three of ``ex, ey, ez``;
        - ``{root}_dheading``: with all three, or with ``"e<up>"`` alone (a
          rotation about the vertical only, whose exponential map is the
          heading angle); without any rotation the heading is 0, so the
          steps below are along the world's forward and left axes;
        - ``{root}_dforward``, ``{root}_dsideways``: with both ground
          translations (one alone is refused);
        - ``{root}_height``: with ``"t<up>"``.

        E.g. ``("tx", "tz")`` with y up makes a ground track invariant to
        where it starts, and ``("tx", "tz", "ey")`` also to which way it
        faces.  ``inverse_transform`` gives a yaw-only root its angle in
        ``[-pi, pi)``.

    Attributes
    ----------
    root_ : str
        Name of the root bone used.
    root_columns_ : ndarray of shape (n_channels,)
        Input columns of the root channels, in the order of ``channels``
        (``tx, ty, tz, ex, ey, ez`` by default).
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

    A ground track alone, in the world's axes (forward z, left x when y is
    up), then with the direction it faces (``ey``, radians):

    >>> track = RootRelativeEncoder(channels=("tx", "tz")).fit(X[:, [0, 2]])
    >>> track.get_feature_names_out()
    array(['root_dforward', 'root_dsideways'], dtype=object)
    >>> tx = [0.0, 2.0, 4.0, 6.0]
    >>> turned = np.column_stack([tx, np.zeros(4), np.full(4, np.pi / 2)])
    >>> vehicle = RootRelativeEncoder(channels=("tx", "tz", "ey")).fit(turned)
    >>> vehicle.get_feature_names_out()
    array(['root_dheading', 'root_dforward', 'root_dsideways'], dtype=object)
    >>> # facing +x and moving along it: 2 forward, none sideways, no turn
    >>> np.allclose(vehicle.transform(turned), [0.0, 2.0, 0.0])
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
        "channels": [list, tuple, None],
    }

    def __init__(
        self, skeleton=None, *, up_axis=None, root=None, roll="euler", channels=None
    ):
        self.skeleton = skeleton
        self.up_axis = up_axis
        self.root = root
        self.roll = roll
        self.channels = channels

    def _root_name(self, names, X, sequences):
        if self.root is not None:
            return self.root
        if names is None:
            return "root"
        if self.skeleton is not None:
            check_skeleton(self.skeleton)
        roots = [
            moving_root(names, X[start:stop], self.skeleton)
            for start, stop in zip(sequences.starts, sequences.stops, strict=True)
        ]
        travelling = [
            (k, root)
            for k, root in enumerate(roots)
            if _travels(names, X[sequences.starts[k] : sequences.stops[k]], root)
        ]
        if len({root for _, root in travelling}) < 2:
            return moving_root(names, X, self.skeleton) or "root"
        return _most_common_root(travelling)

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
        sequences = check_sequence_ids(sequence_ids, X.shape[0])
        up = self.up_axis
        if up is None:
            up = getattr(self.skeleton, "up_axis", None) or "y"
        if up not in _AXES:
            raise ValueError(f"up_axis must be 'x', 'y' or 'z', got {up!r}.")
        self.up_axis_ = up
        channels = self._check_channels(up)
        names = input_names(
            self,
            X.shape[1],
            expmap_feature_names,
            "the skeleton's channels, after ExpMapEncoder, are {}",
        )
        root = self._root_name(names, X, sequences)
        wanted = [f"{root}_{c}" for c in channels]
        if names is None:
            if X.shape[1] < len(channels):
                raise ValueError(
                    f"X has {X.shape[1]} feature(s); RootRelativeEncoder needs the "
                    f"{len(channels)} root channels ({', '.join(channels)}), which "
                    "without feature names or a skeleton are the first "
                    f"{len(channels)} columns; for a root with fewer channels "
                    "pass channels=."
                )
            columns = np.arange(len(channels))
            names = np.asarray([f"x{i}" for i in range(X.shape[1])], dtype=object)
        else:
            columns = self._named_columns(names, root, wanted)
        self.root_columns_ = columns
        self.root_ = root
        self._column = dict(zip(channels, columns.tolist(), strict=True))
        self._outputs = _outputs(channels, up)
        if self._full_orientation():
            self._check_up_axis(X)
        self._names_in = np.asarray(names, dtype=object)
        others = np.setdiff1d(np.arange(X.shape[1]), columns)
        first = columns.min()
        before = others[others < first]
        after = others[others > first]
        k = len(columns)
        self._pass_in = np.concatenate([before, after])
        self._pass_out = np.concatenate(
            [np.arange(len(before)), len(before) + k + np.arange(len(after))]
        ).astype(np.intp)
        self._root_out = len(before) + np.arange(k)
        return self

    def _check_channels(self, up):
        """``channels`` as a tuple, or a ValueError saying which sets work."""
        if self.channels is None:
            return _ROOT_IN
        channels = tuple(str(c) for c in self.channels)
        unknown = sorted(set(channels) - set(_ROOT_IN))
        if unknown or not channels or len(set(channels)) < len(channels):
            raise ValueError(
                f"channels must name distinct root channels from {list(_ROOT_IN)}, "
                f"got {list(channels)}."
            )
        ground = [f"t{a}" for a in "xyz" if a != up]
        rotation = {"ex", "ey", "ez"} & set(channels)
        if sum(g in channels for g in ground) == 1:
            raise ValueError(
                f"channels {list(channels)} hold one ground-plane translation; the "
                f"ground steps need both {ground} (up axis {up!r}), or neither."
            )
        if rotation not in (set(), {"ex", "ey", "ez"}, {f"e{up}"}):
            raise ValueError(
                f"channels {list(channels)} hold the rotation channels "
                f"{sorted(rotation)}; an orientation needs all of ex, ey, ez, or "
                f"e{up} alone (a rotation about the up axis {up!r}: the heading)."
            )
        return channels

    def _named_columns(self, names, root, wanted):
        """Columns of the ``wanted`` names, or a ValueError with a hint."""
        position = {str(n): j for j, n in enumerate(names)}
        missing = [w for w in wanted if w not in position]
        if not missing:
            return np.array([position[w] for w in wanted])
        present = [c for c in _ROOT_IN if f"{root}_{c}" in position]
        hint = ""
        if any(f"{root}_r{a}" in position for a in "xyz"):
            hint = " The root still has Euler channels: apply ExpMapEncoder first."
        elif present:
            hint = (
                f" The data has the root channels {present}: pass channels= to "
                "encode those."
            )
        raise ValueError(
            f"X lacks the root channels {missing}; RootRelativeEncoder needs "
            f"{wanted} (root={root!r}: pass root= to name another bone).{hint}"
        )

    def _full_orientation(self):
        return "pitch" in self._outputs

    def _check_up_axis(self, X):
        """Warn when the forward axis is steep in most frames: a wrong up axis."""
        R = self._local_rotations(X[:, self._expmap_columns()])
        R = R[np.all(np.isfinite(R), axis=(1, 2))]
        if len(R) == 0:
            return
        steep = np.abs(R[:, 2, 0]) > np.cos(np.deg2rad(_STEEP_FORWARD_DEG))
        if steep.mean() <= 0.5:
            return
        # the world axis that the root's up axis (taken to be the same letter
        # as the world's) points along in most frames
        u = _AXES[self.up_axis_]
        body_up = expmap_to_matrix(X[:, self._expmap_columns()])[:, :, u]
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
        dtype = output_dtype(X)
        X = validate_data(
            self, X, reset=False, dtype=np.float64, ensure_all_finite="allow-nan"
        )
        sequences = check_sequence_ids(sequence_ids, X.shape[0])
        n = X.shape[0]
        position = self._local_positions(X)
        encoded, heading = self._orientation(X)
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
        encoded.update(
            zip(("dheading", "dforward", "dsideways"), deltas.T, strict=True)
        )
        encoded["height"] = position[:, 2]

        out = np.empty_like(X)
        for rows in frame_chunks(n):  # no temporary copy of all the other channels
            out[rows, self._pass_out] = X[rows][:, self._pass_in]
        out[:, self._root_out] = np.column_stack([encoded[c] for c in self._outputs])
        return out.astype(dtype, copy=False)

    def _local_positions(self, X):
        """Root positions in (forward, left, up) coordinates; 0 where absent."""
        position = np.zeros((X.shape[0], 3))
        for axis, column in self._translation_columns():
            position[:, axis] = X[:, column]
        return position[:, self._permutation()]

    def _translation_columns(self):
        """``(world axis, input column)`` of every translation channel present."""
        return [
            (i, self._column[f"t{a}"])
            for i, a in enumerate("xyz")
            if f"t{a}" in self._column
        ]

    def _orientation(self, X):
        """``({"pitch": ..., "roll": ...}, heading)``: as far as the channels give."""
        if self._full_orientation():
            R = self._local_rotations(X[:, self._expmap_columns()])
            if self.roll == "taylor":
                pitch, roll, heading = self._taylor_angles(R)
            else:
                # R = R_z(heading) R_y(pi/2 - pitch) R_x(roll - pi/2), exactly
                angles = matrix_to_euler(R, "xyz")
                roll = angles[:, 0] + np.pi / 2
                pitch = np.pi / 2 - angles[:, 1]
                heading = angles[:, 2]
            return {"pitch": pitch, "roll": roll}, heading
        if "dheading" in self._outputs:  # a rotation about the vertical only
            return {}, X[:, self._column[f"e{self.up_axis_}"]]
        return {}, np.zeros(X.shape[0])

    def _expmap_columns(self):
        return [self._column[c] for c in ("ex", "ey", "ez")]

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
        dtype = output_dtype(X)
        X = check_encoded(X, self.n_features_in_, type(self).__name__)
        sequences = check_sequence_ids(sequence_ids, X.shape[0])
        n = X.shape[0]
        encoded = dict(zip(self._outputs, X[:, self._root_out].T, strict=True))
        dheading, dforward, dsideways, height = (
            encoded.get(c, np.zeros(n))
            for c in ("dheading", "dforward", "dsideways", "height")
        )
        heading, ground = _integrate(dheading, dforward, dsideways, sequences)
        inv = np.argsort(self._permutation())
        position = np.column_stack([ground, height])[:, inv]
        out = np.empty_like(X)
        out[:, self._pass_in] = X[:, self._pass_out]
        for axis, column in self._translation_columns():
            out[:, column] = position[:, axis]
        if self._full_orientation():
            R_local = self._rotations(encoded["pitch"], encoded["roll"], heading)
            out[:, self._expmap_columns()] = matrix_to_expmap(
                R_local[:, inv][:, :, inv]
            )
        elif "dheading" in self._outputs:
            out[:, self._column[f"e{self.up_axis_}"]] = heading
        return out.astype(dtype, copy=False)

    def _rotations(self, pitch, roll, heading):
        """Root rotations in (forward, left, up) coordinates from the angles."""
        if self.roll == "taylor":
            return self._taylor_rotations(pitch, roll, heading)
        angles = np.column_stack([roll - np.pi / 2, np.pi / 2 - pitch, heading])
        return euler_to_matrix(angles, "xyz")

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
        out[self._root_out] = [f"{self.root_}_{c}" for c in self._outputs]
        return out

    def __sklearn_is_fitted__(self):
        # set last by fit: a fit that failed half-way leaves the encoder unfitted
        return hasattr(self, "_root_out")

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = True
        tags.transformer_tags.preserves_dtype = ["float64", "float32"]
        return tags
