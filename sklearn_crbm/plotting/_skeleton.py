"""Skeletons from raw channels: one frame, or a strip of frames."""

from numbers import Integral, Real
from typing import NamedTuple

import numpy as np

from ._base import check_matplotlib, get_axes

__all__ = ["plot_motion_strip", "plot_skeleton"]

_AXES = "xyz"


def _check_frames(data, name="data"):
    if hasattr(data, "toarray") or hasattr(data, "tocsr"):
        raise TypeError(
            f"{name} must be a dense array of raw channels, got a sparse matrix; "
            "convert it with .toarray()."
        )
    frames = np.asarray(data, dtype=np.float64)
    if frames.ndim == 1:
        frames = frames[None, :]
    if frames.ndim != 2 or frames.shape[0] == 0:
        raise ValueError(
            f"{name} must be raw channels of shape (n_frames, n_features) or one "
            f"frame of shape (n_features,), got shape {np.shape(data)}."
        )
    if not np.isfinite(frames).all():
        raise ValueError(f"{name} contains NaN or infinity.")
    return frames


class _Body(NamedTuple):
    """The bones drawn: the up axis and each drawn bone's parent among them."""

    up_axis: str
    parent_indices: np.ndarray


def _positions(skeleton, data, feature_names):
    """The body drawn, and its joint positions (n_frames, n_body_bones, 3).

    The body is the skeleton's root and every bone below it, except that a
    static root with a single child (a rig's dummy bone at the origin above
    the hips, as ``joint_Root`` in the Bandai Namco files) is left out, and
    so on down: drawing it would add a line from the origin to the hips.
    """
    if not all(
        hasattr(skeleton, attribute)
        for attribute in ("forward_kinematics", "parent_indices", "up_axis")
    ):
        raise TypeError(
            "skeleton must be a sklearn_crbm.datasets.Skeleton (e.g. "
            f"load_cmu35().skeleton), got {type(skeleton).__name__}."
        )
    frames = _check_frames(data)
    positions = skeleton.forward_kinematics(frames, feature_names)
    parents = np.asarray(skeleton.parent_indices)
    root = 0
    while True:
        children = np.flatnonzero(parents == root)
        if len(children) != 1 or np.ptp(positions[:, root], axis=0).max() > 0:
            break
        root = int(children[0])
    # parents come before their children: one pass marks the root's subtree
    in_body = np.zeros(len(parents), dtype=bool)
    in_body[root] = True
    for i in range(root + 1, len(parents)):
        in_body[i] = parents[i] >= 0 and in_body[parents[i]]
    kept = np.flatnonzero(in_body)
    new_index = np.full(len(parents), -1)
    new_index[kept] = np.arange(len(kept))
    body_parents = np.where(kept == root, -1, new_index[parents[kept]])
    return _Body(skeleton.up_axis, body_parents), positions[:, kept]


def _bone_pairs(skeleton):
    """(child, parent) index of every bone below the root."""
    parents = np.asarray(skeleton.parent_indices)
    children = np.flatnonzero(parents >= 0)
    return children, parents[children]


def _height(positions, up):
    """Extent of the body along the up axis (of its tallest frame)."""
    extent = positions[..., up].max(axis=1) - positions[..., up].min(axis=1)
    return float(max(extent.max(), 1e-9))


def _hips(skeleton, positions, ground):
    """The two children of the root farthest apart on the ground plane, or None.

    ``lhipjoint``/``rhipjoint`` in CMU, ``lhip``/``rhip`` in MIT.
    """
    parents = np.asarray(skeleton.parent_indices)
    children = np.flatnonzero(parents == 0)
    best, pair = 0.0, None
    frame = positions[0][:, ground]
    for i in range(len(children)):
        for j in range(i + 1, len(children)):
            gap = np.linalg.norm(frame[children[i]] - frame[children[j]])
            if gap > best:
                best, pair = gap, (children[i], children[j])
    return None if best < 1e-9 else pair


