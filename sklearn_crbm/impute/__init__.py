"""Filling in missing motion-capture channels (paper §4.4)."""

from ._crbm_imputer import CRBMImputer
from ._nearest_neighbor import NearestNeighborImputer

__all__ = ["CRBMImputer", "NearestNeighborImputer"]
