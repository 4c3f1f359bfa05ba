"""Labels of one or several factors as a style model's context: one-hot blocks.

A style model may be fitted on one label factor (``y`` of shape
``(n_frames,)``, a style) or several (``y`` of shape ``(n_frames,
n_outputs)``, for example a content and a style), as scikit-learn's
multi-output classifiers take them.  Each factor's label becomes a one-hot
block of the context; the blocks sit side by side, factor after factor, so
that what each factor does to the model adds to what the others do.

Wherever labels are given, a factor's entry is a label seen in ``fit`` or a
blend of its labels: a mapping ``{label: weight}`` of non-negative weights
that sum to 1 (``{"elderly": 0.5, "youthful": 0.5}``), which becomes that
factor's block of weights.
"""

import itertools
from collections.abc import Mapping

import numpy as np

from ..utils._array_api import to_numpy

__all__ = [
    "as_entries",
    "check_label_weights",
    "combinations",
    "fit_columns",
    "fitted_classes",
    "label_weights",
]

# How far a row of label weights may sum from 1.
_WEIGHT_SUM_TOLERANCE = 1e-6

BLEND_HINT = (
    "a blend of labels is written, in place of a label, as a mapping "
    "{label: weight} of weights that sum to 1 (one per frame in fit, e.g. "
    "[dict(zip(classes, row)) for row in weights])"
)


def check_label_weights(weights, n_classes, name="style"):
    """``weights`` as a float64 array of rows of non-negative weights summing to 1."""
    try:
        weights = np.asarray(weights, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} weights must be numbers, got {weights!r}.") from exc
    if weights.ndim != 2 or weights.shape[1] != n_classes:
        raise ValueError(
            f"{name} weights must have shape (n_frames, {n_classes}): one weight "
            f"per style and frame; got shape {weights.shape}."
        )
    if not np.all(np.isfinite(weights)):
        raise ValueError(f"{name} weights contain NaN or infinity.")
    if np.any(weights < 0):
        raise ValueError(f"{name} weights must be non-negative.")
    sums = weights.sum(axis=1)
    if np.any(np.abs(sums - 1) > _WEIGHT_SUM_TOLERANCE):
        worst = sums[np.argmax(np.abs(sums - 1))]
        raise ValueError(
            f"{name} weights must sum to 1 in every frame; a frame's sum to "
            f"{worst:g}. Divide each row by its sum."
        )
    return weights


def labels_that_compare(name):
    """The error for labels that cannot be sorted together (str and int, None)."""
    return TypeError(
        f"{name} holds style labels that cannot be compared with each other or "
        "with the styles seen in fit (such as strings and numbers mixed, or None): "
        "give labels of one kind."
    )


def as_written(labels):
    """Labels as plain Python values for messages: ``'sad'``, not ``np.str_('sad')``."""
    return np.asarray(labels).tolist()


def as_entries(labels):
    """``labels`` as a numpy array whose elements are labels or mappings.

    A mapping alone is one entry (a 0-d object array); arrays of any
    namespace come to the host.
    """
    if isinstance(labels, Mapping):
        entry = np.empty((), dtype=object)
        entry[()] = labels
        return entry
    if hasattr(labels, "__array_namespace__") and not isinstance(labels, np.ndarray):
        return to_numpy(labels)
    return np.asarray(labels)


def _is_blend(column):
    """Which entries of a 1-D ``column`` are mappings (blends)."""
    if column.dtype != object:
        return np.zeros(len(column), dtype=bool)
    return np.fromiter(
        (isinstance(v, Mapping) for v in column), dtype=bool, count=len(column)
    )


def _plain(column):
    """A column of a 2-D object array as the array its labels make on their own
    (``['walk', 1]`` rows give a str and an int column); mixed kinds stay
    objects, for :func:`numpy.unique` to refuse."""
    if column.dtype != object or len(column) == 0:
        return column
    kinds = {type(v) for v in column}
    if len(kinds) == 1 and not issubclass(next(iter(kinds)), Mapping):
        return np.asarray(column.tolist())
    return column


