"""Numerical safety: divergence, float32/float64 on real data, large inputs."""

import copy
import warnings

import numpy as np
import pytest
import sklearn

from sklearn_crbm import TrainingDivergedError
from sklearn_crbm.datasets import load_cmu35, make_walker
from sklearn_crbm.impute import CRBMImputer
from sklearn_crbm.layers._base import logistic
from sklearn_crbm.layers._crbm import CRBMFrames, CRBMLayer
from sklearn_crbm.preprocessing import (
    ExpMapEncoder,
    RootRelativeEncoder,
    make_motion_preprocessor,
)
from sklearn_crbm.utils._rotations import euler_to_matrix

DTYPES = [np.float32, np.float64]
# Floating-point trouble that matters: overflow, 0/0, x/0.  (Underflow to 0 of
# exp(-1e4) is exact enough; it is checked separately where it must be silent.)
TROUBLE = dict(over="raise", invalid="raise", divide="raise")


# The one-layer models; the models of styles take every frame's style.
LAYER_MODELS = ["crbm", "factored", "labelled"]
STYLE_MODELS = ["factored", "labelled"]


def _given(key, styles):
    """The styles of the frames as a model's second argument; none for a CRBM."""
    return (styles,) if key in STYLE_MODELS else ()


# --------------------------------------------------------------- divergence
def _diverging(factories, key="crbm", **params):
    return factories[key](
        n_components=8, learning_rate=50.0, momentum_delay=0, n_iter=60, **params
    )


@pytest.mark.parametrize("dtype", DTYPES)
@pytest.mark.parametrize("key", LAYER_MODELS)
def test_divergence_stops_with_an_error_naming_the_learning_rate(
    key, dtype, oscillations, styles, factories
):
    X, ids = oscillations
    model = _diverging(factories, key)
    with (
        np.errstate(all="ignore"),
        pytest.raises(TrainingDivergedError, match=r"learning_rate=50\.0.*Lower"),
    ):
        model.fit((X * 100).astype(dtype), *_given(key, styles), sequence_ids=ids)
    assert issubclass(TrainingDivergedError, FloatingPointError)


@pytest.mark.parametrize("key", LAYER_MODELS)
def test_divergence_in_partial_fit(key, oscillations, styles, factories):
    X, ids = oscillations
    model = _diverging(factories, key)
    with (
        np.errstate(all="ignore"),
        pytest.raises(TrainingDivergedError, match=r"learning_rate=50\.0"),
    ):
        for _ in range(60):
            model.partial_fit(X * 100, *_given(key, styles), sequence_ids=ids)


def test_binary_visibles_bound_the_updates(oscillations, factories):
    """Binary visibles are probabilities: even an absurd learning rate gives
    huge but finite weights, and a usable model (or a clear error)."""
    X, ids = oscillations
    binary = (X > 0).astype(np.float64)
    model = _diverging(factories, visible_type="binary")
    model.set_params(learning_rate=1e100, weight_decay=0.0)
    with np.errstate(all="ignore"):
        model.fit(binary, sequence_ids=ids)
    assert np.isfinite(model.components_).all()
    with np.errstate(**TROUBLE):
        H = model.transform(binary, sequence_ids=ids)
    assert np.isfinite(H).all() and H.min() >= 0 and H.max() <= 1


def test_divergence_in_a_stack(oscillations, factories):
    X, ids = oscillations
    stack = factories["stack"](learning_rate=50.0, momentum_delay=0, n_iter=60)
    with (
        np.errstate(all="ignore"),
        pytest.raises(TrainingDivergedError, match=r"learning_rate=50\.0"),
    ):
        stack.fit(X * 100, sequence_ids=ids)


def test_divergence_inside_an_imputer(oscillations, factories):
    X, ids = oscillations
    imputer = CRBMImputer(_diverging(factories))
    with (
        np.errstate(all="ignore"),
        pytest.raises(TrainingDivergedError, match=r"learning_rate=50\.0"),
    ):
        imputer.fit(X * 100, sequence_ids=ids)


# ----------------------------------------------------------------- real data
@pytest.fixture(scope="module")
def cmu_preprocessed(data_home):
    cmu = load_cmu35(data_home, subset="all")
    with sklearn.config_context(enable_metadata_routing=True):
        Z = make_motion_preprocessor(cmu.skeleton).fit_transform(
            cmu.data, sequence_ids=cmu.sequence_ids
        )
    return Z, cmu.sequence_ids


