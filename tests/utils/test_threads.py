"""The package's choice of BLAS threads (sklearn_crbm.utils._threads)."""

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from threadpoolctl import ThreadpoolController, threadpool_limits

import sklearn_crbm
from sklearn_crbm import (
    ConditionalRBM,
    CRBMImputer,
    FactoredCRBM,
    LabelledCRBM,
    StackedCRBM,
)
from sklearn_crbm.datasets import make_oscillations
from sklearn_crbm.utils._threads import (
    MIN_WORK_PER_THREAD,
    _product_size,
    auto_blas_threads,
    batch_rows,
    frame_rows,
    limit_blas_threads,
)


def blas_threads():
    """Threads each loaded BLAS library (numpy's, scipy's) may use now."""
    return [
        lib.num_threads
        for lib in ThreadpoolController().select(user_api="blas").lib_controllers
    ]


@pytest.fixture
def two_threads():
    """BLAS allowed two threads where the machine has them; the count allowed."""
    with threadpool_limits(2, user_api="blas"):
        yield min(blas_threads())


class Recorder:
    """A stand-in estimator whose method notes the BLAS threads it runs with."""

    def __init__(self, n_components):
        self.n_components = n_components
        self.seen = []

    def _matrix_product_size(self, n_features):
        """Hidden units times the frame and 3 past frames."""
        return self.n_components * n_features * 4

    @limit_blas_threads(lambda self, X: len(X))
    def run(self, X):
        self.seen.append(blas_threads())
        return self


def test_auto_blas_threads_counts_work_per_thread():
    assert auto_blas_threads(0, 8) == 1
    assert auto_blas_threads(MIN_WORK_PER_THREAD - 1, 8) == 1
    assert auto_blas_threads(2 * MIN_WORK_PER_THREAD, 8) == 2
    assert auto_blas_threads(5 * MIN_WORK_PER_THREAD, 8) == 5
    assert auto_blas_threads(50 * MIN_WORK_PER_THREAD, 8) == 8
    assert auto_blas_threads(50 * MIN_WORK_PER_THREAD, 1) == 1


def test_paper_size_runs_on_one_thread_and_restores(two_threads):
    # batch 100 x 200 hidden x 62 features x 4 (frame and 3 past): 5e6 multiply-adds
    recorder = Recorder(200).run(np.zeros((100, 62)))
    assert recorder.seen == [[1, 1]]
    assert min(blas_threads()) == two_threads


def test_large_products_use_the_threads_allowed(two_threads):
    # 1000 rows x 1000 hidden x 100 features x 4: 4e8 multiply-adds
    recorder = Recorder(1000).run(np.zeros((1000, 100)))
    assert recorder.seen == [[two_threads, two_threads]]
    with threadpool_limits(1, user_api="blas"):  # never more than allowed
        assert Recorder(1000).run(np.zeros((1000, 100))).seen == [[1, 1]]


def test_set_config_overrides_auto(two_threads):
    with sklearn_crbm.config_context(blas_threads=two_threads):
        assert Recorder(200).run(np.zeros((100, 62))).seen == [[two_threads] * 2]
    with sklearn_crbm.config_context(blas_threads=1):
        assert Recorder(1000).run(np.zeros((1000, 100))).seen == [[1, 1]]
    assert sklearn_crbm.get_config()["blas_threads"] == "auto"


def test_estimators_limit_their_loops(two_threads, monkeypatch):
    X, ids = make_oscillations(n_sequences=3, n_frames=40, n_features=4, random_state=0)
    seen = []
    from sklearn_crbm.layers._crbm import CRBMLayer

    original = CRBMLayer.cd_statistics

    def spy(*args, **kwargs):
        seen.append(min(blas_threads()))
        return original(*args, **kwargs)

    monkeypatch.setattr(CRBMLayer, "cd_statistics", spy)
    with sklearn_crbm.config_context(blas_threads=1):
        model = ConditionalRBM(5, order=2, n_iter=1, random_state=0)
        model.fit(X, sequence_ids=ids)
        StackedCRBM((5, 3), order=2, n_iter=1, random_state=0).fit(X, sequence_ids=ids)
    assert seen and set(seen) == {1}
    assert min(blas_threads()) == two_threads


