"""Package-wide settings, in the manner of :func:`sklearn.set_config`."""

import threading
from contextlib import contextmanager
from numbers import Integral

__all__ = ["config_context", "get_config", "set_config"]

_global_config = {"blas_threads": "auto"}
_threadlocal = threading.local()


def _get_threadlocal_config():
    if not hasattr(_threadlocal, "config"):
        _threadlocal.config = _global_config.copy()
    return _threadlocal.config


def get_config():
    """The current values of the package's settings.

    Returns
    -------
    config : dict
        Keys are the parameter names of :func:`set_config`.

    See Also
    --------
    set_config : Change the settings.
    config_context : Change them for a block of code.

    Examples
    --------
    >>> from sklearn_crbm import get_config
    >>> get_config()["blas_threads"]
    'auto'
    """
    return _get_threadlocal_config().copy()


def _check_blas_threads(value):
    if value == "auto":
        return value
    if isinstance(value, Integral) and not isinstance(value, bool) and value >= 1:
        return int(value)
    raise ValueError(
        f"blas_threads must be 'auto' or a positive int, got {value!r}. Use e.g. "
        "sklearn_crbm.set_config(blas_threads=4) for four BLAS threads."
    )


def set_config(blas_threads=None):
    """Change the package's settings; a parameter left at ``None`` is unchanged.

    Parameters
    ----------
    blas_threads : 'auto', int or None, default=None
        BLAS threads used by the matrix products of this package's estimators
        (``fit``, ``partial_fit``, ``transform``, ``score``, ``sample`` and the
        imputers).  ``'auto'``, the initial setting, picks the number from the
        size of the products: one thread for the paper's configuration
        (batch 100, a few hundred hidden units), where more threads cost more
        in synchronisation than they save and are many times slower on a busy
        machine, and more threads only for products of at least about 10^8
        multiply-adds per thread (e.g. ``batch_size=1000`` with 1000 hidden
        units).  ``'auto'`` never uses more threads than the BLAS libraries
        are currently allowed (``OPENBLAS_NUM_THREADS``, an enclosing
        :func:`threadpoolctl.threadpool_limits`).  A positive int uses exactly
        that many threads, whatever the environment says.

    See Also
    --------
    get_config : The current settings.
    config_context : Change them for a block of code.

    Examples
    --------
    >>> import sklearn_crbm
    >>> sklearn_crbm.set_config(blas_threads=1)
    >>> sklearn_crbm.get_config()["blas_threads"]
    1
    >>> sklearn_crbm.set_config(blas_threads="auto")
    """
    local = _get_threadlocal_config()
    if blas_threads is not None:
        local["blas_threads"] = _check_blas_threads(blas_threads)


@contextmanager
def config_context(*, blas_threads=None):
    """Change the package's settings inside a ``with`` block only.

    Parameters
    ----------
    blas_threads : 'auto', int or None, default=None
        As in :func:`set_config`; ``None`` keeps the current value.

    Yields
    ------
    None

    See Also
    --------
    set_config : Change the settings for good.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm import ConditionalRBM, config_context
    >>> X = np.random.default_rng(0).standard_normal((50, 3))
    >>> with config_context(blas_threads=2):
    ...     model = ConditionalRBM(4, n_iter=2, random_state=0).fit(X)
    """
    old = get_config()
    set_config(blas_threads=blas_threads)
    try:
        yield
    finally:
        set_config(**old)