@pytest.mark.parametrize("dtype", DTYPES)
def test_paper_settings_stay_finite_on_cmu35(dtype, cmu_preprocessed, factories):
    """CMU subject 35, the paper's preprocessing, 200 hidden units, order 3."""
    Z, ids = cmu_preprocessed
    assert Z.shape == (2813, 62)
    X = Z.astype(dtype)
    model = factories["crbm"](n_components=200, order=3, n_iter=25, batch_size=100)
    with np.errstate(**TROUBLE):
        model.fit(X, sequence_ids=ids)
        for name in ["components_", "intercept_hidden_", "intercept_visible_"]:
            value = getattr(model, name)
            assert value.dtype == dtype and np.isfinite(value).all(), name
        assert np.isfinite(model.autoregressive_).all()
        assert np.isfinite(model.past_to_hidden_).all()
        assert np.isfinite(model.reconstruction_error_)
        # a model that learned something reconstructs better than the mean
        assert model.reconstruction_error_ < 62
        outputs = {
            "transform": model.transform(X, sequence_ids=ids),
            "score_samples": model.score_samples(X, sequence_ids=ids),
            "predict_next": model.predict_next(X, sequence_ids=ids),
            "sample": model.sample(30, n_sequences=4, random_state=0),
        }
        score = model.score(X, sequence_ids=ids)
    for name, out in outputs.items():
        assert out.dtype == dtype, name
        assert np.isfinite(out).all(), name
    # log-likelihood per frame above that of independent standard normals
    assert np.isfinite(score) and score > -62 * (0.5 * np.log(2 * np.pi) + 0.5)
    # generated frames stay within the range of the standardised training data
    assert np.abs(outputs["sample"]).max() <= np.abs(Z).max()


# The style models at sizes a user of the CMU data would start from, walks
# and jogs labelled; few annealing steps, which the checks do not need.
STYLE_SETTINGS = {
    "factored": dict(n_components=200, n_factors=100, n_style_features=50, n_iter=40),
    "labelled": dict(n_components=200, n_iter=25),
}


@pytest.mark.parametrize("dtype", DTYPES)
@pytest.mark.parametrize("key", STYLE_MODELS)
def test_style_models_stay_finite_on_cmu35(
    key, dtype, cmu_preprocessed, data_home, factories
):
    Z, ids = cmu_preprocessed
    cmu = load_cmu35(data_home, subset="all")
    y = cmu.motion[ids]
    assert set(y) == {"walk", "jog"}
    X = Z.astype(dtype)
    model = factories[key](**STYLE_SETTINGS[key], order=3, batch_size=100, ais_steps=10)
    with np.errstate(**TROUBLE):
        model.fit(X, y, sequence_ids=ids)
        assert model._fitted_layers()[0].flat.dtype == dtype
        assert np.isfinite(model._fitted_layers()[0].flat).all()
        assert model.reconstruction_error_ < 62  # better than the mean
        outputs = {
            "transform": model.transform(X, style=y, sequence_ids=ids),
            "score_samples": model.score_samples(X, style=y, sequence_ids=ids),
            "predict_next": model.predict_next(X, style=y, sequence_ids=ids),
            "predict_proba": model.predict_proba(X, sequence_ids=ids),
            "sample": model.sample(30, style="jog", n_sequences=4, random_state=0),
        }
    for name, out in outputs.items():
        assert out.dtype == dtype, name
        assert np.isfinite(out).all(), name
    # above independent standard normals, as for the CRBM
    mean = outputs["score_samples"].mean()
    assert mean > -62 * (0.5 * np.log(2 * np.pi) + 0.5)
    np.testing.assert_allclose(outputs["predict_proba"].sum(axis=1), 1, rtol=1e-5)
    # Within the range of the training data, which a glitch in jog 35_19 takes
    # to |z| = 26 on the thumbs: asked for a jog from a walk's frames, the
    # balanced factored model holds that pose (22.7 in float32), bounded.
    assert np.abs(outputs["sample"]).max() <= np.abs(Z).max()


# ------------------------------------------------------------ large inputs
@pytest.mark.parametrize("dtype", DTYPES)
def test_logistic_is_exact_and_silent_for_large_inputs(dtype):
    a = np.array([-1e4, -800.0, -50.0, 0.0, 50.0, 800.0, 1e4], dtype=dtype)
    with np.errstate(all="raise"):
        p = logistic(a.copy())
    assert p.dtype == dtype
    assert np.isfinite(p).all()
    assert p[0] == 0.0 and p[1] == 0.0 and p[-1] == 1.0 and p[-2] == 1.0
    assert p[3] == 0.5
    # symmetric: sigmoid(-a) = 1 - sigmoid(a)
    np.testing.assert_allclose(p[::-1], 1.0 - p, atol=np.finfo(dtype).eps)


