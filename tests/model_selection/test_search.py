"""Searching hidden units and order over the motion pipeline on CMU subject 35.

The searches run the whole Pipeline (exp maps -> body-centred root ->
z-scores -> model) inside ``GridSearchCV``/``RandomizedSearchCV`` with
``GroupKFold`` by sequence and ``sequence_ids`` routed to every step and to
``score``.  Models are small and train for few epochs, on 9 of the 31
training trials (6 walks, 3 jogs; every fold holds out 2 walks and 1 jog).
"""

import numpy as np
import pytest
import sklearn
from numpy.testing import assert_allclose, assert_array_equal
from scipy.stats import randint
from sklearn.base import clone
from sklearn.model_selection import GridSearchCV, GroupKFold, RandomizedSearchCV
from sklearn.pipeline import Pipeline
from threadpoolctl import threadpool_limits

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.model_selection import make_prediction_scorer
from sklearn_crbm.models._stacked import StackedCRBM
from sklearn_crbm.preprocessing import make_motion_preprocessor

CV = GroupKFold(n_splits=3)
pytestmark = pytest.mark.usefixtures("one_blas_thread")


@pytest.fixture(scope="module")
def cmu(cmu_search_trials):
    return cmu_search_trials


def _pipeline(skeleton, name, model):
    return Pipeline(make_motion_preprocessor(skeleton).steps + [(name, model)])


def _crbm(**params):
    # the numbers below were measured with clean histories (the paper's)
    return ConditionalRBM(
        **{
            "n_iter": 30,
            "batch_size": 50,
            "history_noise": 0.0,
            "random_state": 0,
            **params,
        }
    )


def _scores(search, split=None):
    """``{(order, n_components, learning_rate): score}`` from ``cv_results_``."""
    key = "mean_test_score" if split is None else f"split{split}_test_score"
    results = search.cv_results_
    return {
        tuple(params[name] for name in sorted(params)): score
        for params, score in zip(results["params"], results[key], strict=True)
    }


@pytest.fixture(scope="module")
def crbm_search(cmu):
    X, ids, skeleton = cmu
    grid = {
        "crbm__order": [0, 2],
        "crbm__n_components": [4, 128],
        "crbm__learning_rate": [1e-3, 1e-2],
    }
    with threadpool_limits(limits=1, user_api="blas"):
        with sklearn.config_context(enable_metadata_routing=True):
            search = GridSearchCV(_pipeline(skeleton, "crbm", _crbm()), grid, cv=CV)
            search.fit(X, groups=ids, sequence_ids=ids)
    return search


def test_folds_hold_out_whole_sequences(cmu):
    X, ids, _ = cmu
    for train, test in CV.split(X, groups=ids):
        assert not set(ids[train]) & set(ids[test])
        assert len(np.unique(ids[test])) == 3


def test_grid_search_routes_sequence_ids_to_every_step_and_to_score(cmu, crbm_search):
    X, ids, skeleton = cmu
    train, test = next(CV.split(X, groups=ids))
    params = {"crbm__order": 2, "crbm__n_components": 4, "crbm__learning_rate": 1e-3}
    pipeline = clone(_pipeline(skeleton, "crbm", _crbm())).set_params(**params)
    with sklearn.config_context(enable_metadata_routing=True):
        pipeline.fit(X[train], sequence_ids=ids[train])
        by_hand = pipeline.score(X[test], sequence_ids=ids[test])
        # Without ids the held-out trials would be one long sequence.
        as_one_sequence = pipeline.score(X[test])
    index = crbm_search.cv_results_["params"].index(params)
    assert crbm_search.cv_results_["split0_test_score"][index] == pytest.approx(by_hand)
    assert as_one_sequence != pytest.approx(by_hand)


def test_score_prefers_models_with_history_over_order_zero(crbm_search):
    # Held-out log-likelihood per frame in nats, mean over 3 folds, e.g.
    # order 0: -88 .. -110; order 2: -66 .. -69.
    for split in (None, 0, 1, 2):
        scores = _scores(crbm_search, split)
        with_history = [s for (_, _, order), s in scores.items() if order == 2]
        without = [s for (_, _, order), s in scores.items() if order == 0]
        assert min(with_history) > max(without)
    assert crbm_search.best_params_["crbm__order"] == 2


