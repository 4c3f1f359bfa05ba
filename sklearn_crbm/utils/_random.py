"""Random generators from scikit-learn's ``random_state``."""

import numpy as np
from sklearn.utils import check_random_state

__all__ = ["rng_from"]


def rng_from(random_state):
    """A numpy Generator seeded from a scikit-learn ``random_state``.

    The estimators take ``random_state`` as scikit-learn does (None, an int
    or a ``RandomState``) but draw from a :class:`numpy.random.Generator`
    (fast float32 draws): one int drawn from ``random_state`` seeds it, so a
    ``RandomState`` instance advances by one draw.

    Examples
    --------
    >>> from sklearn_crbm.utils._random import rng_from
    >>> float(rng_from(0).random()) == float(rng_from(0).random())
    True
    """
    seed = check_random_state(random_state).randint(np.iinfo(np.int32).max)
    return np.random.default_rng(seed)