def _params(dtype, n_features=3, n_components=4):
    rng = np.random.default_rng(0)
    return CRBMLayer(n_features, n_components, 2, 2, "gaussian", dtype).initialize(rng)


def _frame_rbms(params, visible_bias, hidden_bias):
    return CRBMFrames(
        visible_bias,
        hidden_bias,
        params.visible_std,
        params.visible_units,
        params.weights,
    )


@pytest.mark.parametrize("dtype", DTYPES)
def test_hidden_probabilities_for_huge_activations(dtype):
    params = _params(dtype)
    visible = np.ones((2, 3), dtype=dtype)
    hidden_bias = np.array([[-1e4, 1e4, -3e4, 3e4]] * 2, dtype=dtype)
    visible_bias = np.zeros((2, 3), dtype=dtype)
    with np.errstate(all="raise"):
        p = _frame_rbms(params, visible_bias, hidden_bias).hidden_probabilities(visible)
    assert p.dtype == dtype
    np.testing.assert_array_equal(p, [[0.0, 1.0, 0.0, 1.0]] * 2)


@pytest.mark.parametrize("dtype", DTYPES)
def test_free_energy_for_huge_activations(dtype):
    params = _params(dtype)
    params.weights[...] = 0.0
    visible = np.array([[1.0, 2.0, 3.0]], dtype=dtype)
    visible_bias = np.zeros((1, 3), dtype=dtype)
    hidden_bias = np.array([[-1e4, 1e4, -3e4, 3e4]], dtype=dtype)
    rbms = _frame_rbms(params, visible_bias, hidden_bias)
    # in the layer's dtype, and in float64 as the likelihood sums
    for frames, out_dtype in ((rbms, dtype), (rbms.astype(np.float64), np.float64)):
        with np.errstate(**TROUBLE):
            negative = frames.negative_free_energy(visible)
        # 0.5 * |v|^2 - sum softplus: softplus(-a) = 0 and softplus(a) = a for a >> 1
        np.testing.assert_allclose(-negative, [7.0 - 4e4], rtol=1e-6)
        assert negative.dtype == out_dtype


@pytest.fixture(scope="module")
def huge_model(fitted):
    """The tiny fitted model with weights giving activations of about 1e4."""
    model = copy.deepcopy(fitted["crbm"])
    rng = np.random.default_rng(0)
    model.components_ = 3e3 * rng.standard_normal(model.components_.shape)
    model.intercept_hidden_ = np.array([-1e4, 1e4, -2e4, 2e4, 0.0])
    return model


@pytest.mark.parametrize(
    "method", ["transform", "score_samples", "predict_next", "sample"]
)
def test_estimator_is_stable_for_huge_activations(method, huge_model, oscillations):
    X, ids = oscillations
    with np.errstate(all="raise"):
        if method == "sample":
            out = huge_model.sample(5, n_sequences=2, hidden_noise=1e4, random_state=0)
        else:
            out = getattr(huge_model, method)(X, sequence_ids=ids)
    assert np.isfinite(out).all()
    if method == "transform":
        assert out.min() >= 0.0 and out.max() <= 1.0
        assert np.isin(out[:, :4], [0.0, 1.0]).mean() > 0.9


# --------------------------------------------------------- preprocessing
@pytest.mark.parametrize("degrees", [1e6, -1e6, 720.0, -540.0, 1e-300, 90.0])
def test_expmap_encoder_is_finite_for_extreme_angles(degrees):
    walker = make_walker(n_sequences=1, n_frames=4, random_state=0)
    X = walker.data.copy()
    X[:, 3:] = degrees
    encoder = ExpMapEncoder(walker.skeleton).fit(X)
    with np.errstate(**TROUBLE):
        Z = encoder.transform(X)
        back = encoder.inverse_transform(Z)
    assert np.isfinite(Z).all() and np.isfinite(back).all()
    # every exponential map has rotation angle at most pi
    assert np.linalg.norm(Z[:, 6:9], axis=1).max() <= np.pi + 1e-12
    # the same rotations come back
    for rows in (slice(3, 6), slice(6, 9)):
        R0 = euler_to_matrix(np.deg2rad(X[:, rows]), "xyz")
        R1 = euler_to_matrix(np.deg2rad(back[:, rows]), "xyz")
        np.testing.assert_allclose(R0, R1, atol=1e-9)


