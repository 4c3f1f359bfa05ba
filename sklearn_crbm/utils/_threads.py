"""How many BLAS threads the package's hot loops use.

numpy and scipy each load their own OpenBLAS, which by default runs one thread
per core.  The products of this package's loops are small (a minibatch of 100
frames against a few hundred hidden units): split over threads they run no
faster on a quiet machine, and many times slower on a busy one, where the
threads spin waiting for each other.  Each public method that runs such a loop
is wrapped in :func:`limit_blas_threads`, which picks the thread count from
the size of the loop's matrix products (:func:`sklearn_crbm.set_config`
overrides it) and puts the previous count back afterwards.
"""

import functools
import threading
from contextlib import contextmanager

import numpy as np
from threadpoolctl import ThreadpoolController

from .._config import get_config
from ._parallel import BLOCK_SEQUENCES, SAMPLE_BLOCK
from ._sequences import CHUNK_FRAMES

__all__ = [
    "MIN_WORK_PER_THREAD",
    "auto_blas_threads",
    "batch_rows",
    "chain_rows",
    "frame_rows",
    "limit_blas_threads",
    "sequence_rows",
]

# Multiply-adds one matrix product must have per BLAS thread before another
# thread pays: below this, one thread.  The paper's training product is about
# 5e6 (batch 100 x 200 hidden x 62 x 4 inputs); batch 1000 with 1000 hidden
# units and 400 inputs (4e8) gets four threads where four cores are allowed.
MIN_WORK_PER_THREAD = 10**8

_controller = None
# The BLAS thread count is one setting of the whole process.  The first of
# the package's calls to start (in any thread) sets it; calls that start while
# it runs (a stack's layers, an imputer's model, other threads) keep it; the
# last to finish puts the previous count back.
_lock = threading.Lock()
_active = 0
_limiter = None


def _blas_controller():
    global _controller
    if _controller is None:
        _controller = ThreadpoolController().select(user_api="blas")
    return _controller


def auto_blas_threads(work, allowed):
    """Threads for products of ``work`` multiply-adds, at most ``allowed``.

    Parameters
    ----------
    work : int
        Multiply-adds of one matrix product.
    allowed : int
        Most threads to use.

    Returns
    -------
    n_threads : int
        One per :data:`MIN_WORK_PER_THREAD` multiply-adds, from 1 to
        ``allowed``.
    """
    return int(max(1, min(allowed, work // MIN_WORK_PER_THREAD)))


def _chosen_threads(controller, work):
    setting = get_config()["blas_threads"]
    if setting != "auto":
        return setting
    allowed = min((lib.num_threads for lib in controller.lib_controllers), default=1)
    return auto_blas_threads(work(), allowed)


@contextmanager
def _blas_limit(work):
    global _active, _limiter
    with _lock:
        if _active == 0:
            controller = _blas_controller()
            _limiter = controller.limit(limits=_chosen_threads(controller, work))
        _active += 1
    try:
        yield
    finally:
        with _lock:
            _active -= 1
            if _active == 0:
                _limiter.restore_original_limits()
                _limiter = None


def limit_blas_threads(rows):
    """Decorate a method to run with the package's choice of BLAS threads.

    Parameters
    ----------
    rows : callable
        ``rows(estimator, *args, **kwargs)`` with the method's arguments:
        the number of rows of one matrix product in the method's loop.  The
        product's size is that times the multiply-adds per row of the
        model's largest product, which the model's layers give
        (``estimator._matrix_product_size(n_features)``, from
        :meth:`~sklearn_crbm.layers.ConditionalLayer.product_size`).  Errors
        count as a small product: the method itself reports bad input.

    Returns
    -------
    decorator : callable
    """

    def decorate(method):
        @functools.wraps(method)
        def wrapper(self, *args, **kwargs):
            with _blas_limit(lambda: _product_size(rows, self, args, kwargs)):
                return method(self, *args, **kwargs)

        return wrapper

    return decorate


def _product_size(rows, estimator, args, kwargs):
    try:
        n_rows = rows(estimator, *args, **kwargs)
        return n_rows * estimator._matrix_product_size(_n_features(args))
    except Exception:  # bad input: the method raises its own clear error
        return 0


def _n_features(args):
    """Features of the data passed first (None: the model's own, once fitted)."""
    if args and np.ndim(args[0]) == 2:
        return int(np.shape(args[0])[1])
    return None


def batch_rows(estimator, *args, **kwargs):
    """Training: one minibatch."""
    return int(estimator.batch_size)


def frame_rows(estimator, X, *args, **kwargs):
    """Inference on every frame: up to one chunk of frames."""
    return min(len(X), CHUNK_FRAMES)


def sequence_rows(estimator, n_samples, *, history=None, n_sequences=1, **kwargs):
    """Generation: the sequences generated together."""
    if history is not None and np.ndim(history) == 3:
        n_sequences = len(history)
    return min(int(n_sequences), SAMPLE_BLOCK)


def chain_rows(estimator, X, n_samples=None, *, sequence_ids=None, **kwargs):
    """On-line fill-in: sequences of one block times the chains of each."""
    n_sequences = 1 if sequence_ids is None else len(np.unique(sequence_ids))
    draws = estimator.n_draws if n_samples is None else int(n_samples)
    return min(n_sequences, BLOCK_SEQUENCES) * draws * estimator.n_particles
