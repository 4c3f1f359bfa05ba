"""Pickle and joblib round trips of every fitted estimator.

A loaded estimator must give exactly the transforms, predictions, samples and
fills of the one that was saved, for the same ``random_state``, and keep
training where it stopped.  Loading a pickle written under another
scikit-learn version warns with ``InconsistentVersionWarning``, as
scikit-learn's own estimators do.
"""

import io
import pickle
import warnings

import joblib
import numpy as np
import pytest
import sklearn
import sklearn.base
from numpy.testing import assert_array_equal
from sklearn.base import BaseEstimator, clone
from sklearn.exceptions import InconsistentVersionWarning
from sklearn.pipeline import Pipeline

from sklearn_crbm import ConditionalRBM
from sklearn_crbm._stacked import StackedCRBM
from sklearn_crbm.datasets import load_cmu35, make_oscillations, make_walker
from sklearn_crbm.impute import CRBMImputer, NearestNeighborImputer
from sklearn_crbm.preprocessing import (
    ExpMapEncoder,
    RootRelativeEncoder,
    StandardScaler,
    make_motion_preprocessor,
)
from sklearn_crbm.utils._persistence import VersionedPickleMixin

X_OSC, IDS_OSC = make_oscillations(n_sequences=4, n_frames=40, random_state=0)
WALKER = make_walker(n_sequences=2, n_frames=40, random_state=0)
X_MISSING = X_OSC[IDS_OSC == 3].copy()
X_MISSING[20:, :2] = np.nan


def _pickle(estimator):
    return pickle.loads(pickle.dumps(estimator))


def _joblib(estimator):
    buffer = io.BytesIO()
    joblib.dump(estimator, buffer)
    buffer.seek(0)
    return joblib.load(buffer)


ROUND_TRIPS = [_pickle, _joblib]


def _crbm():
    return ConditionalRBM(n_components=8, order=2, n_iter=5, random_state=0).fit(
        X_OSC, sequence_ids=IDS_OSC
    )


def _stack():
    return StackedCRBM((8, 4), order=1, n_iter=5, random_state=0).fit(
        X_OSC, sequence_ids=IDS_OSC
    )


def _expmap():
    return ExpMapEncoder(WALKER.skeleton).fit(WALKER.data)


def _root():
    encoded = ExpMapEncoder(WALKER.skeleton).fit_transform(WALKER.data)
    return RootRelativeEncoder(WALKER.skeleton).fit(
        encoded, sequence_ids=WALKER.sequence_ids
    )


def _scaler():
    return StandardScaler().fit(WALKER.data)


def _crbm_imputer():
    model = ConditionalRBM(n_components=8, order=2, n_iter=5, random_state=0)
    return CRBMImputer(model, n_gibbs=5, random_state=0).fit(
        X_OSC[IDS_OSC < 3], sequence_ids=IDS_OSC[IDS_OSC < 3]
    )


def _nn_imputer():
    return NearestNeighborImputer().fit(X_OSC[IDS_OSC < 3])


def _outputs(estimator):
    """Everything a fitted estimator computes, as a list of arrays."""
    if isinstance(estimator, (CRBMImputer, NearestNeighborImputer)):
        return [estimator.transform(X_MISSING)]
    if isinstance(estimator, (ExpMapEncoder, StandardScaler)):
        Z = estimator.transform(WALKER.data)
        return [Z, estimator.inverse_transform(Z)]
    if isinstance(estimator, RootRelativeEncoder):
        encoded = ExpMapEncoder(WALKER.skeleton).fit_transform(WALKER.data)
        Z = estimator.transform(encoded, sequence_ids=WALKER.sequence_ids)
        return [Z, estimator.inverse_transform(Z, sequence_ids=WALKER.sequence_ids)]
    return [
        estimator.transform(X_OSC, sequence_ids=IDS_OSC),
        estimator.predict_next(X_OSC, sequence_ids=IDS_OSC),
        np.atleast_1d(estimator.score(X_OSC, sequence_ids=IDS_OSC)),
        estimator.sample(10, n_sequences=3, random_state=0),
        estimator.sample(10, n_sequences=3),  # the estimator's own random_state
    ]