def test_nested_and_concurrent_calls_restore_the_count(two_threads):
    X, ids = make_oscillations(n_sequences=4, n_frames=30, n_features=4, random_state=0)
    imputer = CRBMImputer(ConditionalRBM(5, order=2, n_iter=2), random_state=0)
    imputer.fit(X, sequence_ids=ids)
    X_missing = X.copy()
    X_missing[10:20, 1] = np.nan
    with ThreadPoolExecutor(4) as pool:
        results = list(
            pool.map(lambda _: imputer.transform(X_missing, sequence_ids=ids), range(8))
        )
    for filled in results:
        np.testing.assert_array_equal(filled, results[0])
    assert min(blas_threads()) == two_threads


def _small_models():
    yield ConditionalRBM(5, order=2, n_iter=1, random_state=0)
    yield StackedCRBM((5, 3), order=2, n_iter=1, random_state=0)
    yield FactoredCRBM(
        5, n_factors=4, n_style_features=2, order=2, n_iter=1, random_state=0
    )
    yield LabelledCRBM(5, order=2, n_iter=1, random_state=0)


@pytest.mark.parametrize("model", list(_small_models()), ids=lambda m: type(m).__name__)
def test_every_model_has_a_work_estimate(model):
    """Before and after fit, the product size is the layers' (never 0)."""
    X, ids = make_oscillations(n_sequences=2, n_frames=30, n_features=4, random_state=0)
    y = ids if isinstance(model, FactoredCRBM | LabelledCRBM) else None
    before = _product_size(batch_rows, model, (X, y), {})
    assert before >= model.batch_size * 4 * 5
    model.fit(X, y, sequence_ids=ids)
    largest = max(layer.product_size() for layer in model._fitted_layers())
    assert _product_size(batch_rows, model, (X, y), {}) == model.batch_size * largest
    assert _product_size(frame_rows, model, (X,), {}) == len(X) * largest
    imputer = CRBMImputer(model).fit(X, y, sequence_ids=ids)
    assert _product_size(lambda *a: 1, imputer, (X,), {}) == largest


def test_layer_product_size_is_its_largest_weight_matrix():
    X, ids = make_oscillations(n_sequences=2, n_frames=30, n_features=4, random_state=0)
    crbm = ConditionalRBM(5, order=2, n_iter=1).fit(X, sequence_ids=ids)
    assert crbm._layer.product_size() == (4 + 5) * (2 * 4)  # [A; B] on the past
    factored = FactoredCRBM(5, n_factors=7, n_style_features=2, order=3, n_iter=1)
    factored.fit(X, ids, sequence_ids=ids)
    assert factored._layer.product_size() == 3 * 4 * 7  # the past to the factors


def test_large_factored_model_trains_on_the_threads_allowed(two_threads, monkeypatch):
    """FactoredCRBM has no hidden_order: its work was once estimated as 0."""
    from sklearn_crbm.layers._factored import FactoredLayer

    seen = []
    original = FactoredLayer.cd_statistics

    def spy(*args, **kwargs):
        seen.append(min(blas_threads()))
        return original(*args, **kwargs)

    monkeypatch.setattr(FactoredLayer, "cd_statistics", spy)
    X, ids = make_oscillations(
        n_sequences=2, n_frames=520, n_features=100, random_state=0
    )
    # batch 1000 x 1000 hidden units x 200 factors: 2e8 multiply-adds
    model = FactoredCRBM(
        1000, n_factors=200, n_style_features=2, order=2, batch_size=1000, n_iter=1
    )
    # the estimate is the layer's, before fit (the layer fit would make) and after
    before = _product_size(batch_rows, model, (X, ids), {})
    assert before >= 2 * MIN_WORK_PER_THREAD
    model.fit(X, ids, sequence_ids=ids)
    model.partial_fit(X, ids, sequence_ids=ids)
    assert _product_size(batch_rows, model, (X, ids), {}) == before
    assert seen and set(seen) == {two_threads}
    assert min(blas_threads()) == two_threads


@pytest.mark.parametrize("value", [0, -1, 1.5, True, "all", "none"])
def test_set_config_rejects_bad_thread_counts(value):
    with pytest.raises(
        ValueError, match="blas_threads must be 'auto' or a positive int"
    ):
        sklearn_crbm.set_config(blas_threads=value)
