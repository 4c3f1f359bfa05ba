"""Pickles that name their layout: a format number, and the scikit-learn version.

Every estimator of the package pickles through :class:`VersionedPickleMixin`,
which writes ``PICKLE_FORMAT``, the number of the layout of the package's
fitted state.  Loading a pickle of another format raises a ValueError that
names the format and the package version that wrote it and says to refit,
instead of failing deep inside pickle or, worse, loading a model that
computes something else.  Increase ``PICKLE_FORMAT`` with every change that
an older pickle would not survive: a fitted attribute renamed or reshaped, a
hyper-parameter added, a class of the fitted state moved or removed.

Formats:

0. Before formats were recorded.  Fitted models of that layout hold objects
   of the module ``sklearn_crbm._crbm_math``, which no longer exists: loading
   one says to refit (:func:`raise_removed_layout`).
1. The layer layout: each model's parameters in a layer object
   (:mod:`sklearn_crbm.layers`).

Pickles name the modules of their classes.  Where a class of a stored
format has moved since, :data:`MOVED_MODULES` and :data:`MOVED_CLASSES` say
where it lives now and :data:`REMOVED_MODULES` which modules are gone; an
import hook resolves those old names only, and only when something (a
pickle) imports them.
"""

import importlib
import importlib.abc
import importlib.util
import sys
import warnings
from functools import partial, reduce

import sklearn
from sklearn.exceptions import InconsistentVersionWarning

from .._version import __version__

__all__ = [
    "PICKLE_FORMAT",
    "VersionedPickleMixin",
    "check_pickle_format",
    "raise_removed_layout",
]

PICKLE_FORMAT = 1

# The key of the format in an estimator's pickled state.
_FORMAT_KEY = "_sklearn_crbm_pickle_format"

# Modules that pickles of a stored format name, and where they live now.
MOVED_MODULES = {
    # the estimators, into sklearn_crbm.models
    "sklearn_crbm._crbm": "sklearn_crbm.models._crbm",
    "sklearn_crbm._factored": "sklearn_crbm.models._factored",
    "sklearn_crbm._labelled": "sklearn_crbm.models._labelled",
    "sklearn_crbm._stacked": "sklearn_crbm.models._stacked",
    # the layers, into sklearn_crbm.layers
    "sklearn_crbm._layer": "sklearn_crbm.layers._base",
    "sklearn_crbm._crbm_layer": "sklearn_crbm.layers._crbm",
    "sklearn_crbm._factored_layer": "sklearn_crbm.layers._factored",
    "sklearn_crbm._parameters": "sklearn_crbm.layers._parameters",
}

# Classes of a stored format renamed: the layer of a LabelledCRBM pickled
# before contexts were real-valued is a CRBM layer of the label weights.
MOVED_CLASSES = {
    "sklearn_crbm._labelled.LabelledLayer": "sklearn_crbm.layers._crbm.CRBMLayer",
}

# Modules of a layout no longer read (the format 0 layout), and the classes
# that its pickles name in them.
REMOVED_MODULES = {
    "sklearn_crbm._crbm_math": frozenset(
        {
            "CDWorkspace",
            "CRBMParameters",
            "HiddenSampler",
            "MomentumUpdate",
            "ParameterAverage",
            "ParameterGroup",
        }
    ),
}


def _moved_attribute(old_module, name):
    """The class that a pickle names ``old_module.name``, where it lives now."""
    if name.startswith("__"):  # what tools ask of any module (__file__, ...)
        raise AttributeError(f"module {old_module!r} has no attribute {name!r}")
    if name in REMOVED_MODULES.get(old_module, ()):
        raise_removed_layout(old_module, name)
    if old_module in REMOVED_MODULES:
        raise AttributeError(f"module {old_module!r} has no attribute {name!r}")
    module, _, new_name = MOVED_CLASSES.get(
        f"{old_module}.{name}", f"{MOVED_MODULES[old_module]}.{name}"
    ).rpartition(".")
    try:
        return getattr(importlib.import_module(module), new_name)
    except AttributeError:
        raise AttributeError(
            f"module {old_module!r} has no attribute {name!r}"
        ) from None


