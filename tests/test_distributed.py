"""The same grid search on a dask.distributed cluster as on this machine.

A ``LocalCluster`` of two single-threaded worker processes on 127.0.0.1
runs a small search through joblib's dask backend, and CRBMImputer fills
blocks of sequences there; the results must equal the local run's.  Needs the ``distributed`` extra (``dask[distributed]``).
"""

from concurrent.futures import ThreadPoolExecutor

import joblib
import numpy as np
import pytest
import sklearn
from distributed import Client, LocalCluster, get_task_stream
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.model_selection import GridSearchCV, GroupKFold
from sklearn.pipeline import Pipeline

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.datasets import load_cmu35, make_oscillations
from sklearn_crbm.impute import CRBMImputer, NearestNeighborImputer
from sklearn_crbm.model_selection import make_imputation_scorer
from sklearn_crbm.preprocessing import make_motion_preprocessor

# Wall-clock bound of one search on the cluster, worker start-up excluded.
SEARCH_TIMEOUT_S = 180
CV = GroupKFold(n_splits=3)


@pytest.fixture(scope="module")
def client(request):
    cluster = LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
        silence_logs=40,
    )
    client = Client(cluster, timeout="60s")

    def close():
        client.close()
        cluster.close()

    request.addfinalizer(close)
    client.wait_for_workers(2, timeout=120)
    return client


@pytest.fixture(scope="module")
def cmu(data_home):
    bunch = load_cmu35(data_home, subset="train")
    keep = np.isin(bunch.sequence_ids, [0, 1, 2, 3, 4, 5, 16, 17, 18])
    return bunch.data[keep], bunch.sequence_ids[keep], bunch.skeleton


def _search(cmu):
    X, ids, skeleton = cmu
    pipeline = Pipeline(
        make_motion_preprocessor(skeleton).steps
        + [("crbm", ConditionalRBM(8, n_iter=10, batch_size=50, random_state=0))]
    )
    return GridSearchCV(pipeline, {"crbm__order": [0, 2]}, cv=CV, n_jobs=2)


def _fit(search, X, ids, backend, client=None):
    """Fit ``search`` under a joblib backend, within ``SEARCH_TIMEOUT_S``."""

    def run():
        with sklearn.config_context(enable_metadata_routing=True):
            with joblib.parallel_backend(backend):
                return search.fit(X, groups=ids, sequence_ids=ids)

    with ThreadPoolExecutor(max_workers=1) as pool:
        return pool.submit(run).result(timeout=SEARCH_TIMEOUT_S)


def test_grid_search_on_a_local_cluster_equals_the_local_run(client, cmu):
    X, ids, _ = cmu
    local = _fit(_search(cmu), X, ids, "sequential")
    with get_task_stream(client) as tasks:
        remote = _fit(_search(cmu), X, ids, "dask")
    assert len(tasks.data) >= 6  # 2 candidates x 3 folds ran on the workers
    workers = {task["worker"] for task in tasks.data}
    assert workers <= set(client.scheduler_info()["workers"])
    for k in range(3):
        key = f"split{k}_test_score"
        assert_allclose(remote.cv_results_[key], local.cv_results_[key], rtol=1e-12)
    assert remote.best_params_ == local.best_params_ == {"crbm__order": 2}
    assert_array_equal(
        remote.best_estimator_.named_steps["crbm"].components_,
        local.best_estimator_.named_steps["crbm"].components_,
    )


def test_imputer_search_on_a_local_cluster_equals_the_local_run(client, cmu):
    X, ids, skeleton = cmu
    with sklearn.config_context(enable_metadata_routing=True):
        pre = make_motion_preprocessor(skeleton)
        Z = pre.fit_transform(X, sequence_ids=ids)
    scorer = make_imputation_scorer(
        bones=["lfemur", "ltibia"], feature_names=pre.get_feature_names_out()
    )
    searches = [
        GridSearchCV(NearestNeighborImputer(), {}, scoring=scorer, cv=CV, n_jobs=2)
        for _ in range(2)
    ]
    local = _fit(searches[0], Z, ids, "sequential")
    remote = _fit(searches[1], Z, ids, "dask")
    for k in range(3):
        key = f"split{k}_test_score"
        assert_allclose(remote.cv_results_[key], local.cv_results_[key], rtol=1e-12)
    assert np.all(local.cv_results_["mean_test_score"] < 0)


def test_crbm_imputer_fills_blocks_of_sequences_on_the_cluster(client):
    # 70 sequences: three blocks of sequences, filled by the workers.
    X, ids = make_oscillations(n_sequences=70, n_frames=12, random_state=0)
    X_missing = X.copy()
    X_missing[np.tile(np.arange(12), 70) >= 6, :2] = np.nan
    model = ConditionalRBM(8, order=2, n_iter=5, random_state=0)
    imputer = CRBMImputer(model, n_gibbs=3, random_state=0, n_jobs=2)
    imputer.fit(X, sequence_ids=ids)
    local = imputer.transform(X_missing, sequence_ids=ids)
    with get_task_stream(client) as tasks:
        with joblib.parallel_backend("dask"):
            remote = imputer.transform(X_missing, sequence_ids=ids)
    assert len(tasks.data) >= 3
    assert_array_equal(remote, local)
    assert not np.isnan(remote).any()