def _factor_name(name, factor, n_factors):
    """``y``, or ``y[:, 1]`` for the second of several factors."""
    return name if n_factors == 1 else f"{name}[:, {factor}]"


def fit_columns(y, n_frames, name="y"):
    """The columns of the labels ``y`` of ``fit``, one per label factor.

    ``y`` of shape ``(n_frames,)`` or ``(n_frames, 1)`` is one factor;
    ``(n_frames, n_outputs)`` is ``n_outputs`` factors (floats are refused
    there: they were once label weights, which are mappings now).
    """
    entries = as_entries(y)
    if entries.ndim == 2 and entries.shape[1] == 1:
        entries = entries[:, 0]
    if entries.ndim == 2 and entries.dtype.kind in "fc":
        raise ValueError(
            f"{name} of shape {entries.shape} holds the labels of "
            f"{entries.shape[1]} label factors (one column each, such as content "
            "and style), as scikit-learn's multi-output classifiers take them, "
            "but it holds floats: give labels as strings or integers. Label "
            f"weights per frame are not a 2-D {name}: {BLEND_HINT}."
        )
    if entries.ndim not in (1, 2) or len(entries) != n_frames:
        raise ValueError(
            f"{name} must hold one style label per frame of X ({n_frames}); got an "
            f"array of shape {entries.shape} (the labels of several label "
            "factors: shape (n_frames, n_outputs))."
        )
    columns = [entries] if entries.ndim == 1 else [_plain(c) for c in entries.T]
    for j, column in enumerate(columns):
        if column.dtype.kind == "f" and np.any(np.isnan(column)):
            factor = _factor_name(name, j, len(columns))
            raise ValueError(f"{factor} contains NaN: every frame needs a style label.")
    return columns


def fitted_classes(y, n_frames, name="y"):
    """The classes of each label factor of ``y`` (fit): a list of arrays.

    See :func:`fit_columns`.  A blend's labels (the keys of a mapping) are
    classes too.
    """
    columns = fit_columns(y, n_frames, name)
    classes = []
    for j, column in enumerate(columns):
        blend = _is_blend(column)
        labels = column[~blend]
        if np.any(blend):
            keys = [key for entry in column[blend] for key in entry]
            labels = np.asarray(labels.tolist() + keys)
        try:
            classes.append(np.unique(labels))
        except TypeError:
            raise labels_that_compare(_factor_name(name, j, len(columns))) from None
    return classes


def _one_hot(labels, classes, name):
    """Weights that put each label's whole weight on its class."""
    try:
        index = np.searchsorted(classes, labels)
    except TypeError:
        raise labels_that_compare(name) from None
    index = np.minimum(index, len(classes) - 1)
    unseen = classes[index] != labels
    if np.any(unseen):
        raise ValueError(
            f"{name} holds the style {as_written(labels[np.argmax(unseen)])!r}, "
            f"not seen in fit; the styles are {as_written(classes)}."
        )
    return np.eye(len(classes))[index]


