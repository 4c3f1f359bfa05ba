"""Skeletons from raw channels: one frame, a strip of frames, an animation."""

from numbers import Integral, Real
from pathlib import Path
from typing import NamedTuple

import numpy as np

from ._base import check_matplotlib, get_axes

__all__ = [
    "animate_motion",
    "animate_motions",
    "motion_to_html",
    "plot_motion_strip",
    "plot_skeleton",
    "save_animation",
]

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


def animate_motion(
    skeleton,
    data,
    *,
    feature_names=None,
    frame_rate=30.0,
    follow=True,
    view="auto",
    horizontal=None,
    ax=None,
    color="k",
    linewidth=2.0,
    title=None,
):
    """Animate a sequence as a moving stick figure.

    Save it with :func:`save_animation` (GIF through Pillow, MP4 through
    ffmpeg) or show it in a notebook with :func:`motion_to_html`.

    Parameters
    ----------
    skeleton : Skeleton
        Bones and their channels.
    data : array-like of shape (n_frames, n_features)
        Raw channels of one sequence, in time order.
    feature_names : array-like of str, default=None
        Name of each channel; default ``skeleton.feature_names``.
    frame_rate : float, default=30.0
        Frames per second of playback.
    follow : bool, default=True
        Keep the figure centred by moving the view with the root; otherwise
        the view covers the whole path.
    view : {"auto", "front", "side", "top"}, default="auto"
        Where the camera is; ``"auto"`` faces the plane in which the joints
        move most (see :func:`plot_motion_strip`).
    horizontal : array-like of shape (3,) or (2,) or "facing", default=None
        The body's forward direction; default the direction the root
        travels; ``"facing"`` follows the body as it turns (see
        :func:`plot_motion_strip`).
    ax : matplotlib Axes, default=None
        Where to draw; default a new figure.
    color : color, default="k"
        Line colour.
    linewidth : float, default=2.0
        Line width.
    title : str, default=None
        Axes title; ``"{title}  frame {k}"`` is shown while playing.

    Returns
    -------
    animation : matplotlib.animation.FuncAnimation
        One animation frame per data frame.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> from sklearn_crbm.datasets import make_walker
    >>> from sklearn_crbm.plotting import animate_motion
    >>> walker = make_walker(n_sequences=1, n_frames=12, random_state=0)
    >>> animation = animate_motion(walker.skeleton, walker.data)
    >>> len(list(animation.new_frame_seq()))
    12
    >>> html = animation.to_jshtml()  # or save_animation(animation, "walk.gif")
    """
    check_matplotlib()
    from matplotlib.animation import FuncAnimation

    frame_rate = _check_frame_rate(frame_rate)
    body, coordinates = _drawn(skeleton, data, feature_names, horizontal)
    view = _chosen_view(view, horizontal, [coordinates])
    ax = get_axes(ax)
    update, n_frames = _motion_updater(
        ax, (body, coordinates, view), follow, color, linewidth, title
    )
    update(0)
    return FuncAnimation(
        ax.figure,
        update,
        frames=n_frames,
        interval=1000.0 / frame_rate,
        blit=False,
    )


def _check_frame_rate(frame_rate):
    if isinstance(frame_rate, bool) or not isinstance(frame_rate, Real):
        raise ValueError(f"frame_rate must be a positive number, got {frame_rate!r}.")
    if not frame_rate > 0:
        raise ValueError(f"frame_rate must be a positive number, got {frame_rate!r}.")
    return float(frame_rate)


def _motion_updater(ax, drawn, follow, color, linewidth, title):
    """Draw frame 0 of a sequence on ``ax``; ``(update(k), n_frames)``.

    ``drawn`` is :func:`_drawn`'s ``(body, coordinates, view)``;
    ``update(k)`` draws frame ``k`` (the last frame for ``k`` beyond it).
    Following, the side and front views move left and right with the
    root, over a fixed ground; the top view moves both ways.
    """
    from matplotlib.collections import LineCollection

    body, coordinates, view = drawn
    segments, points = _view_segments(body, coordinates, view)
    height = _height(coordinates, 2)
    lines = LineCollection(segments[0], colors=color, linewidths=linewidth)
    ax.add_collection(lines)
    low = points[..., 1].min() - 0.05 * height
    high = points[..., 1].max() + 0.05 * height
    widest = np.ptp(points, axis=1).max(axis=0)  # of one frame, on each axis
    if view == "top":
        half = 0.55 * widest.max() + 0.05 * height
    else:
        ax.set_ylim(low, high)
        ax.axhline(points[..., 1].min(), color="0.6", linewidth=0.8, zorder=0)
        half = max(0.75 * (high - low), 0.55 * widest[0] + 0.05 * height)
    if not follow:
        _frame_limits(ax, points.reshape(-1, 2), margin=0.05)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])

    def centre(k):
        ax.set_xlim(points[k, 0, 0] - half, points[k, 0, 0] + half)
        if view == "top":
            ax.set_ylim(points[k, 0, 1] - half, points[k, 0, 1] + half)

    if follow:
        centre(0)

    def update(k):
        k = min(k, len(segments) - 1)
        lines.set_segments(segments[k])
        if follow:
            centre(k)
        if title is not None:
            ax.set_title(f"{title}  frame {k}")
        return (lines,)

    return update, len(points)


