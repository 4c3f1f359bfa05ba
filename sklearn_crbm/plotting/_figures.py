"""The paper's Fig. 1 (hidden activations) and Fig. 4 (filled-in channels),
and the style of motion over time."""

import numpy as np

from ..utils._sequences import check_sequence_ids
from ._base import check_matplotlib, get_axes

__all__ = [
    "plot_filled_channels",
    "plot_hidden_activations",
    "plot_style_probabilities",
]


def plot_hidden_activations(
    hidden, *, sequence_ids=None, frame_rate=None, ax=None, cmap="gray", colorbar=True
):
    """Hidden-unit probabilities over a sequence as an image, like Fig. 1 of the paper.

    Rows are hidden units, columns are frames; white is "on".  Feed it the
    output of :meth:`ConditionalRBM.transform` (or
    :meth:`StackedCRBM.transform`).

    Parameters
    ----------
    hidden : array-like of shape (n_frames, n_components)
        Hidden probabilities (values in [0, 1]).
    sequence_ids : array-like of shape (n_frames,), default=None
        When given, a vertical line marks where each new sequence starts.
    frame_rate : float, default=None
        When given, the horizontal axis is in seconds instead of frames.
    ax : matplotlib Axes, default=None
        Where to draw; default a new figure.
    cmap : str or Colormap, default="gray"
        Colour map from 0 (off) to 1 (on).
    colorbar : bool, default=True
        Add a colour bar.

    Returns
    -------
    ax : matplotlib Axes
        The axes, holding the image.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> from sklearn_crbm.plotting import plot_hidden_activations
    >>> hidden = np.random.default_rng(0).random((50, 8))
    >>> ax = plot_hidden_activations(hidden, sequence_ids=np.repeat([0, 1], 25))
    >>> ax.images[0].get_array().shape  # units by frames
    (8, 50)
    """
    hidden = _check_probabilities(hidden, "hidden", "n_components", "transform")
    n_frames, n_components = hidden.shape
    ax = get_axes(ax)
    scale = 1.0 if frame_rate is None else 1.0 / float(frame_rate)
    image = ax.imshow(
        hidden.T,
        aspect="auto",
        cmap=cmap,
        vmin=0.0,
        vmax=1.0,
        interpolation="nearest",
        origin="upper",
        extent=(-0.5 * scale, (n_frames - 0.5) * scale, n_components - 0.5, -0.5),
    )
    if sequence_ids is not None:
        sequences = check_sequence_ids(sequence_ids, n_frames)
        for start in sequences.starts[1:]:
            ax.axvline((start - 0.5) * scale, color="tab:red", linewidth=1.0)
    ax.set_xlabel("frame" if frame_rate is None else "time (s)")
    ax.set_ylabel("hidden unit")
    if colorbar:
        ax.figure.colorbar(image, ax=ax, label="p(h = 1 | data)")
    return ax


def _check_probabilities(values, name, columns, method):
    """``values`` as a float array of shape (n_frames, ``columns``) in [0, 1]."""
    _check_dense(values, name)
    values = np.asarray(values, dtype=np.float64)
    if values.ndim != 2 or 0 in values.shape:
        raise ValueError(
            f"{name} must have shape (n_frames, {columns}) with at least one "
            f"frame and one column, got shape {values.shape}."
        )
    if not np.isfinite(values).all():
        raise ValueError(f"{name} contains NaN or infinity.")
    if values.min() < 0 or values.max() > 1:
        raise ValueError(
            f"{name} must hold probabilities in [0, 1] (the output of {method}), "
            f"got values in [{values.min():g}, {values.max():g}]."
        )
    return values


def _check_dense(values, name):
    if hasattr(values, "toarray") or hasattr(values, "tocsr"):
        raise TypeError(
            f"{name} must be a dense array, got a sparse matrix; convert it with "
            ".toarray()."
        )


def _as_columns(values, name, n_frames=None):
    _check_dense(values, name)
    values = np.asarray(values, dtype=np.float64)
    if values.ndim == 1:
        values = values[:, None]
    if values.ndim != 2:
        raise ValueError(f"{name} must be 1-D or 2-D (n_frames, n_features).")
    if n_frames is not None and values.shape[0] != n_frames:
        raise ValueError(f"{name} has {values.shape[0]} frames, expected {n_frames}.")
    return values