def _facings(skeleton, positions, up, ground):
    """Per-frame ground-plane unit vector perpendicular to the hips.

    The way the body faces when the first of the two hips is its left
    (``across x up``, right-handed axes); the sign is kept continuous from
    frame to frame and chosen so that the body mostly moves along it.
    Without hips the first ground axis is used.
    """
    pair = _hips(skeleton, positions, ground)
    if pair is None:
        return np.tile([1.0, 0.0], (len(positions), 1))
    across = positions[:, pair[0]] - positions[:, pair[1]]
    across[:, up] = 0.0
    facing = np.cross(across, np.eye(3)[up])[:, ground]
    facing /= np.maximum(np.linalg.norm(facing, axis=1, keepdims=True), 1e-12)
    for k in range(1, len(facing)):
        if facing[k] @ facing[k - 1] < 0:
            facing[k] = -facing[k]
    steps = np.diff(positions[:, 0, ground], axis=0)
    if len(steps) and np.sum(steps * facing[:-1]) < 0:
        facing = -facing
    return facing


def _facing(skeleton, positions, up, ground):
    """Ground-plane unit vector perpendicular to the hips in the first frame."""
    return _facings(skeleton, positions[:1], up, ground)[0]


def _forward(skeleton, positions, horizontal):
    """The body's forward direction on the ground plane, and the axes.

    Returns ``(forward, up, ground)``: ``forward`` a unit 2-D vector on the
    ground axes ``ground`` (or one per frame, shape ``(n_frames, 2)``, for
    ``horizontal="facing"``), ``up`` the index of the up axis.  Default: the
    direction the root travels over the sequence, or the way the first frame
    faces when it hardly travels.
    """
    up = _AXES.index(skeleton.up_axis)
    ground = [a for a in range(3) if a != up]
    if isinstance(horizontal, str):
        if horizontal != "facing":
            raise ValueError(
                f"horizontal must be a direction or 'facing', got {horizontal!r}."
            )
        return _facings(skeleton, positions, up, ground), up, ground
    if horizontal is not None:
        direction = np.asarray(horizontal, dtype=np.float64)
        if direction.shape == (3,):
            direction = direction[ground]
        if direction.shape != (2,) or not np.linalg.norm(direction) > 0:
            raise ValueError(
                "horizontal must be a non-zero direction: 3 world coordinates or 2 "
                f"ground-plane coordinates, got {horizontal!r}."
            )
        return direction / np.linalg.norm(direction), up, ground
    travel = positions[-1, 0, ground] - positions[0, 0, ground]
    if np.linalg.norm(travel) > 0.1 * _height(positions, up):
        return travel / np.linalg.norm(travel), up, ground
    return _facing(skeleton, positions, up, ground), up, ground


# The cameras a drawing can take: the body's forward direction (f) and the
# up axis (u) give each view's picture axes, (left to right, bottom to top).
# "side" draws f left to right; "front" looks at the body from where it
# faces, so its left hand (u x f) is on the right; "top" looks down, f left
# to right as in the side view.  The indices are the body axes (f, u x f, u)
# drawn left to right and bottom to top.
VIEWS = ("auto", "front", "side", "top")
_PICTURE_AXES = {"side": (0, 2), "front": (1, 2), "top": (0, 1)}
# "auto" looks from above at motion whose joints spread up and down less than
# this times as much as along either ground axis (on real takes, walks and
# runs: 0.67 to 2.3; a turn: 0.08).
TOP_SPREAD = 1 / 3


def _check_view(view, allowed=VIEWS):
    if not isinstance(view, str) or view not in allowed:
        names = ", ".join(repr(name) for name in allowed)
        raise ValueError(f"view must be one of {names}, got {view!r}.")
    return view


def _body_coordinates(positions, forward, up, ground):
    """Joint positions along the body's axes (f, u x f, u): (n_frames, n_bones, 3).

    With one ``forward`` per frame (a body that turns) each frame is seen
    along its own axes, about its root, and placed along the path walked.
    """
    n_frames = len(positions)
    f = np.zeros((n_frames, 3))
    f[:, ground] = forward
    u = np.zeros(3)
    u[up] = 1.0
    axes = np.stack([f, np.cross(u, f), np.broadcast_to(u, f.shape)], axis=1)
    root = positions[:, :1]
    relative = np.einsum("fbw,fcw->fbc", positions - root, axes)
    steps = np.einsum("fw,fcw->fc", np.diff(root[:, 0], axis=0), axes[:-1])
    path = root[0, 0] @ axes[0].T + np.concatenate([[np.zeros(3)], np.cumsum(steps, 0)])
    return relative + path[:, None]