def animate_motions(
    skeleton,
    sequences,
    *,
    titles=None,
    feature_names=None,
    frame_rate=30.0,
    step=1,
    proba=None,
    classes=None,
    follow=True,
    view="auto",
    horizontal=None,
    panel_width=2.6,
    figure=None,
):
    """Animate several sequences side by side, frame by frame together.

    Real motion beside generated motion, or one generated sequence per
    style: each sequence gets its own panel, all seen from the same side
    (up axis vertical), and every panel shows the same frame.  With
    ``proba``, a panel below plots the probability of each style over the frames (see
    :func:`~sklearn_crbm.plotting.plot_style_probabilities`) with a line at
    the frame shown.  Save it with :func:`save_animation`, at
    ``frame_rate / step`` frames per second to play in real time.

    Parameters
    ----------
    skeleton : Skeleton
        Bones and their channels (the same for every sequence).
    sequences : list of array-like of shape (n_frames, n_features)
        Raw channels of each sequence; a shorter one stays at its last frame.
    titles : list of str, default=None
        The title of each panel.
    feature_names : array-like of str, default=None
        Name of each channel; default ``skeleton.feature_names``.
    frame_rate : float, default=30.0
        Frames per second of the data.
    step : int, default=1
        Show every ``step``-th frame (a smaller file).
    proba : array-like of shape (n_frames, n_classes), default=None
        Probability of each style at every frame of the sequences, drawn
        below them.
    classes : array-like of shape (n_classes,), default=None
        The names of the styles of ``proba``.
    follow : bool, default=True
        Move each panel's view with its root (see :func:`animate_motion`).
    view : {"auto", "front", "side", "top"}, default="auto"
        Where the camera is (see :func:`plot_motion_strip`), the same for
        every panel; ``"auto"`` faces the plane in which the joints of all
        the sequences together move most.
    horizontal : array-like of shape (3,) or (2,) or "facing", default=None
        As for :func:`animate_motion`.
    panel_width : float, default=2.6
        Width of each panel, in inches (of a new figure).
    figure : matplotlib Figure, default=None
        Where to draw (an empty figure); default a new one.

    Returns
    -------
    animation : matplotlib.animation.FuncAnimation
        One animation frame per ``step`` data frames of the longest sequence.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> from sklearn_crbm.datasets import make_walker
    >>> from sklearn_crbm.plotting import animate_motions
    >>> walker = make_walker(n_sequences=2, n_frames=12, random_state=0)
    >>> first, second = walker.data[:12], walker.data[12:]
    >>> animation = animate_motions(walker.skeleton, [first, second],
    ...                             titles=["real", "generated"], step=2)
    >>> len(list(animation.new_frame_seq()))
    6
    """
    plt = check_matplotlib()
    from matplotlib.animation import FuncAnimation

    frame_rate = _check_frame_rate(frame_rate)
    if isinstance(step, bool) or not isinstance(step, Integral) or step < 1:
        raise ValueError(f"step must be a positive integer, got {step!r}.")
    sequences = list(sequences)
    if not sequences:
        raise ValueError("sequences must hold at least one sequence.")
    titles = [None] * len(sequences) if titles is None else list(titles)
    if len(titles) != len(sequences):
        raise ValueError(
            f"titles must name each of the {len(sequences)} sequences, got "
            f"{len(titles)} titles."
        )
    rows = 1 if proba is None else 2
    if figure is None:
        figure = plt.figure(
            figsize=(max(panel_width * len(sequences), 5.0), 3.0 + 2.0 * (rows - 1))
        )
    drawn = [_drawn(skeleton, data, feature_names, horizontal) for data in sequences]
    view = _chosen_view(view, horizontal, [coordinates for _, coordinates in drawn])
    grid = figure.add_gridspec(rows, len(sequences), height_ratios=[3, 2][:rows])
    updates, n_frames = [], 0
    for k, ((body, coordinates), title) in enumerate(zip(drawn, titles, strict=True)):
        ax = figure.add_subplot(grid[0, k])
        if title is not None:
            ax.set_title(title, fontsize=9)
        update, length = _motion_updater(
            ax, (body, coordinates, view), follow, "k", 2.0, None
        )
        updates.append(update)
        n_frames = max(n_frames, length)
    if proba is not None:
        from ._figures import plot_style_probabilities

        ax = figure.add_subplot(grid[1, :])
        plot_style_probabilities(proba, classes=classes, frame_rate=frame_rate, ax=ax)
        ax.legend(fontsize=7, ncols=4, loc="upper right")
        cursor = ax.axvline(0.0, color="0.2", linewidth=1.0)

        def move_cursor(k):
            cursor.set_xdata([k / frame_rate] * 2)

        updates.append(move_cursor)
    figure.tight_layout()

    def update_all(k):
        for update in updates:
            update(k)

    update_all(0)
    return FuncAnimation(
        figure,
        update_all,
        frames=range(0, n_frames, step),
        interval=1000.0 * step / frame_rate,
        blit=False,
    )


