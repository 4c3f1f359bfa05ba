"""Removed in the layer redesign (November 2026); kept so old pickles fail clearly.

Fitted models pickled before the redesign hold objects of this module's
classes; loading one raises a ValueError that says to refit, instead of a
ModuleNotFoundError.
"""

from .utils._persistence import raise_removed_layout

_CLASSES = frozenset(
    {
        "CDWorkspace",
        "CRBMParameters",
        "HiddenSampler",
        "MomentumUpdate",
        "ParameterAverage",
        "ParameterGroup",
    }
)


def __getattr__(name):
    if name in _CLASSES:
        raise_removed_layout(__name__, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
