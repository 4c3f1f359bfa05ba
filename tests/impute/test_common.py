"""scikit-learn's estimator checks on both imputers."""

import pytest
from sklearn.utils.estimator_checks import (
    check_param_validation,
    parametrize_with_checks,
)

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.impute import CRBMImputer, NearestNeighborImputer


def _estimators():
    return [
        NearestNeighborImputer(),
        CRBMImputer(
            ConditionalRBM(n_components=8, n_iter=5, random_state=0),
            n_gibbs=5,
            random_state=0,
        ),
        CRBMImputer(
            ConditionalRBM(n_components=8, order=1, n_iter=5, random_state=0),
            n_gibbs=3,
            n_draws=2,
            n_particles=3,
            random_state=0,
        ),
    ]


@parametrize_with_checks(_estimators())
def test_sklearn_compatible_estimator(estimator, check):
    check(estimator)


@pytest.mark.parametrize("estimator", _estimators(), ids=lambda e: type(e).__name__)
def test_param_validation(estimator):
    check_param_validation(type(estimator).__name__, estimator)