@pytest.mark.parametrize("pitch", [0.0, np.pi, np.pi / 2])
def test_root_encoder_is_finite_when_the_body_points_up_or_down(pitch):
    """Body forward axis straight down (pitch 0) or up (pi): heading is undefined."""
    # y up: forward is z; rotate about x by -(pi/2 - pitch) to tilt forward down
    n = 5
    X = np.zeros((n, 6))
    X[:, 2] = np.arange(n)  # walking along z
    X[:, 1] = 17.0
    X[:, 3] = np.pi / 2 - pitch  # exponential map about x
    with warnings.catch_warnings():  # a body that always points up or down
        warnings.filterwarnings("ignore", "The root's forward axis")
        encoder = RootRelativeEncoder(up_axis="y").fit(X)
    with np.errstate(**TROUBLE):
        encoded = encoder.transform(X)
        back = encoder.inverse_transform(encoded)
    assert np.isfinite(encoded).all() and np.isfinite(back).all()
    np.testing.assert_allclose(encoded[:, 0], pitch, atol=1e-7)
    np.testing.assert_allclose(back[:, 1], 17.0)
    # and exactly so: the orientation comes back (heading starts at 0)
    np.testing.assert_allclose(back[:, 3:6], X[:, 3:6], atol=1e-12)


@pytest.fixture(scope="module")
def huge_style_models(fitted):
    """The tiny fitted style models with activations of about 1e4 or more."""
    models = {}
    rng = np.random.default_rng(0)
    for key in STYLE_MODELS:
        model = copy.deepcopy(fitted[key])
        flat = model._fitted_layers()[0].flat
        flat[...] = 3e3 * rng.standard_normal(flat.shape)
        models[key] = model
    return models


@pytest.mark.parametrize("key", STYLE_MODELS)
@pytest.mark.parametrize(
    "method", ["transform", "score_samples", "predict_next", "predict_proba", "sample"]
)
def test_style_models_are_stable_for_huge_activations(
    key, method, huge_style_models, oscillations, styles
):
    X, ids = oscillations
    model = huge_style_models[key]
    with np.errstate(all="raise"):
        if method == "sample":
            out = model.sample(5, style="low", n_sequences=2, hidden_noise=1e4)
        elif method == "predict_proba":
            out = model.predict_proba(X, sequence_ids=ids)
        else:
            out = getattr(model, method)(X, style=styles, sequence_ids=ids)
    assert np.isfinite(out).all()
    if method in ("transform", "predict_proba"):
        assert out.min() >= 0.0 and out.max() <= 1.0


@pytest.mark.parametrize("scale", [1.0, 1e3])
def test_stack_style_models_and_imputers_are_stable_for_large_inputs(
    scale, fitted, oscillations
):
    """Frames far outside the training range (1e3 standard deviations) give
    finite outputs without any floating-point warning."""
    X, ids = oscillations
    X = X * scale
    X_missing = X.copy()
    X_missing[10:30, :2] = np.nan
    with np.errstate(all="raise"):
        outputs = [
            fitted["stack"].transform(X, sequence_ids=ids),
            fitted["stack"].predict_next(X, sequence_ids=ids),
            fitted["stack"].sample(5, history=X[:6], random_state=0),
            fitted["crbm_imputer"].transform(X_missing, sequence_ids=ids),
            fitted["stack_imputer"].transform(X_missing, sequence_ids=ids),
            fitted["nn_imputer"].transform(X_missing, sequence_ids=ids),
            fitted["factored_imputer"].transform(X_missing, sequence_ids=ids),
            fitted["factored_imputer"].transform(
                X_missing, sequence_ids=ids, style="high"
            ),
            *[
                output
                for key in STYLE_MODELS
                for output in (
                    fitted[key].transform(X, sequence_ids=ids),
                    fitted[key].score_samples(X, sequence_ids=ids),
                    fitted[key].predict_next(X, style="low", sequence_ids=ids),
                    fitted[key].predict_proba(X, sequence_ids=ids),
                    fitted[key].sample(5, history=X[:6], style="high"),
                )
            ],
        ]
    for out in outputs:
        assert np.isfinite(out).all()
