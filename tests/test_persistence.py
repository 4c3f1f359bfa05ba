"""Pickle and joblib round trips of every fitted estimator, and pickle formats.

A loaded estimator must give exactly the transforms, predictions, samples and
fills of the one that was saved, for the same ``random_state``, and keep
training where it stopped.  Pickles carry the package's pickle format: the
pickle of this format stored in ``data/`` must load and compute what it
computed when it was saved, and pickles of another format must fail with a
ValueError that names it and says to refit -- among them real pickles of
commit 08bf639, before the layer redesign (``data/README.md`` says how they
were made).  Loading a pickle written under another scikit-learn version
warns with ``InconsistentVersionWarning``, as scikit-learn's own estimators
do.

Running this file as a script writes the stored pickle of the present format
and the outputs it must give; a change of the layout raises ``PICKLE_FORMAT``
first (see ``sklearn_crbm/utils/_persistence.py``)::

    PYTHONPATH=$PWD python tests/test_persistence.py
"""

import io
import json
import pickle
import sys
import types
import warnings
from pathlib import Path

import joblib
import numpy as np
import pytest
import sklearn
import sklearn.base
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.base import BaseEstimator
from sklearn.exceptions import InconsistentVersionWarning
from sklearn.pipeline import Pipeline

from sklearn_crbm import ConditionalRBM, FactoredCRBM, LabelledCRBM
from sklearn_crbm.datasets import (
    load_cmu35,
    make_oscillations,
    make_styled_oscillations,
    make_walker,
)
from sklearn_crbm.impute import CRBMImputer, NearestNeighborImputer
from sklearn_crbm.models._stacked import StackedCRBM
from sklearn_crbm.preprocessing import (
    ExpMapEncoder,
    RootRelativeEncoder,
    StandardScaler,
    make_motion_preprocessor,
)
from sklearn_crbm.utils import _persistence
from sklearn_crbm.utils._persistence import PICKLE_FORMAT, VersionedPickleMixin

DATA = Path(__file__).parent / "data"
STORED = DATA / f"pickle_format{PICKLE_FORMAT}.pkl"
STORED_OUTPUTS = DATA / f"pickle_format{PICKLE_FORMAT}_outputs.json"

X_OSC, IDS_OSC = make_oscillations(n_sequences=4, n_frames=40, random_state=0)
WALKER = make_walker(n_sequences=2, n_frames=40, random_state=0)
# a control signal per frame: the sequence's sign and a ramp
C_OSC = np.column_stack(
    [np.where(IDS_OSC % 2 == 0, 1.0, -1.0), np.linspace(-1, 1, len(X_OSC))]
)
X_MISSING = X_OSC[IDS_OSC == 3].copy()
X_MISSING[20:, :2] = np.nan
X_STY, IDS_STY, STY = make_styled_oscillations(
    n_sequences=4, n_frames=20, random_state=0
)
X_STY_MISSING = X_STY[IDS_STY == 1].copy()
X_STY_MISSING[10:, :2] = np.nan
STYLE_MODELS = (FactoredCRBM, LabelledCRBM)


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


def _crbm_context():
    return ConditionalRBM(n_components=8, order=2, n_iter=5, random_state=0).fit(
        X_OSC, sequence_ids=IDS_OSC, context=C_OSC
    )


def _stack():
    return StackedCRBM((8, 4), order=1, n_iter=5, random_state=0).fit(
        X_OSC, sequence_ids=IDS_OSC
    )


def _small_factored():
    return FactoredCRBM(
        8,
        n_factors=4,
        n_style_features=3,
        order=2,
        cd_steps=1,
        n_iter=3,
        n_gibbs=3,
        random_state=0,
    )


def _small_labelled():
    return LabelledCRBM(8, order=2, n_iter=3, n_gibbs=3, random_state=0)


def _factored():
    return _small_factored().fit(X_STY, STY, sequence_ids=IDS_STY)


def _labelled():
    return _small_labelled().fit(X_STY, STY, sequence_ids=IDS_STY)


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


def _context_imputer():
    model = ConditionalRBM(n_components=8, order=2, n_iter=5, random_state=0)
    train = IDS_OSC < 3
    return CRBMImputer(model, n_gibbs=5, random_state=0).fit(
        X_OSC[train], sequence_ids=IDS_OSC[train], context=C_OSC[train]
    )


def _style_imputer():
    return CRBMImputer(_small_factored(), n_gibbs=3, n_particles=4, random_state=0).fit(
        X_STY, STY, sequence_ids=IDS_STY
    )


def _nn_imputer():
    return NearestNeighborImputer().fit(X_OSC[IDS_OSC < 3])