FITTED = [_crbm, _stack, _expmap, _root, _scaler, _crbm_imputer, _nn_imputer]


@pytest.mark.parametrize("round_trip", ROUND_TRIPS, ids=["pickle", "joblib"])
@pytest.mark.parametrize("make", FITTED, ids=lambda f: f.__name__.strip("_"))
def test_round_trip_gives_identical_outputs(make, round_trip):
    estimator = make()
    loaded = round_trip(estimator)
    assert type(loaded) is type(estimator)
    assert loaded.get_params().keys() == estimator.get_params().keys()
    for before, after in zip(_outputs(estimator), _outputs(loaded), strict=True):
        assert_array_equal(after, before)


def test_crbm_imputer_draws_are_identical_after_a_round_trip():
    imputer = _crbm_imputer()
    loaded = _joblib(imputer)
    assert_array_equal(
        loaded.sample(X_MISSING, n_samples=3, random_state=1),
        imputer.sample(X_MISSING, n_samples=3, random_state=1),
    )


@pytest.mark.parametrize("round_trip", ROUND_TRIPS, ids=["pickle", "joblib"])
def test_partial_fit_continues_identically_after_a_round_trip(round_trip):
    model = ConditionalRBM(n_components=8, order=2, random_state=0)
    model.partial_fit(X_OSC, sequence_ids=IDS_OSC)
    loaded = round_trip(model)
    # The momentum, epoch count and random state travel with the model.
    model.partial_fit(X_OSC, sequence_ids=IDS_OSC)
    loaded.partial_fit(X_OSC, sequence_ids=IDS_OSC)
    assert loaded.n_iter_ == model.n_iter_ == 2
    assert_array_equal(loaded.components_, model.components_)
    assert_array_equal(loaded.autoregressive_, model.autoregressive_)


def test_whole_pipeline_on_cmu35_round_trips(data_home, tmp_path):
    cmu = load_cmu35(data_home, subset="test")
    X, ids = cmu.data, cmu.sequence_ids
    with sklearn.config_context(enable_metadata_routing=True):
        pipeline = Pipeline(
            make_motion_preprocessor(cmu.skeleton).steps
            + [("crbm", ConditionalRBM(16, order=2, n_iter=5, random_state=0))]
        ).fit(X, sequence_ids=ids)
        joblib.dump(pipeline, tmp_path / "pipeline.joblib")
        loaded = joblib.load(tmp_path / "pipeline.joblib")
        for model in (pipeline, loaded):
            hidden = model.transform(X, sequence_ids=ids)
            score = model.score(X, sequence_ids=ids)
            # Generated frames mapped back to raw channels through the encoders.
            new = model.named_steps["crbm"].sample(20, n_sequences=2, random_state=0)
            new_ids = np.repeat([0, 1], 20)
            raw = model[:-1].inverse_transform(new, sequence_ids=new_ids)
            if model is pipeline:
                expected = (hidden, score, raw)
        assert_array_equal(hidden, expected[0])
        assert score == expected[1]
        assert_array_equal(raw, expected[2])
    assert raw.shape == (40, X.shape[1])


def _pickle_as_version(estimator, version, monkeypatch):
    """Pickle ``estimator`` as if scikit-learn ``version`` had written it."""
    with monkeypatch.context() as patch:
        patch.setattr(sklearn, "__version__", version)
        patch.setattr(sklearn.base, "__version__", version)
        return pickle.dumps(estimator)


class _Versioned(VersionedPickleMixin, BaseEstimator):
    def __init__(self, alpha=1.0):
        self.alpha = alpha


