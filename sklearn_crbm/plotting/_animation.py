"""Skeletons in motion: animations, saved or as HTML."""

from numbers import Integral
from pathlib import Path

import numpy as np

from ..utils._validation import check_frame_rate
from ._base import check_matplotlib, get_axes
from ._skeleton import (
    _chosen_view,
    _drawn,
    _frame_limits,
    _height,
    _view_segments,
)

__all__ = ["animate_motion", "animate_motions", "motion_to_html", "save_animation"]


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

    frame_rate = check_frame_rate(frame_rate)
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
    ncols=None,
    figure=None,
):
    """Animate several sequences side by side, frame by frame together.

    Real motion beside generated motion, or one generated sequence per
    style: each sequence gets its own panel, all seen from the same side
    (up axis vertical), and every panel shows the same frame.  With
    ``ncols``, the panels fill a grid row by row (contents down, styles
    across).  With
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
    ncols : int, default=None
        Panels per row; the sequences fill the rows in order.  ``None``:
        all in one row.
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

    frame_rate = check_frame_rate(frame_rate)
    if isinstance(step, bool) or not isinstance(step, Integral) or step < 1:
        raise ValueError(f"step must be a positive integer, got {step!r}.")
    sequences = list(sequences)
    if not sequences:
        raise ValueError("sequences must hold at least one sequence.")
    if ncols is None:
        ncols = len(sequences)
    if isinstance(ncols, bool) or not isinstance(ncols, Integral) or ncols < 1:
        raise ValueError(f"ncols must be a positive integer, got {ncols!r}.")
    ncols = min(ncols, len(sequences))
    n_rows = -(-len(sequences) // ncols)
    titles = [None] * len(sequences) if titles is None else list(titles)
    if len(titles) != len(sequences):
        raise ValueError(
            f"titles must name each of the {len(sequences)} sequences, got "
            f"{len(titles)} titles."
        )
    rows = n_rows + (proba is not None)
    if figure is None:
        figure = plt.figure(
            figsize=(
                max(panel_width * ncols, 5.0),
                3.0 * n_rows + 2.0 * (rows - n_rows),
            )
        )
    drawn = [_drawn(skeleton, data, feature_names, horizontal) for data in sequences]
    view = _chosen_view(view, horizontal, [coordinates for _, coordinates in drawn])
    grid = figure.add_gridspec(
        rows, ncols, height_ratios=[3] * n_rows + [2] * (rows - n_rows)
    )
    updates, n_frames = [], 0
    for k, ((body, coordinates), title) in enumerate(zip(drawn, titles, strict=True)):
        ax = figure.add_subplot(grid[k // ncols, k % ncols])
        if title is not None:
            ax.set_title(title, fontsize=9)
        update, length = _motion_updater(
            ax, (body, coordinates, view), follow, "k", 2.0, None
        )
        updates.append(update)
        n_frames = max(n_frames, length)
    if proba is not None:
        from ._figures import plot_style_probabilities

        ax = figure.add_subplot(grid[n_rows, :])
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