class _StoredModuleNames(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Imports the module names of stored pickles as their new places.

    Consulted only for names no real module has (it comes last on
    :data:`sys.meta_path`) and only for those in :data:`MOVED_MODULES` and
    :data:`REMOVED_MODULES`: such a module holds nothing and looks every
    name up where it lives now.
    """

    def find_spec(self, fullname, path=None, target=None):
        if fullname in MOVED_MODULES or fullname in REMOVED_MODULES:
            return importlib.util.spec_from_loader(fullname, self)
        return None

    def create_module(self, spec):
        return None

    def exec_module(self, module):
        module.__getattr__ = partial(_moved_attribute, module.__name__)


if not any(isinstance(finder, _StoredModuleNames) for finder in sys.meta_path):
    sys.meta_path.append(_StoredModuleNames())


def _refit_advice(name):
    return (
        f"Refit the {name} with sklearn_crbm {__version__} and save it "
        "again (or load it with the release that saved it)."
    )


def check_pickle_format(saved_format, name, saved_by="an older sklearn_crbm"):
    """Raise a ValueError unless ``saved_format`` is the format this code reads."""
    if saved_format == PICKLE_FORMAT:
        return
    reads = f"sklearn_crbm {__version__} reads pickle format {PICKLE_FORMAT}"
    if saved_format is None:
        raise ValueError(
            f"This {name} was pickled by {saved_by} that recorded no pickle format "
            f"(format 0, the first layout), but {reads} only. " + _refit_advice(name)
        )
    if isinstance(saved_format, int) and saved_format < PICKLE_FORMAT:
        raise ValueError(
            f"This {name} was pickled by {saved_by} in pickle format "
            f"{saved_format}, an older layout, but {reads} only. " + _refit_advice(name)
        )
    raise ValueError(
        f"This {name} was pickled by {saved_by} in pickle format {saved_format!r}, "
        f"which this version does not know: {reads}. Load it with the release "
        "that saved it (or a later one), or refit it with this version."
    )


def raise_removed_layout(module, name):
    """Say that a pickle holds ``module.name`` of a layout no longer read."""
    raise ValueError(
        f"This model was pickled by an sklearn_crbm from before the layer "
        f"redesign (pickle format 0): its fitted parameters are "
        f"a {module}.{name}, a layout that sklearn_crbm {__version__} "
        f"(pickle format {PICKLE_FORMAT}) no longer reads. " + _refit_advice("model")
    )


def _unpickle(saved_format, saved_version, module, qualname):
    """An empty estimator to fill with its pickled state, once its format is read.

    Pickle calls this before it reads the state, so a pickle of another
    format fails here with a clear message even where its state holds
    classes that no longer exist; the class is looked up only afterwards.
    """
    check_pickle_format(
        saved_format, qualname, saved_by=f"sklearn_crbm {saved_version}"
    )
    cls = reduce(getattr, qualname.split("."), importlib.import_module(module))
    return cls.__new__(cls)


class VersionedPickleMixin:
    """Pickle with the package's format; warn when scikit-learn's version differs.

    Loading a pickle of another format (:data:`PICKLE_FORMAT`) raises a
    ValueError that names it and says to refit.  As
    :class:`sklearn.base.BaseEstimator` does for ``sklearn.*`` classes only,
    the pickle records the scikit-learn version, and loading it under
    another warns with :class:`~sklearn.exceptions.InconsistentVersionWarning`.
    Put the mixin to the left of ``BaseEstimator``.

    Examples
    --------
    >>> import pickle
    >>> import warnings
    >>> from sklearn.base import BaseEstimator
    >>> from sklearn_crbm.utils._persistence import VersionedPickleMixin
    >>> class Model(VersionedPickleMixin, BaseEstimator):
    ...     pass
    >>> state = Model().__getstate__()
    >>> state["_sklearn_version"] = "0.24.2"  # as if pickled by an old release
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     Model.__new__(Model).__setstate__(state)
    >>> type(caught[0].message).__name__
    'InconsistentVersionWarning'
    >>> del state["_sklearn_crbm_pickle_format"]  # as pickled before formats
    >>> Model.__new__(Model).__setstate__(state)
    Traceback (most recent call last):
    ...
    ValueError: This Model was pickled by ... that recorded no pickle format ...
    """

    def __reduce_ex__(self, protocol):
        cls = type(self)
        saved = (PICKLE_FORMAT, __version__, cls.__module__, cls.__qualname__)
        return _unpickle, saved, self.__getstate__()

    def __getstate__(self):
        state = super().__getstate__()
        return dict(
            state, _sklearn_version=sklearn.__version__, **{_FORMAT_KEY: PICKLE_FORMAT}
        )

    def __setstate__(self, state):
        state = dict(state)
        check_pickle_format(state.pop(_FORMAT_KEY, None), type(self).__name__)
        pickled_version = state.pop("_sklearn_version", "pre-0.18")
        if pickled_version != sklearn.__version__:
            warnings.warn(
                InconsistentVersionWarning(
                    estimator_name=type(self).__name__,
                    current_sklearn_version=sklearn.__version__,
                    original_sklearn_version=pickled_version,
                )
            )
        super().__setstate__(state)
