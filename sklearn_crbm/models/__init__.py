"""The estimators and the one base class they share.

:class:`~sklearn_crbm.models._base.BaseCRBM` (``_base.py``) holds what every
model does with its fitted layers: the hooks a model fills in, the checks of
its input, inference, scoring and generation.  Its context (``_context.py``)
and its seeds and judging of generated motion (``_sampling.py``) live beside
it; ``_one_layer.py`` trains a model of one conditional layer, ``_style.py``
adds the style labels; one module per estimator.  The package re-exports the
estimators: import them from :mod:`sklearn_crbm`.
"""

from ._crbm import ConditionalRBM
from ._factored import FactoredCRBM
from ._labelled import LabelledCRBM
from ._stacked import StackedCRBM

__all__ = ["ConditionalRBM", "FactoredCRBM", "LabelledCRBM", "StackedCRBM"]