def _model_outputs(model, X, ids, styles=None, context=None):
    """What a fitted model computes on ``X``; a style model given ``styles``,
    a model of a context given ``context``.

    Every method takes the styles of the frames (``score`` as ``y``);
    generation takes the first and the last style (or row of context).
    """
    given = {} if styles is None else {"style": styles}
    first, last = (
        ({}, {})
        if styles is None
        else (
            {"style": model.classes_[0]},
            {"style": model.classes_[-1]},
        )
    )
    if context is not None:
        given = {"context": context}
        first, last = {"context": context[:1]}, {"context": context[-1:]}
    # the stored outputs were drawn with one mean-field step, the default then
    first, last = {**first, "n_mean_field": 1}, {**last, "n_mean_field": 1}
    outputs = [
        model.transform(X, sequence_ids=ids, **given),
        model.predict_next(X, sequence_ids=ids, **given),
        model.score_samples(X, sequence_ids=ids, **given),
        np.atleast_1d(
            model.score(X, styles, sequence_ids=ids, context=given.get("context"))
        ),
        model.sample(10, n_sequences=3, random_state=0, **first),
        model.sample(10, n_sequences=3, **last),  # the model's own random_state
    ]
    if styles is not None:
        outputs.append(model.predict_proba(X, sequence_ids=ids))
    return outputs


def _outputs(estimator):
    """Everything a fitted estimator computes, as a list of arrays."""
    if isinstance(estimator, CRBMImputer) and isinstance(
        estimator.estimator_, STYLE_MODELS
    ):
        return [
            estimator.transform(X_STY_MISSING, style="high"),
            estimator.transform(X_STY_MISSING),  # the style inferred
        ]
    if isinstance(estimator, CRBMImputer) and estimator.estimator_.n_context_:
        return [estimator.transform(X_MISSING, context=C_OSC[IDS_OSC == 3])]
    if isinstance(estimator, (CRBMImputer, NearestNeighborImputer)):
        return [estimator.transform(X_MISSING)]
    if isinstance(estimator, (ExpMapEncoder, StandardScaler)):
        Z = estimator.transform(WALKER.data)
        return [Z, estimator.inverse_transform(Z)]
    if isinstance(estimator, RootRelativeEncoder):
        encoded = ExpMapEncoder(WALKER.skeleton).fit_transform(WALKER.data)
        Z = estimator.transform(encoded, sequence_ids=WALKER.sequence_ids)
        return [Z, estimator.inverse_transform(Z, sequence_ids=WALKER.sequence_ids)]
    if isinstance(estimator, STYLE_MODELS):
        return _model_outputs(estimator, X_STY, IDS_STY, STY)
    if estimator.n_context_:
        return _model_outputs(estimator, X_OSC, IDS_OSC, context=C_OSC)
    return _model_outputs(estimator, X_OSC, IDS_OSC)


FITTED = [
    _crbm,
    _crbm_context,
    _stack,
    _factored,
    _labelled,
    _expmap,
    _root,
    _scaler,
    _crbm_imputer,
    _context_imputer,
    _style_imputer,
    _nn_imputer,
]


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


# name -> (unfitted model, training data before sequence_ids, sequence_ids)
PARTIAL_FITS = {
    "crbm": (
        lambda: ConditionalRBM(n_components=8, order=2, random_state=0),
        (X_OSC,),
        IDS_OSC,
    ),
    "factored": (_small_factored, (X_STY, STY), IDS_STY),
    "labelled": (_small_labelled, (X_STY, STY), IDS_STY),
}


@pytest.mark.parametrize("round_trip", ROUND_TRIPS, ids=["pickle", "joblib"])
@pytest.mark.parametrize("name", list(PARTIAL_FITS))
def test_partial_fit_continues_identically_after_a_round_trip(name, round_trip):
    make, data, ids = PARTIAL_FITS[name]
    model = make()
    model.partial_fit(*data, sequence_ids=ids)
    loaded = round_trip(model)
    # The momentum, epoch count and random state travel with the model.
    model.partial_fit(*data, sequence_ids=ids)
    loaded.partial_fit(*data, sequence_ids=ids)
    assert loaded.n_iter_ == model.n_iter_ == 2
    assert_array_equal(loaded._fitted_layers()[0].flat, model._fitted_layers()[0].flat)


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


# --------------------------------------------------------------- formats
SMALL_OSC = make_oscillations(
    n_sequences=2, n_frames=10, n_features=3, random_state=0
) + (None,)
SMALL_STY = make_styled_oscillations(
    n_sequences=2, n_frames=10, n_features=3, random_state=0
)


def _stored_models():
    """name -> (the unfitted model the stored pickle holds, its data (X, ids, y))."""
    return {
        "crbm": (ConditionalRBM(4, order=2, n_iter=3, random_state=0), SMALL_OSC),
        "factored": (
            FactoredCRBM(
                4,
                n_factors=3,
                n_style_features=2,
                order=2,
                cd_steps=1,
                n_iter=3,
                n_gibbs=2,
                random_state=0,
            ),
            SMALL_STY,
        ),
        "labelled": (
            LabelledCRBM(4, order=2, n_iter=3, n_gibbs=2, random_state=0),
            SMALL_STY,
        ),
    }