def _auto_view(coordinates):
    """The view facing the plane in which the joints move most.

    ``coordinates``: a list of :func:`_body_coordinates`, one per sequence.
    The joints' trajectories (each about its own mean over the frames,
    travel included) are pooled.  On the ground plane, the side view when
    they spread more along the forward direction than across it (a walk),
    else the front view (a wave); the top view when they spread less than
    ``TOP_SPREAD`` times as much up and down as along either ground axis
    (a turn on flat ground).  Motion that hardly moves is seen from the
    side.
    """
    spread = np.zeros(3)  # standard deviations along (f, u x f, u)
    for coords in coordinates:
        spread += ((coords - coords.mean(axis=0)) ** 2).mean(axis=(0, 1))
    spread = np.sqrt(spread)
    height = max(_height(coords, 2) for coords in coordinates)
    if spread.max() <= 1e-6 * height:
        return "side"
    forward, across, up = spread
    if up < TOP_SPREAD * min(forward, across):
        return "top"
    return "front" if across > forward else "side"


def _view_segments(skeleton, coordinates, view):
    """2-D segments (n_frames, n_bones - 1, 2, 2) of a view, and the points."""
    points = coordinates[..., list(_PICTURE_AXES[view])]
    child, parent = _bone_pairs(skeleton)
    segments = np.stack([points[:, parent], points[:, child]], axis=2)
    return segments, points


def _drawn(skeleton, data, feature_names, horizontal):
    """The body drawn and its joints' coordinates along its axes."""
    body, positions = _positions(skeleton, data, feature_names)
    forward, up, ground = _forward(body, positions, horizontal)
    return body, _body_coordinates(positions, forward, up, ground)


def _chosen_view(view, horizontal, coordinates):
    """``view``, with ``"auto"`` chosen from the motion (:func:`_auto_view`).

    With a direction for ``horizontal``, ``"auto"`` is the side view, which
    draws that direction left to right.
    """
    _check_view(view)
    if view != "auto":
        return view
    if horizontal is not None and not isinstance(horizontal, str):
        return "side"
    return _auto_view(coordinates)


