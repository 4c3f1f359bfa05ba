"""The paper's motion preprocessing as scikit-learn transformers.

Raw channels (Euler angles, root position) -> :class:`ExpMapEncoder` ->
:class:`RootRelativeEncoder` -> :class:`StandardScaler`; every step has an
exact ``inverse_transform``.  :func:`make_motion_preprocessor` builds the
chain for a skeleton, :func:`make_motion_pipeline` the chain and a model in
a :class:`MotionPipeline`, which generates raw channels and writes them as
BVH or AMC files.  :class:`MotionContext` derives per-frame control signals
(forward speed, turning rate) from the motion.
"""

from ._context import MotionContext
from ._data import StandardScaler
from ._expmap import ExpMapEncoder
from ._pipeline import MotionPipeline, make_motion_pipeline, make_motion_preprocessor
from ._root import RootRelativeEncoder

__all__ = [
    "ExpMapEncoder",
    "MotionContext",
    "MotionPipeline",
    "RootRelativeEncoder",
    "StandardScaler",
    "make_motion_pipeline",
    "make_motion_preprocessor",
]