def test_mixin_records_the_version_and_warns_on_another():
    model = _Versioned(alpha=2.0)
    model.coef_ = np.arange(3.0)
    assert model.__getstate__()["_sklearn_version"] == sklearn.__version__
    with warnings.catch_warnings():
        warnings.simplefilter("error", InconsistentVersionWarning)
        same = pickle.loads(pickle.dumps(model))
    assert "_sklearn_version" not in vars(same)
    assert_array_equal(same.coef_, model.coef_)
    state = model.__getstate__()
    state["_sklearn_version"] = "0.24.2"
    other = _Versioned.__new__(_Versioned)
    with pytest.warns(InconsistentVersionWarning, match="0.24.2") as record:
        other.__setstate__(state)
    assert record[0].message.estimator_name == "_Versioned"
    assert other.alpha == 2.0 and "_sklearn_version" not in vars(other)
    del state["_sklearn_version"]  # written before versions were recorded
    with pytest.warns(InconsistentVersionWarning, match="pre-0.18"):
        _Versioned.__new__(_Versioned).__setstate__(state)


@pytest.mark.parametrize("make", FITTED, ids=lambda f: f.__name__.strip("_"))
def test_loading_under_another_sklearn_version_warns(make, monkeypatch):
    estimator = make()
    payload = _pickle_as_version(estimator, "1.0.0", monkeypatch)
    with pytest.warns(InconsistentVersionWarning) as record:
        loaded = pickle.loads(payload)
    versions = {
        w.message.original_sklearn_version
        for w in record
        if isinstance(w.message, InconsistentVersionWarning)
    }
    assert versions == {"1.0.0"}
    assert type(loaded) is type(estimator)
    # The same scikit-learn version loads silently.
    with warnings.catch_warnings():
        warnings.simplefilter("error", InconsistentVersionWarning)
        pickle.loads(pickle.dumps(estimator))


def test_whole_pipeline_under_another_version_warns_for_every_step(monkeypatch):
    with sklearn.config_context(enable_metadata_routing=True):
        pipeline = Pipeline(
            make_motion_preprocessor(WALKER.skeleton).steps
            + [("crbm", ConditionalRBM(8, order=1, n_iter=2, random_state=0))]
        ).fit(WALKER.data, sequence_ids=WALKER.sequence_ids)
    payload = _pickle_as_version(pipeline, "1.0.0", monkeypatch)
    with pytest.warns(InconsistentVersionWarning) as record:
        pickle.loads(payload)
    warned = {
        w.message.estimator_name
        for w in record
        if isinstance(w.message, InconsistentVersionWarning)
    }
    assert warned >= {
        "ExpMapEncoder",
        "RootRelativeEncoder",
        "StandardScaler",
        "ConditionalRBM",
    }


@pytest.mark.parametrize(
    "make, added",
    [
        (
            lambda: ConditionalRBM(5, order=2, n_iter=3, random_state=0),
            {
                "centering": False,
                "history_noise_fraction": 1.0,
                "average_fraction": 0.0,
            },
        ),
        (
            lambda: StackedCRBM((5, 4), order=2, n_iter=3, random_state=0),
            {"history_noise_fraction": 1.0, "average_fraction": 0.0},
        ),
    ],
)
def test_pickles_from_before_a_parameter_was_added_still_work(make, added):
    """A pickle without a later parameter loads with the value it was trained under."""
    X, ids = make_oscillations(n_sequences=3, n_frames=30, random_state=0)
    model = make().fit(X, sequence_ids=ids)
    state = model.__getstate__()
    for name in added:
        del state[name]  # as an earlier release wrote it
    old = type(model).__new__(type(model))
    old.__setstate__(state)
    for name, value in added.items():
        assert old.get_params()[name] == value
    assert_array_equal(
        old.transform(X, sequence_ids=ids), model.transform(X, sequence_ids=ids)
    )
    clone(old).fit(X, sequence_ids=ids)
    if hasattr(old, "partial_fit"):
        old.partial_fit(X, sequence_ids=ids)