def save_animation(animation, filename, *, frame_rate=30.0, dpi=80):
    """Write an animation to a GIF (Pillow), an MP4 (ffmpeg) or an HTML file.

    Parameters
    ----------
    animation : matplotlib.animation.Animation
        E.g. from :func:`animate_motion`.
    filename : path-like
        ``.gif`` uses matplotlib's ``PillowWriter``; ``.mp4`` its
        ``FFMpegWriter`` (needs the ``ffmpeg`` program); ``.html`` writes the
        self-contained JavaScript player of :func:`motion_to_html`.
    frame_rate : float, default=30.0
        Frames per second.  A GIF stores each frame's delay in whole
        hundredths of a second: the delays alternate (70, 70 and 60 ms at
        15 frames per second) so that every stretch of the GIF plays in
        its time to within a hundredth of a second.
    dpi : int, default=80
        Resolution of the frames.

    Returns
    -------
    filename : pathlib.Path
        The file written.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import tempfile, pathlib
    >>> from sklearn_crbm.datasets import make_walker
    >>> from sklearn_crbm.plotting import animate_motion, save_animation
    >>> walker = make_walker(n_sequences=1, n_frames=5, random_state=0)
    >>> animation = animate_motion(walker.skeleton, walker.data)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = save_animation(animation, pathlib.Path(folder) / "walk.gif")
    ...     path.stat().st_size > 0
    True
    """
    check_matplotlib()
    from matplotlib import animation as mpl_animation

    path = Path(filename)
    suffix = path.suffix.lower()
    if suffix == ".gif":
        writer = _timed_gif_writer(mpl_animation.PillowWriter)(fps=frame_rate)
    elif suffix == ".mp4":
        if not mpl_animation.FFMpegWriter.isAvailable():
            raise RuntimeError(
                "Writing MP4 needs the ffmpeg program, which was not found; save a "
                "GIF instead (filename ending in .gif)."
            )
        writer = mpl_animation.FFMpegWriter(fps=frame_rate)
    elif suffix in (".html", ".htm"):
        path.write_text(animation.to_jshtml(fps=frame_rate), encoding="utf-8")
        return path
    else:
        raise ValueError(
            f"Cannot tell the format of {str(path)!r}: use a name ending in .gif, "
            ".mp4 or .html."
        )
    animation.save(path, writer=writer, dpi=dpi)
    return path


def _gif_delays(n_frames, frame_rate):
    """Each frame's delay in a GIF, in hundredths of a second.

    Frame ``k`` starts at ``round(100 * k / frame_rate)`` hundredths, so the
    first ``k`` frames last ``k / frame_rate`` seconds to within half a
    hundredth, however many frames there are.
    """
    starts = np.rint(100.0 * np.arange(n_frames + 1) / frame_rate)
    return np.diff(starts).astype(int)


def _timed_gif_writer(pillow_writer):
    """matplotlib's ``PillowWriter``, writing the delays of :func:`_gif_delays`.

    (``PillowWriter`` gives every frame ``int(1000 / fps)`` ms, which a GIF
    stores as whole hundredths: 66.7 ms becomes 60, 11% fast.)
    """

    class TimedPillowWriter(pillow_writer):
        def finish(self):
            delays = _gif_delays(len(self._frames), self.fps)
            self._frames[0].save(
                self.outfile,
                save_all=True,
                append_images=self._frames[1:],
                duration=[10 * int(delay) for delay in delays],
                loop=0,
            )

    return TimedPillowWriter


def motion_to_html(skeleton, data, *, feature_names=None, frame_rate=30.0, **kwargs):
    """A self-contained HTML/JavaScript player of the motion, for notebooks.

    Show it with ``IPython.display.HTML(motion_to_html(...))``.  Unless an
    ``ax`` is given, the figure used to render the frames is closed
    afterwards.

    Parameters
    ----------
    skeleton : Skeleton
        Bones and their channels.
    data : array-like of shape (n_frames, n_features)
        Raw channels of one sequence, in time order.
    feature_names : array-like of str, default=None
        Name of each channel; default ``skeleton.feature_names``.
    frame_rate : float, default=30.0
        Frames per second of playback.
    **kwargs
        Passed to :func:`animate_motion` (``follow``, ``horizontal``, ``ax``,
        ``color``, ``linewidth``, ``title``).

    Returns
    -------
    html : str
        HTML with the frames embedded as images and a JavaScript player.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> from sklearn_crbm.datasets import make_walker
    >>> from sklearn_crbm.plotting import motion_to_html
    >>> walker = make_walker(n_sequences=1, n_frames=4, random_state=0)
    >>> html = motion_to_html(walker.skeleton, walker.data)
    >>> "<script" in html
    True
    """
    plt = check_matplotlib()
    figure = None
    if kwargs.get("ax") is None:
        figure, kwargs["ax"] = plt.subplots()
    animation = animate_motion(
        skeleton, data, feature_names=feature_names, frame_rate=frame_rate, **kwargs
    )
    try:
        return animation.to_jshtml(fps=frame_rate)
    finally:
        if figure is not None:
            plt.close(figure)