def plot_skeleton(
    skeleton,
    frame,
    *,
    feature_names=None,
    view="side",
    horizontal=None,
    ax=None,
    color="k",
    linewidth=2.0,
):
    """Draw one frame of motion as a stick figure.

    The raw channels go through ``skeleton.forward_kinematics`` and every
    bone is drawn as a line from its parent's joint to its own, with the
    skeleton's up axis (``skeleton.up_axis``: y for CMU, z for MIT)
    vertical.

    Parameters
    ----------
    skeleton : Skeleton
        Bones and their channels (e.g. ``load_cmu35().skeleton``).
    frame : array-like of shape (n_features,)
        Raw channels of one frame (a ``(1, n_features)`` array works too),
        e.g. a row of ``load_cmu35().data`` or generated frames after the
        preprocessing's ``inverse_transform``.
    feature_names : array-like of str, default=None
        Name of each channel; default ``skeleton.feature_names``.
    view : {"side", "front", "top", "3d"}, default="side"
        ``"side"``: an orthographic side view on the vertical plane through
        ``horizontal``; ``"front"``: seen from where the body faces (its
        left hand on the right); ``"top"``: seen from above, ``horizontal``
        left to right.  ``"3d"``: matplotlib 3-D axes, up axis vertical.
        (One frame has no motion to choose a view from: the functions that
        draw motion also take ``"auto"``.)
    horizontal : array-like of shape (3,) or (2,) or "facing", default=None
        The body's forward direction, in world (or ground-plane)
        coordinates: drawn left to right in the side and top views, looked
        along in the front view; default (and ``"facing"``) the direction
        the body faces (perpendicular to the hips).
    ax : matplotlib Axes, default=None
        Where to draw (3-D axes for ``view="3d"``); default a new figure.
    color : color, default="k"
        Line colour.
    linewidth : float, default=2.0
        Line width.

    Returns
    -------
    ax : matplotlib Axes
        The axes, holding one line collection with a line per bone.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> from sklearn_crbm.datasets import make_walker
    >>> from sklearn_crbm.plotting import plot_skeleton
    >>> walker = make_walker(n_sequences=1, n_frames=10, random_state=0)
    >>> ax = plot_skeleton(walker.skeleton, walker.data[0])
    >>> len(ax.collections[0].get_segments())  # one line per bone below the root
    17
    """
    check_matplotlib()
    _check_view(view, ("front", "side", "top", "3d"))
    body, positions = _positions(skeleton, frame, feature_names)
    positions = positions[:1]
    if view == "3d":
        from mpl_toolkits.mplot3d.art3d import Line3DCollection

        ax = get_axes(ax, projection="3d")
        up = _AXES.index(body.up_axis)
        ground = [a for a in range(3) if a != up]
        order = [*ground, up]
        points = positions[0][:, order]
        child, parent = _bone_pairs(body)
        ax.add_collection3d(
            Line3DCollection(
                np.stack([points[parent], points[child]], axis=1),
                colors=color,
                linewidths=linewidth,
            )
        )
        centre = (points.max(axis=0) + points.min(axis=0)) / 2
        half = (points.max(axis=0) - points.min(axis=0)).max() / 2 * 1.1
        ax.set_xlim(centre[0] - half, centre[0] + half)
        ax.set_ylim(centre[1] - half, centre[1] + half)
        ax.set_zlim(centre[2] - half, centre[2] + half)
        ax.set_box_aspect((1, 1, 1))
        ax.set_xlabel(_AXES[ground[0]])
        ax.set_ylabel(_AXES[ground[1]])
        ax.set_zlabel(f"{_AXES[up]} (up)")
        return ax
    from matplotlib.collections import LineCollection

    ax = get_axes(ax)
    forward, up, ground = _forward(body, positions, horizontal)
    coordinates = _body_coordinates(positions, forward, up, ground)
    segments, points = _view_segments(body, coordinates, view)
    ax.add_collection(LineCollection(segments[0], colors=color, linewidths=linewidth))
    _frame_limits(ax, points.reshape(-1, 2))
    return ax


def _frame_limits(ax, points, margin=0.1):
    low, high = points.min(axis=0), points.max(axis=0)
    pad = margin * max(float((high - low).max()), 1e-9)
    ax.set_xlim(low[0] - pad, high[0] + pad)
    ax.set_ylim(low[1] - pad, high[1] + pad)
    ax.set_aspect("equal")