def plot_filled_channels(
    X_true,
    X_filled,
    X_nearest=None,
    *,
    features=None,
    feature_names=None,
    missing_from=None,
    frame_rate=None,
    axes=None,
    labels=("true", "model", "nearest neighbour"),
):
    """Filled-in channels against the truth, like Fig. 4 of the paper.

    One panel per chosen channel: the true values as a solid line, the
    model's fill as a dashed line, and optionally the nearest-neighbour fill
    as a dotted line; a vertical line marks where the channels went missing.

    Parameters
    ----------
    X_true : array-like of shape (n_frames, n_features) or (n_frames,)
        The original data.
    X_filled : array-like of the same shape
        The data with the missing values filled in by a model.
    X_nearest : array-like of the same shape, default=None
        A second fill, e.g. by nearest neighbours.
    features : list of int or str, default=None
        Which channels to draw, by index or by name (with
        ``feature_names``); default all.
    feature_names : array-like of str, default=None
        Name of each channel, used for panel titles and to find ``features``.
    missing_from : int, default=None
        First missing frame, marked by a vertical line.
    frame_rate : float, default=None
        When given, the horizontal axis is in seconds instead of frames.
    axes : array-like of matplotlib Axes, default=None
        One axes per channel; default a new figure with one row per channel.
    labels : tuple of str, default=("true", "model", "nearest neighbour")
        Legend labels of the three curves.

    Returns
    -------
    axes : ndarray of matplotlib Axes
        One axes per channel, each with two or three lines.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> from sklearn_crbm.plotting import plot_filled_channels
    >>> t = np.linspace(0, 6, 60)
    >>> true = np.column_stack([np.sin(t), np.cos(t)])
    >>> filled = true + 0.1
    >>> nearest = true - 0.2
    >>> axes = plot_filled_channels(true, filled, nearest, missing_from=30,
    ...                             feature_names=["hip_x", "hip_z"])
    >>> [len(ax.get_lines()) for ax in axes]  # 3 curves and the marker line
    [4, 4]
    """
    plt = check_matplotlib()
    X_true = _as_columns(X_true, "X_true")
    n_frames, n_features = X_true.shape
    X_filled = _as_columns(X_filled, "X_filled", n_frames)
    if X_filled.shape[1] != n_features:
        raise ValueError("X_filled must have the same shape as X_true.")
    if X_nearest is not None:
        X_nearest = _as_columns(X_nearest, "X_nearest", n_frames)
        if X_nearest.shape[1] != n_features:
            raise ValueError("X_nearest must have the same shape as X_true.")
    names = None if feature_names is None else np.asarray(feature_names, dtype=object)
    if names is not None and names.shape != (n_features,):
        raise ValueError(f"feature_names needs {n_features} names.")
    if features is None:
        columns = list(range(n_features))
    else:
        columns = []
        for feature in features:
            if isinstance(feature, str):
                if names is None or feature not in names:
                    raise ValueError(f"No feature is named {feature!r}.")
                columns.append(int(np.flatnonzero(names == feature)[0]))
            else:
                columns.append(int(feature))
    if axes is None:
        _, axes = plt.subplots(
            len(columns),
            1,
            sharex=True,
            figsize=(6, 2 + 1.6 * len(columns)),
            squeeze=False,
        )
    axes = np.asarray(axes, dtype=object).ravel()
    if len(axes) != len(columns):
        raise ValueError(f"axes has {len(axes)} axes for {len(columns)} channels.")
    scale = 1.0 if frame_rate is None else 1.0 / float(frame_rate)
    time = np.arange(n_frames) * scale
    for ax, column in zip(axes, columns, strict=True):
        ax.plot(time, X_true[:, column], "k-", linewidth=1.5, label=labels[0])
        ax.plot(time, X_filled[:, column], "--", color="tab:blue", label=labels[1])
        if X_nearest is not None:
            ax.plot(time, X_nearest[:, column], ":", color="tab:red", label=labels[2])
        if missing_from is not None:
            ax.axvline(missing_from * scale, color="0.5", linewidth=0.8)
        ax.set_title(str(names[column]) if names is not None else f"channel {column}")
    axes[0].legend(loc="best", fontsize="small")
    axes[-1].set_xlabel("frame" if frame_rate is None else "time (s)")
    return axes


def plot_style_probabilities(proba, *, classes=None, frame_rate=None, ax=None):
    """Probability of each style over the frames of a sequence, one curve each.

    Feed it the per-frame probabilities of
    :meth:`StyleJudge.predict_proba <sklearn_crbm.metrics.StyleJudge.predict_proba>`
    for one sequence, for example a generated transition from one style to
    another, to see when the motion changes style.

    Parameters
    ----------
    proba : array-like of shape (n_frames, n_classes)
        Probability of every style at every frame, in [0, 1].
    classes : array-like of shape (n_classes,), default=None
        Names of the styles in the order of the columns (the judge's
        ``classes_``), for the legend; default ``"style 0"``, ...
    frame_rate : float, default=None
        When given, the horizontal axis is in seconds instead of frames.
    ax : matplotlib Axes, default=None
        Where to draw; default a new figure.

    Returns
    -------
    ax : matplotlib Axes
        The axes, with one line per style, labelled with its name.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> from sklearn_crbm.plotting import plot_style_probabilities
    >>> fast = np.linspace(0, 1, 50)[:, None]  # from slow to fast
    >>> ax = plot_style_probabilities(np.hstack([1 - fast, fast]),
    ...                               classes=["slow", "fast"])
    >>> [line.get_label() for line in ax.get_lines()]
    ['slow', 'fast']
    """
    proba = _check_probabilities(proba, "proba", "n_classes", "predict_proba")
    n_frames, n_classes = proba.shape
    if classes is None:
        classes = [f"style {k}" for k in range(n_classes)]
    classes = np.asarray(classes, dtype=object)
    if classes.shape != (n_classes,):
        raise ValueError(
            f"classes must name the {n_classes} styles of the columns of proba, "
            f"got {classes.size} names."
        )
    ax = get_axes(ax)
    scale = 1.0 if frame_rate is None else 1.0 / float(frame_rate)
    time = np.arange(n_frames) * scale
    for column, name in enumerate(classes):
        ax.plot(time, proba[:, column], label=str(name))
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlabel("frame" if frame_rate is None else "time (s)")
    ax.set_ylabel("probability")
    ax.legend(loc="center left", bbox_to_anchor=(1.0, 0.5), fontsize="small")
    return ax
