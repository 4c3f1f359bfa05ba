"""Filling in missing motion-capture channels (paper §4.4)."""

from ._autoregressive import AutoregressiveImputer
from ._crbm_imputer import CRBMImputer
from ._nearest_neighbor import NearestNeighborImputer

__all__ = ["AutoregressiveImputer", "CRBMImputer", "NearestNeighborImputer"]
