"""Keeping an estimator consistent when fitting fails."""

from contextlib import contextmanager

__all__ = ["forget_fit", "unfitted_on_error"]


def forget_fit(estimator):
    """Remove every fitted attribute (``name_``) and private training state."""
    for name in list(vars(estimator)):
        fitted = name.endswith("_") and not name.startswith("__")
        if fitted or name in getattr(estimator, "_training_state", ()):
            delattr(estimator, name)


@contextmanager
def unfitted_on_error(estimator, errors=(Exception,)):
    """Leave ``estimator`` unfitted if the block raises one of ``errors``.

    A fit that fails half-way (bad input found after validation started, or
    training that diverged) must not leave an estimator that looks fitted
    with partial or non-finite parameters: later calls then raise
    ``NotFittedError`` instead of returning garbage.
    """
    try:
        yield
    except errors:
        forget_fit(estimator)
        raise
