"""The paper's motion preprocessing as scikit-learn transformers.

Raw channels (Euler angles, root position) -> :class:`ExpMapEncoder` ->
:class:`RootRelativeEncoder` -> :class:`StandardScaler`; every step has an
exact ``inverse_transform``.  :func:`make_motion_preprocessor` builds the
chain for a skeleton.
"""

from ._data import StandardScaler
from ._expmap import ExpMapEncoder
from ._pipeline import make_motion_preprocessor
from ._root import RootRelativeEncoder

__all__ = [
    "ExpMapEncoder",
    "RootRelativeEncoder",
    "StandardScaler",
    "make_motion_preprocessor",
]
