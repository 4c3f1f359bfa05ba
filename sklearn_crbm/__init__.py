"""Conditional Restricted Boltzmann Machines for human motion, for scikit-learn.

A scikit-learn compatible implementation of Taylor, Hinton & Roweis,
"Modeling Human Motion Using Binary Latent Variables" (NIPS 2006): the
conditional RBM and its two-level stack, the paper's motion-capture
preprocessing, on-line filling in of missing channels, and generation; and
models of many styles in one (the factored CRBM of Taylor & Hinton, ICML
2009, and a CRBM whose biases take the style labels).
"""

from . import datasets, exceptions, metrics, model_selection, plotting, preprocessing
from ._config import config_context, get_config, set_config
from ._version import __version__
from .exceptions import TrainingDivergedError
from .impute import AutoregressiveImputer, CRBMImputer, NearestNeighborImputer
from .models import ConditionalRBM, FactoredCRBM, LabelledCRBM, StackedCRBM
from .preprocessing import (
    ExpMapEncoder,
    RootRelativeEncoder,
    StandardScaler,
    make_motion_preprocessor,
)

__all__ = [
    "AutoregressiveImputer",
    "CRBMImputer",
    "ConditionalRBM",
    "ExpMapEncoder",
    "FactoredCRBM",
    "LabelledCRBM",
    "NearestNeighborImputer",
    "RootRelativeEncoder",
    "StackedCRBM",
    "StandardScaler",
    "TrainingDivergedError",
    "__version__",
    "config_context",
    "datasets",
    "exceptions",
    "get_config",
    "make_motion_preprocessor",
    "metrics",
    "model_selection",
    "plotting",
    "preprocessing",
    "set_config",
]
