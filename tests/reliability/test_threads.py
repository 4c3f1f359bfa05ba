"""Thread safety: a fitted model called from many threads at once gives what
serial calls give.

Each task gets its own input (a different slice, scaling or seed), so that a
buffer or random state shared between calls would mix up their results.
"""

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
import sklearn
from numpy.testing import assert_array_equal

from sklearn_crbm.datasets import make_oscillations

N_TASKS = 24
N_WORKERS = 8


@pytest.fixture(scope="module")
def inputs():
    """Per task: frames (300 of them, 4 features), their sequence ids, a seed."""
    X, ids = make_oscillations(n_sequences=6, n_frames=50, n_features=4, random_state=1)
    tasks = []
    for k in range(N_TASKS):
        rolled = np.roll(X, 7 * k, axis=0) * (1.0 + 0.05 * k)
        tasks.append((rolled, ids, k))
    return tasks


def _concurrently(function, tasks):
    """``function(*task)`` for every task: serially, then all at once in threads."""
    serial = [function(*task) for task in tasks]
    with ThreadPoolExecutor(max_workers=N_WORKERS) as pool:
        threaded = list(pool.map(lambda task: function(*task), tasks))
    # and again in reverse order, so that different calls overlap
    with ThreadPoolExecutor(max_workers=N_WORKERS) as pool:
        reverse = list(pool.map(lambda task: function(*task), tasks[::-1]))[::-1]
    for k, (a, b, c) in enumerate(zip(serial, threaded, reverse, strict=True)):
        assert_array_equal(a, b, err_msg=f"task {k} differs when run in threads")
        assert_array_equal(a, c, err_msg=f"task {k} differs when run in threads")
    return serial


CALLS = {
    "ConditionalRBM.transform": lambda f, X, ids, k: f["crbm"].transform(
        X, sequence_ids=ids
    ),
    "ConditionalRBM.score_samples": lambda f, X, ids, k: f["crbm"].score_samples(
        X, sequence_ids=ids
    ),
    "ConditionalRBM.predict_next": lambda f, X, ids, k: f["crbm"].predict_next(
        X, sequence_ids=ids
    ),
    "ConditionalRBM.score": lambda f, X, ids, k: np.array(
        f["crbm"].score(X, sequence_ids=ids)
    ),
    "ConditionalRBM.sample": lambda f, X, ids, k: f["crbm"].sample(
        20, n_sequences=3, random_state=k
    ),
    "ConditionalRBM.sample(history)": lambda f, X, ids, k: f["crbm"].sample(
        10, history=X[:5], n_sequences=2, hidden_noise=0.5, random_state=k
    ),
    "StackedCRBM.transform": lambda f, X, ids, k: f["stack"].transform(
        X, sequence_ids=ids
    ),
    "StackedCRBM.predict_next": lambda f, X, ids, k: f["stack"].predict_next(
        X, sequence_ids=ids
    ),
    "StackedCRBM.sample": lambda f, X, ids, k: f["stack"].sample(
        10, n_sequences=2, random_state=k
    ),
    "FactoredCRBM.transform": lambda f, X, ids, k: f["factored"].transform(
        X, style="high", sequence_ids=ids
    ),
    "FactoredCRBM.predict_proba": lambda f, X, ids, k: f["factored"].predict_proba(
        X, sequence_ids=ids
    ),
    "FactoredCRBM.sample": lambda f, X, ids, k: f["factored"].sample(
        10, style="low", n_sequences=2, random_state=k
    ),
    "LabelledCRBM.score_samples": lambda f, X, ids, k: f["labelled"].score_samples(
        X, sequence_ids=ids
    ),
    "LabelledCRBM.sample(history)": lambda f, X, ids, k: f["labelled"].sample(
        10, history=X[:5], style="high", n_sequences=2, random_state=k
    ),
    "CRBMImputer(FactoredCRBM).sample": lambda f, X, ids, k: f[
        "factored_imputer"
    ].sample(_erase(X, k), 2, sequence_ids=ids, random_state=k),
    "CRBMImputer.sample": lambda f, X, ids, k: f["crbm_imputer"].sample(
        _erase(X, k), 2, sequence_ids=ids, random_state=k
    ),
    "NearestNeighborImputer.transform": lambda f, X, ids, k: f["nn_imputer"].transform(
        _erase(X, k), sequence_ids=ids
    ),
}


def _erase(X, k):
    """X with a different block of channels erased for every task."""
    X = X.copy()
    rng = np.random.default_rng(k)
    X[rng.random(X.shape) < 0.3] = np.nan
    X[40 + k : 80 + k, : 1 + k % 3] = np.nan
    return X


@pytest.mark.parametrize("name", list(CALLS))
def test_concurrent_calls_equal_serial_calls(name, fitted, inputs):
    call = CALLS[name]
    results = _concurrently(lambda X, ids, k: call(fitted, X, ids, k), inputs)
    assert all(np.isfinite(r).all() for r in results)
    # the tasks really differ, so a mix-up between threads would show
    assert not np.array_equal(results[0], results[1])


def test_concurrent_imputation_equals_serial(fitted, inputs):
    imputer = fitted["crbm_imputer"]  # random_state=0: transform is deterministic
    results = _concurrently(
        lambda X, ids, k: imputer.transform(_erase(X, k), sequence_ids=ids), inputs
    )
    for (X, _, k), filled in zip(inputs, results, strict=True):
        erased = _erase(X, k)
        observed = ~np.isnan(erased)
        assert not np.isnan(filled).any()
        assert_array_equal(filled[observed], erased[observed])


def test_concurrent_preprocessing_equals_serial(fitted, walker):
    pipeline = fitted["preprocessor"]
    tasks = [
        (np.roll(walker.data, 3 * k, axis=0), walker.sequence_ids, k)
        for k in range(N_TASKS)
    ]

    # scikit-learn's configuration is per thread: each task turns routing on
    def encode(X, ids, k):
        with sklearn.config_context(enable_metadata_routing=True):
            return pipeline.transform(X, sequence_ids=ids)

    def round_trip(X, ids, k):
        with sklearn.config_context(enable_metadata_routing=True):
            return pipeline.inverse_transform(encode(X, ids, k), sequence_ids=ids)

    encoded = _concurrently(encode, tasks)
    _concurrently(round_trip, tasks)
    assert not np.array_equal(encoded[0], encoded[1])


def test_concurrent_fits_of_clones_equal_serial_fits(factories, inputs):
    """Fitting separate estimators in threads (GridSearchCV with a threading
    backend) shares no state: each gives what a serial fit gives."""

    def fit(X, ids, k):
        model = factories["crbm"](random_state=k % 4).fit(
            X[:120], sequence_ids=ids[:120]
        )
        return np.concatenate(
            [model.components_.ravel(), model.transform(X[:30]).ravel()]
        )

    results = _concurrently(fit, inputs[:12])
    assert not np.array_equal(results[0], results[1])
