"""The warnings and errors of the package, as :mod:`sklearn.exceptions` has them.

:class:`GenerationWarning` says that generated motion died out or blew up;
:class:`TrainingDivergedError` that training produced non-finite weights.
"""

__all__ = ["GenerationWarning", "TrainingDivergedError"]


class GenerationWarning(UserWarning):
    """Generated motion died out into a pose, or blew up.

    Raised by ``sample`` when a generated sequence, over its last frames,
    moves less than half as much as the training sequences do (it came to
    rest), or when it leaves the training data's range by more than ten of
    its standard deviations or becomes non-finite.  The message says which
    sequences and what to try.

    Examples
    --------
    >>> import warnings
    >>> from sklearn_crbm.exceptions import GenerationWarning
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     warnings.warn("frozen", GenerationWarning)
    >>> caught[0].category.__name__
    'GenerationWarning'
    """


class TrainingDivergedError(FloatingPointError):
    """Training produced non-finite weights (the learning rate is too large)."""
