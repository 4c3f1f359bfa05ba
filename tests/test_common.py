"""scikit-learn's estimator checks on every estimator of the package."""

import pytest
from sklearn.utils.estimator_checks import (
    check_param_validation,
    parametrize_with_checks,
)

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.impute import AutoregressiveImputer

ROW_DEPENDENCE = (
    "rows are frames of sequences: each frame's output depends on the frames "
    "before it in its sequence, so outputs change when rows are dropped or "
    "reordered"
)


def _estimators():
    return [
        ConditionalRBM(n_components=8, n_iter=5, random_state=0),
        AutoregressiveImputer(order=1),
    ]


def _expected_failed_checks(estimator):
    if isinstance(estimator, ConditionalRBM):
        return {
            "check_methods_subset_invariance": ROW_DEPENDENCE,
            "check_methods_sample_order_invariance": ROW_DEPENDENCE,
        }
    return {}


@parametrize_with_checks(_estimators(), expected_failed_checks=_expected_failed_checks)
def test_sklearn_compatible_estimator(estimator, check):
    check(estimator)


@pytest.mark.parametrize("estimator", _estimators(), ids=lambda e: type(e).__name__)
def test_param_validation(estimator):
    check_param_validation(type(estimator).__name__, estimator)