def plot_motion_strip(
    skeleton,
    data,
    *,
    feature_names=None,
    step=4,
    spacing="auto",
    view="auto",
    horizontal=None,
    ax=None,
    color="k",
    linewidth=1.5,
    ground=True,
    max_figures=30,
):
    """Draw every ``step``-th frame side by side, like Fig. 3 of the paper.

    Each drawn frame is a stick figure at its place in the world, seen
    from the side that shows the motion best (a walk from the side, moving
    from left to right; a wave from the front); ``spacing`` adds room
    between figures that would otherwise overlap.

    Parameters
    ----------
    skeleton : Skeleton
        Bones and their channels.
    data : array-like of shape (n_frames, n_features)
        Raw channels of one sequence, in time order (e.g. one trial of
        ``load_cmu35().data``, or generated frames after the preprocessing's
        ``inverse_transform``).
    feature_names : array-like of str, default=None
        Name of each channel; default ``skeleton.feature_names``.
    step : int, default=4
        Draw frames ``0, step, 2 * step, ...`` (the paper: 4 frames apart).
    spacing : "auto" or float, default="auto"
        Extra distance added between consecutive figures along the
        horizontal axis.  ``"auto"`` spreads them by at least 0.4 body
        heights each (a walk advances far less than a body width in 4
        frames), and in the front and top views by at least the widest
        figure; ``0`` draws them where they are.
    view : {"auto", "front", "side", "top"}, default="auto"
        Where the camera is, relative to the body's forward direction
        (``horizontal``): ``"side"`` draws the forward direction left to
        right, ``"front"`` looks at the body from where it faces (its left
        hand on the right), ``"top"`` looks down, forward left to right.
        ``"auto"`` faces the plane in which the joints move most (the
        side of a walk, the front of a wave, the top of a turn); with a
        direction given as ``horizontal``, the side view.
    horizontal : array-like of shape (3,) or (2,) or "facing", default=None
        The body's forward direction, in world (or ground-plane)
        coordinates; default the direction the root travels over the
        sequence (the way the body faces when it hardly travels).
        ``"facing"`` sees every frame along its own forward direction
        (perpendicular to its hips) and places the figures along the path
        walked, for motion that turns.
    ax : matplotlib Axes, default=None
        Where to draw; default a new wide figure.
    color : color or list of colors, default="k"
        Colour of all figures, or one per figure.
    linewidth : float, default=1.5
        Line width.
    ground : bool, default=True
        Draw a thin ground line under the figures (not in the top view).
    max_figures : int or None, default=30
        At most this many figures, so that they stay readable: when ``step``
        would draw more, the step grows to ``ceil(n_frames / max_figures)``
        and the strip still covers every frame.  ``None`` draws every
        ``step``-th frame however many there are.

    Returns
    -------
    ax : matplotlib Axes
        The axes, with one line collection per drawn frame.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> from sklearn_crbm.datasets import make_walker
    >>> from sklearn_crbm.plotting import plot_motion_strip
    >>> walker = make_walker(n_sequences=1, n_frames=40, random_state=0)
    >>> ax = plot_motion_strip(walker.skeleton, walker.data, step=4)
    >>> len(ax.collections)  # 40 frames, every 4th drawn
    10
    """
    check_matplotlib()
    from matplotlib.collections import LineCollection

    if isinstance(step, bool) or not isinstance(step, Integral) or step < 1:
        raise ValueError(f"step must be a positive integer, got {step!r}.")
    if max_figures is not None and (
        isinstance(max_figures, bool)
        or not isinstance(max_figures, Integral)
        or max_figures < 1
    ):
        raise ValueError(
            f"max_figures must be a positive integer or None, got {max_figures!r}."
        )
    if not (
        (isinstance(spacing, str) and spacing == "auto")
        or (
            isinstance(spacing, Real) and not isinstance(spacing, bool) and spacing >= 0
        )
    ):
        raise ValueError(f"spacing must be 'auto' or a number >= 0, got {spacing!r}.")
    body, coordinates = _drawn(skeleton, data, feature_names, horizontal)
    view = _chosen_view(view, horizontal, [coordinates])
    segments, points = _view_segments(body, coordinates, view)
    if max_figures is not None:
        step = max(step, -(-len(coordinates) // max_figures))
    drawn = np.arange(0, len(coordinates), step)
    segments, points = segments[drawn], points[drawn]
    if spacing == "auto":
        room = 0.4 * _height(coordinates, 2)
        if view != "side":  # figures as wide as they are: arms spread, steps
            room = max(room, 1.05 * np.ptp(points[..., 0], axis=1).max())
        advance = 0.0
        if len(drawn) > 1:
            advance = (points[-1, 0, 0] - points[0, 0, 0]) / (len(drawn) - 1)
        spacing = max(0.0, room - advance)
    shift = np.zeros(2)
    if ax is None:
        plt = check_matplotlib()
        _, ax = plt.subplots(figsize=(min(2 + 0.6 * len(drawn), 20), 3))
    colors = color if isinstance(color, list | tuple) else [color] * len(drawn)
    if len(colors) != len(drawn):
        raise ValueError(f"color has {len(colors)} entries for {len(drawn)} figures.")
    for k in range(len(drawn)):
        shift[0] = k * spacing
        segments[k] += shift
        points[k] += shift
        ax.add_collection(
            LineCollection(segments[k], colors=colors[k], linewidths=linewidth)
        )
    flat = points.reshape(-1, 2)
    _frame_limits(ax, flat, margin=0.05)
    if ground and view != "top":
        ax.axhline(flat[:, 1].min(), color="0.6", linewidth=0.8, zorder=0)
    ax.set_xticks([])
    ax.set_yticks([])
    return ax