def _write_stored():
    """Fit the stored models; write their pickle and their outputs."""
    models, outputs = {}, {}
    for name, (model, (X, ids, styles)) in _stored_models().items():
        models[name] = model.fit(X, styles, sequence_ids=ids)
        for i, output in enumerate(_model_outputs(model, X, ids, styles)):
            outputs[f"{name}_{i}"] = output
    STORED.write_bytes(pickle.dumps(models))
    # JSON: Python's float repr gives every float32 and float64 back exactly
    arrays = {
        key: {"dtype": str(a.dtype), "shape": a.shape, "values": a.ravel().tolist()}
        for key, a in ((key, np.asarray(a)) for key, a in outputs.items())
    }
    STORED_OUTPUTS.write_text(json.dumps(arrays))


@pytest.fixture(scope="module")
def stored():
    """The stored models, loaded, and the outputs they gave when saved."""
    models = pickle.loads(STORED.read_bytes())
    arrays = json.loads(STORED_OUTPUTS.read_text())
    outputs = {
        key: np.array(a["values"], dtype=a["dtype"]).reshape(a["shape"])
        for key, a in arrays.items()
    }
    return models, outputs


@pytest.mark.parametrize("name", list(_stored_models()))
def test_stored_pickle_of_this_format_computes_what_it_computed_when_saved(
    name, stored
):
    models, expected = stored
    model = models[name]
    unfitted, (X, ids, styles) = _stored_models()[name]
    assert type(model) is type(unfitted)
    # A hyper-parameter added or removed is a new layout: a new format.
    assert model.get_params().keys() == unfitted.get_params().keys()
    outputs = _model_outputs(model, X, ids, styles)
    assert len(outputs) == sum(key.startswith(f"{name}_") for key in expected)
    for i, output in enumerate(outputs):
        assert_allclose(output, expected[f"{name}_{i}"], rtol=1e-12, atol=0)


def _joblib_loads(payload):
    return joblib.load(io.BytesIO(payload))


# Real pickles of commit 08bf639 (see data/README.md): a fitted ConditionalRBM
# of the layout before the layer redesign, and a StandardScaler, which loaded
# as if it were new.
OLD_PICKLES = {
    "crbm_08bf639.pkl": r"before the layer redesign .*\(pickle format 0\): its "
    r"fitted parameters are a sklearn_crbm\._crbm_math\.CRBMParameters, .* no "
    r"longer reads\. Refit the model",
    "scaler_08bf639.pkl": r"This StandardScaler was pickled by an older "
    r"sklearn_crbm that recorded no pickle format \(format 0, .* reads pickle "
    r"format 1 only\. Refit the StandardScaler",
}


@pytest.mark.parametrize("loads", [pickle.loads, _joblib_loads])
@pytest.mark.parametrize("name", list(OLD_PICKLES))
def test_pickles_of_an_older_layout_say_to_refit(name, loads):
    with pytest.raises(ValueError, match=OLD_PICKLES[name]):
        loads((DATA / name).read_bytes())


@pytest.mark.parametrize("make", FITTED, ids=lambda f: f.__name__.strip("_"))
def test_every_estimator_pickles_its_format(make, monkeypatch):
    payload = pickle.dumps(make())
    monkeypatch.setattr(_persistence, "PICKLE_FORMAT", PICKLE_FORMAT + 1)
    with pytest.raises(
        ValueError,
        match=rf"pickle format {PICKLE_FORMAT}, an older layout, but sklearn_crbm "
        rf".* reads pickle format {PICKLE_FORMAT + 1} only\. Refit the",
    ):
        pickle.loads(payload)


def test_pickle_of_a_newer_format_fails_before_its_state_is_read(monkeypatch):
    """A later format may hold classes this version lacks: the format comes first."""
    later = types.ModuleType("sklearn_crbm_of_a_later_release")

    class Layer:  # a class of the later release's fitted state
        pass

    Layer.__module__, Layer.__qualname__ = later.__name__, "Layer"
    later.Layer = Layer
    model = _crbm()
    model.layer_of_a_later_release_ = Layer()
    with monkeypatch.context() as patch:
        patch.setitem(sys.modules, later.__name__, later)
        patch.setattr(_persistence, "PICKLE_FORMAT", PICKLE_FORMAT + 1)
        payload = pickle.dumps(model)
    with pytest.raises(
        ValueError,
        match=rf"This ConditionalRBM was pickled by sklearn_crbm \S+ in pickle format "
        rf"{PICKLE_FORMAT + 1}, which this version does not know: sklearn_crbm "
        rf"\S+ reads pickle format {PICKLE_FORMAT}\.",
    ):
        pickle.loads(payload)


if __name__ == "__main__":
    _write_stored()
    print(f"wrote {STORED} and {STORED_OUTPUTS}")
