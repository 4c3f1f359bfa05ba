"""Shared helpers of the plotting functions: the lazy matplotlib import."""

__all__ = ["check_matplotlib", "get_axes"]


def check_matplotlib():
    """Import and return ``matplotlib.pyplot``, or say how to install it.

    Raises
    ------
    ImportError
        If matplotlib is not installed; the message names the ``plot`` extra.
    """
    try:
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise ImportError(
            "sklearn_crbm.plotting needs matplotlib, which is not installed. "
            "Install it with: pip install sklearn_crbm[plot]  (or: pip install "
            "matplotlib)."
        ) from exc
    return plt


def get_axes(ax, **subplot_kw):
    """``ax`` itself, or the axes of a new figure."""
    plt = check_matplotlib()
    if ax is not None:
        return ax
    _, ax = plt.subplots(subplot_kw=subplot_kw or None)
    return ax
