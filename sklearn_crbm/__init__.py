"""Conditional Restricted Boltzmann Machines for human motion, for scikit-learn.

A scikit-learn compatible implementation of Taylor, Hinton & Roweis,
"Modeling Human Motion Using Binary Latent Variables" (NIPS 2006).
"""

from ._crbm import ConditionalRBM, TrainingDivergedError

__version__ = "0.1.0.dev0"

__all__ = ["ConditionalRBM", "TrainingDivergedError", "__version__"]
