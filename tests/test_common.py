"""scikit-learn's estimator checks on every public estimator of the package.

As in imbalanced-learn's ``test_common.py``: one instance generator,
:func:`_tested_estimators`, gives every estimator small settings (few hidden
units and epochs) and what it needs to run on the checks' data, and
:func:`_expected_failed_checks` lists, with its reason, every check an
estimator is expected to fail.
"""

import pytest
from sklearn.utils.estimator_checks import (
    check_param_validation,
    parametrize_with_checks,
)

from sklearn_crbm import (
    AutoregressiveImputer,
    ConditionalRBM,
    CRBMImputer,
    ExpMapEncoder,
    NearestNeighborImputer,
    RootRelativeEncoder,
    StackedCRBM,
    StandardScaler,
)

PUBLIC_ESTIMATORS = {
    AutoregressiveImputer,
    ConditionalRBM,
    StackedCRBM,
    CRBMImputer,
    NearestNeighborImputer,
    ExpMapEncoder,
    RootRelativeEncoder,
    StandardScaler,
}

ROW_DEPENDENCE = (
    "rows are frames of sequences: each frame's output depends on the frames "
    "before it in its sequence, so outputs change when rows are dropped or "
    "reordered"
)
ROOT_NEEDS_SIX_COLUMNS = (
    "the check's data has fewer than six columns, but RootRelativeEncoder needs "
    "the six root channels (tx, ty, tz, ex, ey, ez); test_root.py checks the "
    "same properties on root data"
)


def _tested_estimators():
    """One small instance of every public estimator, CRBMImputer in three settings."""
    yield ConditionalRBM(n_components=8, n_iter=5, random_state=0)
    yield ConditionalRBM(
        n_components=8, n_iter=5, init="autoregressive", random_state=0
    )
    yield StackedCRBM((8, 6), order=3, n_iter=5, random_state=0)
    yield CRBMImputer(
        ConditionalRBM(n_components=8, n_iter=5, random_state=0),
        n_gibbs=5,
        random_state=0,
    )
    yield CRBMImputer(
        ConditionalRBM(n_components=8, order=1, n_iter=5, random_state=0),
        n_gibbs=3,
        n_draws=2,
        n_particles=3,
        random_state=0,
    )
    yield CRBMImputer(
        StackedCRBM((8, 6), order=2, n_iter=3, random_state=0),
        n_gibbs=3,
        random_state=0,
    )
    yield NearestNeighborImputer()
    yield AutoregressiveImputer(order=1)
    yield ExpMapEncoder()
    yield ExpMapEncoder(continuous=True)
    yield RootRelativeEncoder()
    yield StandardScaler()


def _expected_failed_checks(estimator):
    if isinstance(estimator, ConditionalRBM | StackedCRBM):
        return {
            "check_methods_subset_invariance": ROW_DEPENDENCE,
            "check_methods_sample_order_invariance": ROW_DEPENDENCE,
        }
    if isinstance(estimator, RootRelativeEncoder):
        return dict.fromkeys(_ROOT_CHECKS_ON_FEW_COLUMNS, ROOT_NEEDS_SIX_COLUMNS)
    return {}


_ROOT_CHECKS_ON_FEW_COLUMNS = [
    "check_dict_unchanged",
    "check_dont_overwrite_parameters",
    "check_estimators_dtypes",
    "check_estimators_fit_returns_self",
    "check_estimators_overwrite_params",
    "check_estimators_pickle",
    "check_f_contiguous_array_estimator",
    "check_fit2d_predict1d",
    "check_fit_check_is_fitted",
    "check_fit_idempotent",
    "check_fit_score_takes_y",
    "check_methods_sample_order_invariance",
    "check_methods_subset_invariance",
    "check_n_features_in",
    "check_n_features_in_after_fitting",
    "check_pipeline_consistency",
    "check_positive_only_tag_during_fit",
    "check_readonly_memmap_input",
    "check_transformer_data_not_an_array",
    "check_transformer_general",
    "check_transformer_preserve_dtypes",
]


def test_every_public_estimator_is_checked():
    assert {type(e) for e in _tested_estimators()} == PUBLIC_ESTIMATORS


@parametrize_with_checks(
    list(_tested_estimators()), expected_failed_checks=_expected_failed_checks
)
def test_sklearn_compatible_estimator(estimator, check):
    check(estimator)


@pytest.mark.parametrize(
    "estimator", list(_tested_estimators()), ids=lambda e: type(e).__name__
)
def test_param_validation(estimator):
    check_param_validation(type(estimator).__name__, estimator)
