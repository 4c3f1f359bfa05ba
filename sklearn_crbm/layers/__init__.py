"""Conditional layers: the models' parameters and math, one class per kind.

A layer models a frame given its past and its context
(:class:`ConditionalLayer`, whose module docstring states the interface);
given both it is an RBM of the frame, a :class:`FrameRBMs`, whose visible
units' math is :class:`GaussianUnits` or :class:`BinaryUnits`.  Training,
generation, fill-in and the likelihood talk to layers through that
interface only, so a new kind of model is a new layer class (its trainable
arrays packed by :class:`PackedParameters`) and its estimator.

- :class:`CRBMLayer`: the conditional RBM (Taylor, Hinton & Roweis, 2006),
  its context added to the dynamic biases;
- :class:`FactoredLayer`: the factored CRBM (Taylor & Hinton, 2009), its
  context gating the factors.
"""

from ._base import (
    BinaryUnits,
    ConditionalLayer,
    FrameRBMs,
    GaussianUnits,
    TrainingWorkspace,
)
from ._crbm import CRBMFrames, CRBMLayer
from ._factored import FactoredFrames, FactoredLayer
from ._parameters import PackedParameters, ParameterGroup

__all__ = [
    "BinaryUnits",
    "CRBMFrames",
    "CRBMLayer",
    "ConditionalLayer",
    "FactoredFrames",
    "FactoredLayer",
    "FrameRBMs",
    "GaussianUnits",
    "PackedParameters",
    "ParameterGroup",
    "TrainingWorkspace",
]