def test_score_does_not_simply_favour_bigger_models(crbm_search):
    # With a larger step 128 units overfit the 6 training trials: their
    # held-out log-likelihood is lower in every fold (mean -68.8 against
    # -67.2 nats per frame for 4 units).
    for split in (None, 0, 1, 2):
        scores = _scores(crbm_search, split)
        assert scores[(1e-2, 4, 2)] > scores[(1e-2, 128, 2)] + 0.5
    assert crbm_search.best_params_["crbm__learning_rate"] == 1e-3


def test_prediction_scorer_in_a_search(cmu):
    X, ids, skeleton = cmu
    grid = {"crbm__order": [0, 2]}
    with sklearn.config_context(enable_metadata_routing=True):
        search = GridSearchCV(
            _pipeline(skeleton, "crbm", _crbm(n_components=4)),
            grid,
            cv=CV,
            scoring=make_prediction_scorer(),
        ).fit(X, groups=ids, sequence_ids=ids)
    # minus the one-step mean squared error in z-score units
    scores = search.cv_results_["mean_test_score"]
    assert -1.0 < scores[1] < 0 and scores[0] < scores[1]


def test_randomized_search_over_order_and_hidden_units(cmu):
    X, ids, skeleton = cmu
    distributions = {"crbm__order": [0, 1, 2], "crbm__n_components": randint(2, 64)}
    with sklearn.config_context(enable_metadata_routing=True):
        search = RandomizedSearchCV(
            _pipeline(skeleton, "crbm", _crbm(learning_rate=1e-2)),
            distributions,
            n_iter=4,
            cv=CV,
            random_state=2,
        ).fit(X, groups=ids, sequence_ids=ids)
    results = search.cv_results_
    orders = np.array(results["param_crbm__order"], dtype=int)
    assert set(orders) >= {0} and (orders > 0).any()
    scores = results["mean_test_score"]
    assert scores[orders > 0].min() > scores[orders == 0].max()
    assert search.best_params_["crbm__order"] > 0
    with sklearn.config_context(enable_metadata_routing=True):
        assert np.isfinite(search.score(X, sequence_ids=ids))


def test_grid_search_over_stacked_crbm(cmu):
    X, ids, skeleton = cmu
    stack = StackedCRBM(n_iter=30, batch_size=50, learning_rate=1e-2, random_state=0)
    grid = {"stack__order": [0, 2], "stack__n_components": [(4, 4), (128, 64)]}
    with sklearn.config_context(enable_metadata_routing=True):
        search = GridSearchCV(_pipeline(skeleton, "stack", stack), grid, cv=CV)
        search.fit(X, groups=ids, sequence_ids=ids)
    scores = {
        (p["stack__order"], p["stack__n_components"]): s
        for p, s in zip(
            search.cv_results_["params"],
            search.cv_results_["mean_test_score"],
            strict=True,
        )
    }
    assert min(scores[(2, (4, 4))], scores[(2, (128, 64))]) > max(
        scores[(0, (4, 4))], scores[(0, (128, 64))]
    )
    assert scores[(2, (4, 4))] > scores[(2, (128, 64))]
    assert search.best_params_ == {"stack__order": 2, "stack__n_components": (4, 4)}


def test_grid_search_with_two_jobs_matches_one_job(cmu):
    X, ids, skeleton = cmu
    grid = {"crbm__order": [0, 2]}
    results = []
    with sklearn.config_context(enable_metadata_routing=True):
        for n_jobs in (1, 2):
            search = GridSearchCV(
                _pipeline(skeleton, "crbm", _crbm(n_components=8)),
                grid,
                cv=CV,
                n_jobs=n_jobs,
            ).fit(X, groups=ids, sequence_ids=ids)
            results.append(search)
    serial, parallel = results
    for k in range(3):
        key = f"split{k}_test_score"
        assert_allclose(parallel.cv_results_[key], serial.cv_results_[key], rtol=1e-12)
    assert parallel.best_params_ == serial.best_params_
    assert_array_equal(
        parallel.best_estimator_.named_steps["crbm"].components_,
        serial.best_estimator_.named_steps["crbm"].components_,
    )