def _blend_weights(blend, classes, name):
    """One row of weights from a mapping ``{label: weight}``."""
    labels = list(blend)
    if not labels:
        raise ValueError(f"{name} holds an empty blend {{}}: give at least one label.")
    try:
        weights = np.array([blend[label] for label in labels], dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(
            f"{name} holds the blend {blend!r}, whose weights are not numbers: "
            "write {label: weight}."
        ) from None
    if not np.all(np.isfinite(weights)) or np.any(weights < 0):
        raise ValueError(
            f"{name} holds the blend {blend!r}: weights must be non-negative "
            "finite numbers."
        )
    if abs(weights.sum() - 1) > _WEIGHT_SUM_TOLERANCE:
        raise ValueError(
            f"{name} holds the blend {blend!r}, whose weights sum to "
            f"{weights.sum():g}: they must sum to 1 (divide each by their sum)."
        )
    index = np.argmax(
        _one_hot(_plain(np.asarray(labels, dtype=object)), classes, name), axis=1
    )
    row = np.zeros(len(classes))
    row[index] = weights
    return row


def _column_weights(column, classes, name):
    """Label weights ``(len(column), n_classes)`` of labels or blends."""
    if column.dtype.kind == "f" and np.any(np.isnan(column)):
        raise ValueError(f"{name} contains NaN: give a style for every frame.")
    blend = _is_blend(column)
    if not np.any(blend):
        return _one_hot(column, classes, name)
    weights = np.zeros((len(column), len(classes)))
    if not np.all(blend):
        weights[~blend] = _one_hot(_plain(column[~blend]), classes, name)
    for i in np.flatnonzero(blend):
        weights[i] = _blend_weights(column[i], classes, name)
    return weights


def label_weights(labels, classes, n_frames, *, name="y", every_frame=False):
    """Label weights ``(n_frames, sum of n_classes)`` of every frame.

    Parameters
    ----------
    labels : label, mapping or array-like
        One factor: a label or blend per frame, ``(n_frames,)`` or
        ``(n_frames, 1)``.  Several: one row per frame, ``(n_frames,
        n_outputs)``.  With ``every_frame``, one entry (one factor) or one
        row (several, shape ``(n_outputs,)`` or ``(1, n_outputs)``) stands
        for every frame.
    classes : list of ndarray
        Each factor's classes.
    n_frames : int
    name : str
        What the caller calls ``labels``, for messages.
    every_frame : bool
        Whether one entry or row may stand for every frame.
    """
    entries = as_entries(labels)
    n_factors = len(classes)
    one_row = False
    if n_factors == 1:
        if entries.ndim == 2 and entries.shape[1] == 1:
            entries = entries[:, 0]
        if entries.ndim == 0 and every_frame:
            entries, one_row = entries[None], True
        if entries.ndim != 1:
            shape = "a label, " if every_frame else ""
            raise ValueError(
                f"{name} must be {shape}one style label per frame, shape "
                f"(n_frames,), for a model of one label factor; got an array of "
                f"shape {entries.shape}; {BLEND_HINT}."
            )
        columns = [entries]
    else:
        if entries.ndim == 1 and every_frame and len(entries) == n_factors:
            entries = entries[None, :]
        one_row = every_frame and entries.ndim == 2 and len(entries) == 1
        if entries.ndim != 2 or entries.shape[1] != n_factors:
            row = f"one row of {n_factors} labels (for every frame) or " * every_frame
            raise ValueError(
                f"{name} must give a label of each of the model's {n_factors} "
                f"label factors: {row}one row per frame, shape (n_frames, "
                f"{n_factors}); got an array of shape {entries.shape}."
            )
        columns = [_plain(entries[:, j]) for j in range(n_factors)]
    n_rows = len(columns[0])
    if n_rows != n_frames and not one_row:
        raise ValueError(
            f"{name} gives {n_rows} frames' {'styles' if n_factors == 1 else 'labels'}"
            f" but {n_frames} are needed: one per frame"
            f"{' (or one for all)' * (every_frame and n_factors > 1)}."
        )
    weights = np.hstack(
        [
            _column_weights(column, factor_classes, _factor_name(name, j, n_factors))
            for j, (column, factor_classes) in enumerate(
                zip(columns, classes, strict=True)
            )
        ]
    )
    if n_rows != n_frames:
        weights = np.repeat(weights, n_frames, axis=0)
    return weights


def blocks(classes):
    """The slice of the context that each factor's weights fill."""
    stops = np.cumsum([len(c) for c in classes])
    return [
        slice(int(stop - len(c)), int(stop))
        for c, stop in zip(classes, stops, strict=True)
    ]


def combinations(classes):
    """Every combination of one class per factor: codes and context rows.

    Returns ``codes`` of shape ``(n_combinations, n_factors)`` (the first
    factor's code changes slowest) and ``contexts`` of shape
    ``(n_combinations, sum of n_classes)``, one one-hot block per factor.
    """
    sizes = [len(c) for c in classes]
    codes = np.array(list(itertools.product(*map(range, sizes))), dtype=np.intp)
    contexts = np.hstack([np.eye(size)[codes[:, j]] for j, size in enumerate(sizes)])
    return codes, contexts
