"""Checks of arguments that several estimators and functions share."""

from numbers import Integral, Real

from ._array_api import array_ops

__all__ = ["check_context", "check_count", "check_frame_rate"]


def check_context(context, n_frames, n_context, like, *, one_row=False):
    """``context`` as an array of ``like``'s namespace, dtype and device.

    Parameters
    ----------
    context : array-like of shape (n_frames, n_context) or None
        None passes through.
    n_frames : int
    n_context : int or None
        The columns a fitted model takes (0: none); None in ``fit``, where
        any number of columns but 0 is one.
    like : ndarray
    one_row : bool, default=False
        Whether one row may stand for every frame (then broadcast).

    Returns
    -------
    context : ndarray of shape (n_frames, n_context) or None
    """
    if context is None:
        return None
    if n_context == 0:
        raise ValueError(
            "This model was fitted without context, so it takes none: fit it "
            "with context= of shape (n_frames, n_context) to condition on one."
        )
    if hasattr(context, "toarray") or hasattr(context, "tocsr"):
        raise TypeError("context must be a dense array, got a sparse matrix.")
    ops = array_ops(like)
    try:
        context = ops.asarray(context, dtype=like.dtype)
    except (TypeError, ValueError) as exc:
        raise TypeError(
            f"context must be an array of numbers, got {type(context).__name__}."
        ) from exc
    rows = (1, n_frames) if one_row else (n_frames,)
    wanted = "(n_frames, n_context)" if n_context is None else f"(n, {n_context})"
    if (
        context.ndim != 2
        or context.shape[0] not in rows
        or context.shape[1] == 0
        or n_context not in (None, context.shape[1])
    ):
        frames = " or ".join(str(n) for n in rows)
        raise ValueError(
            f"context must have shape {wanted} with n = {frames}: one row of "
            f"context per frame; got shape {tuple(context.shape)}. A single "
            "signal is one column: context.reshape(-1, 1)."
        )
    if not bool(ops.all(ops.isfinite(context))):
        raise ValueError("context contains NaN or infinity.")
    if context.shape[0] != n_frames:
        context = ops.broadcast_to(context, (n_frames, context.shape[1]))
    return context


def check_count(value, name, minimum):
    """``value`` as an int; a ValueError naming ``name`` unless it is one >= minimum."""
    if isinstance(value, bool) or not isinstance(value, Integral) or value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}.")
    return int(value)


def check_frame_rate(frame_rate):
    """``frame_rate`` (frames per second) as a float; a ValueError unless positive."""
    if isinstance(frame_rate, bool) or not isinstance(frame_rate, Real):
        raise ValueError(f"frame_rate must be a positive number, got {frame_rate!r}.")
    if not frame_rate > 0:
        raise ValueError(f"frame_rate must be a positive number, got {frame_rate!r}.")
    return float(frame_rate)
