"""The models under ``sklearn.set_config(array_api_dispatch=True)``.

Every namespace and device available here (numpy, array-api-strict on its
two devices, PyTorch on the CPU and on CUDA when present; PyTorch only when
installed, see README) against the numpy path: the same fitted parameters
give the same outputs within float tolerance; training and generation,
whose random streams differ across namespaces, agree statistically and,
where a namespace draws from numpy (array-api-strict), exactly when given
the same stream.
"""

import importlib.util
import itertools
import pickle
from functools import partial

import numpy as np
import pytest
import sklearn
from sklearn.base import clone
from sklearn.frozen import FrozenEstimator
from sklearn.utils._array_api import (
    _convert_to_numpy,
    get_namespace_and_device,
    move_estimator_to,
    yield_namespace_device_dtype_combinations,
)
from sklearn.utils._testing import _array_api_for_tests

from sklearn_crbm import (
    AutoregressiveImputer,
    ConditionalRBM,
    CRBMImputer,
    FactoredCRBM,
    LabelledCRBM,
    NearestNeighborImputer,
    StackedCRBM,
)
from sklearn_crbm._engines._gibbs import gibbs_frames
from sklearn_crbm._engines._online import History, _ancestors
from sklearn_crbm.datasets import make_oscillations
from sklearn_crbm.layers._crbm import CRBMLayer
from sklearn_crbm.layers._parameters import MomentumUpdate
from sklearn_crbm.utils._array_api import ArrayRandom, array_ops


def _available(namespace, device):
    if namespace not in ("numpy", "array_api_strict", "torch"):
        return False  # cupy, dpnp: not installed on the test machines
    if importlib.util.find_spec(namespace) is None:
        return False
    if namespace == "torch":
        import torch

        return device == "cpu" or (device == "cuda" and torch.cuda.is_available())
    return True


COMBINATIONS = [
    combination
    for combination in yield_namespace_device_dtype_combinations()
    if _available(*combination[:2])
]
# The namespaces other than numpy itself
DEVICE_COMBINATIONS = [c for c in COMBINATIONS if c[0] != "numpy"]


@pytest.fixture(autouse=True)
def one_torch_thread():
    """One PyTorch thread: on a busy machine each elementwise operation of a
    small array otherwise waits milliseconds for its second thread."""
    if importlib.util.find_spec("torch") is None:
        yield
        return
    import torch

    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        yield
    finally:
        torch.set_num_threads(threads)


@pytest.fixture
def dispatch():
    with sklearn.config_context(array_api_dispatch=True):
        yield


def _data(dtype_name):
    X, ids = make_oscillations(n_sequences=4, n_frames=40, random_state=0)
    return X.astype(dtype_name or "float64"), ids


def _to(xp, device, array):
    return xp.asarray(array, device=device)


def _numpy(array):
    return _convert_to_numpy(array, get_namespace_and_device(array)[0])


def _same_place(array, reference):
    """``array`` has the namespace, device and dtype of ``reference``."""
    array_xp, _, array_device = get_namespace_and_device(array)
    xp, _, device = get_namespace_and_device(reference)
    assert array_xp == xp
    assert array_device == device
    assert array.dtype == reference.dtype


# The models of styles take every frame's style as the second argument of fit
# and of the methods that score or transform frames, and ``style=`` in sample.
STYLE_MODELS = {"factored": FactoredCRBM, "labelled": LabelledCRBM}
MODELS = {"crbm": ConditionalRBM, "stack": StackedCRBM, **STYLE_MODELS}
SMALL_STYLE_PARAMS = {
    "factored": dict(n_factors=4, n_style_features=3, cd_steps=1, n_gibbs=3),
    "labelled": dict(n_gibbs=3),
}


def _small_model(name, **params):
    """A model of ``name`` with 6 hidden units, order 2 and 2 epochs."""
    params = {**SMALL_STYLE_PARAMS.get(name, {}), "n_iter": 2, **params}
    return MODELS[name](6, order=2, random_state=0, **params)


def _styles(ids):
    """A style for every frame: the sequences alternate between two."""
    return np.where(ids % 2 == 1, "high", "low")


def _is_style_model(model):
    return isinstance(model, tuple(STYLE_MODELS.values()))


def _given(model, ids):
    """The frames' styles as ``style=``; none for other models."""
    return {"style": _styles(ids)} if _is_style_model(model) else {}


def _one_style(model):
    """``style=`` for generating or filling in with a model of styles."""
    return {"style": "high"} if _is_style_model(model) else {}


@pytest.mark.parametrize("namespace, device_name, dtype_name", COMBINATIONS)
def test_fitted_attributes_and_outputs_live_on_the_input_device(
    namespace, device_name, dtype_name, dispatch
):
    xp, device = _array_api_for_tests(namespace, device_name, dtype_name)
    X, ids = _data(dtype_name)
    X_xp = _to(xp, device, X)
    model = ConditionalRBM(6, order=2, n_iter=2, random_state=0)
    model.fit(X_xp, sequence_ids=ids)
    for name in (
        "components_",
        "intercept_hidden_",
        "intercept_visible_",
        "autoregressive_",
        "past_to_hidden_",
        "visible_variance_",
        "seed_windows_",
    ):
        _same_place(getattr(model, name), X_xp)
    model.partial_fit(X_xp, sequence_ids=ids)
    assert model.n_iter_ == 3
    for output in (
        model.transform(X_xp, sequence_ids=ids),
        model.predict_next(X_xp, sequence_ids=ids),
        model.score_samples(X_xp, sequence_ids=ids),
        model.sample(4, n_sequences=3, random_state=0),
        model.sample(4, history=X_xp[:2, ...], random_state=0),
    ):
        _same_place(output, X_xp)
    assert np.isfinite(model.score(X_xp, sequence_ids=ids))


@pytest.mark.parametrize("namespace, device_name, dtype_name", DEVICE_COMBINATIONS)
@pytest.mark.parametrize("n_components", [6, 30])  # exact score; annealed score
@pytest.mark.parametrize("visible_variance", ["unit", "learned"])
def test_fitted_numpy_model_gives_the_same_outputs(
    namespace, device_name, dtype_name, n_components, visible_variance, dispatch
):
    xp, device = _array_api_for_tests(namespace, device_name, dtype_name)
    X, ids = _data(dtype_name)
    with sklearn.config_context(array_api_dispatch=False):
        model = ConditionalRBM(
            n_components,
            order=2,
            hidden_order=1,
            visible_variance=visible_variance,
            n_iter=5,
            random_state=0,
        ).fit(X, sequence_ids=ids)
    moved = move_estimator_to(model, xp, device)
    X_xp = _to(xp, device, X)
    rtol = 1e-4 if dtype_name == "float32" else 1e-10
    for method in ("transform", "predict_next"):
        expected = getattr(model, method)(X, sequence_ids=ids)
        got = _numpy(getattr(moved, method)(X_xp, sequence_ids=ids))
        np.testing.assert_allclose(got, expected, rtol=rtol, atol=rtol)
    expected = model.score_samples(X, sequence_ids=ids)
    got = _numpy(moved.score_samples(X_xp, sequence_ids=ids))
    if n_components == 6:  # exact: the same numbers
        np.testing.assert_allclose(got, expected, rtol=rtol, atol=rtol)
    else:  # annealed with other random numbers: within its own error
        error = model.estimate_log_likelihood(X, sequence_ids=ids, reverse=False)
        assert np.abs(got - expected).max() < 10 * error.standard_error.max() + rtol
        assert abs(got.mean() - expected.mean()) < 0.01
    # and back to numpy: the same model again
    back = move_estimator_to(moved, np, None)
    np.testing.assert_array_equal(back.components_, model.components_)
    np.testing.assert_array_equal(back.autoregressive_, model.autoregressive_)
    # the moved model has its own parameters: training it leaves the original
    before = model.components_.copy()
    moved.partial_fit(X_xp, sequence_ids=ids)
    np.testing.assert_array_equal(model.components_, before)


def _strict_and_numpy_streams(seed, ops):
    # array-api-strict draws with numpy: the same seed gives the same numbers
    return ArrayRandom(seed, ops), np.random.default_rng(seed)


def test_training_step_matches_numpy_given_the_same_random_stream():
    xp, device = _array_api_for_tests("array_api_strict", "CPU_DEVICE", "float64")
    rng = np.random.default_rng(0)
    params = CRBMLayer(
        5, 7, 2, 1, "gaussian", np.float64, learned_variance=True
    ).initialize(rng)
    moved = params.__sklearn_array_api_convert__(lambda a: _to(xp, device, a))
    visible = rng.standard_normal((20, 5))
    history = rng.standard_normal((20, 10))
    ops = array_ops(moved.flat)
    device_rng, numpy_rng = _strict_and_numpy_streams(1, ops)
    results = []
    for p, v, h, r in (
        (params, visible, history, numpy_rng),
        (moved, _to(xp, device, visible), _to(xp, device, history), device_rng),
    ):
        update = MomentumUpdate(p)
        _, error = p.cd_statistics(
            v,
            h,
            None,
            2,
            r,
            out=update.statistics,
            scale=0.01,
            workspace=p.new_workspace(20),
        )
        update.apply(0.5, 0.01, 0.001)
        update.apply(0.5, 0.01, 0.001)  # with momentum
        results.append((p.flat, float(error)))
    np.testing.assert_allclose(_numpy(results[1][0]), results[0][0], rtol=1e-12)
    assert results[1][1] == pytest.approx(results[0][1], rel=1e-12)


def test_gibbs_sampling_matches_numpy_given_the_same_random_stream():
    xp, device = _array_api_for_tests("array_api_strict", "CPU_DEVICE", "float64")
    rng = np.random.default_rng(0)
    params = CRBMLayer(4, 6, 1, 1, "gaussian", np.float64).initialize(rng)
    moved = params.__sklearn_array_api_convert__(lambda a: _to(xp, device, a))
    start = rng.standard_normal((8, 4))
    history = rng.standard_normal((8, 4))
    ops = array_ops(moved.flat)
    device_rng, numpy_rng = _strict_and_numpy_streams(2, ops)
    frames = []
    for p, s, h, r in (
        (params, start, history, numpy_rng),
        (moved, _to(xp, device, start), _to(xp, device, history), device_rng),
    ):
        frames.append(gibbs_frames(p.frame_rbms(h), s, 5, r, hidden_noise=0.3))
    np.testing.assert_allclose(_numpy(frames[1]), frames[0], rtol=1e-12)


@pytest.mark.parametrize("namespace, device_name, dtype_name", DEVICE_COMBINATIONS)
def test_training_and_generation_agree_with_numpy_statistically(
    namespace, device_name, dtype_name, dispatch
):
    xp, device = _array_api_for_tests(namespace, device_name, dtype_name)
    X, ids = _data(dtype_name)
    settings = dict(order=2, n_iter=30, learning_rate=1e-2, random_state=0)
    with sklearn.config_context(array_api_dispatch=False):
        model = ConditionalRBM(6, **settings).fit(X, sequence_ids=ids)
        expected_score = model.score(X, sequence_ids=ids)
        expected_frames = model.sample(20, n_sequences=100, random_state=0)
    trained = ConditionalRBM(6, **settings).fit(_to(xp, device, X), sequence_ids=ids)
    # the same start parameters, other random numbers: the same quality
    # (across training seeds the last epoch's error spreads by about 20%
    # and the score by about 0.03 nats)
    assert trained.reconstruction_error_ == pytest.approx(
        model.reconstruction_error_, rel=0.3
    )
    score = trained.score(_to(xp, device, X), sequence_ids=ids)
    assert abs(score - expected_score) < 0.06
    # generation from the numpy model moved over: the same distribution
    frames = _numpy(move_estimator_to(model, xp, device).sample(20, n_sequences=100))
    assert frames.shape == expected_frames.shape
    spread = expected_frames.std(axis=0)
    np.testing.assert_array_less(
        np.abs(frames.mean(axis=0) - expected_frames.mean(axis=0)), 0.2 * spread
    )
    np.testing.assert_allclose(frames.std(axis=0), spread, rtol=0.2)


@pytest.mark.parametrize("namespace, device_name, dtype_name", DEVICE_COMBINATIONS)
@pytest.mark.parametrize("estimator", ["crbm", *STYLE_MODELS])
def test_pickling_keeps_the_namespace_and_moving_to_numpy_keeps_the_model(
    namespace, device_name, dtype_name, estimator, dispatch
):
    xp, device = _array_api_for_tests(namespace, device_name, dtype_name)
    X, ids = _data(dtype_name)
    X_xp = _to(xp, device, X)
    model = _small_model(estimator)
    given = _given(model, ids)
    model.fit(X_xp, given.get("style"), sequence_ids=ids)
    expected = _numpy(model.transform(X_xp, **given, sequence_ids=ids))
    loaded = pickle.loads(pickle.dumps(model))
    _same_place(loaded._fitted_layers()[0].flat, X_xp)
    np.testing.assert_array_equal(
        _numpy(loaded.transform(X_xp, **given, sequence_ids=ids)), expected
    )
    on_numpy = pickle.loads(pickle.dumps(move_estimator_to(model, np, None)))
    with sklearn.config_context(array_api_dispatch=False):
        np.testing.assert_allclose(
            on_numpy.transform(X, **given, sequence_ids=ids),
            expected,
            rtol=1e-5,
            atol=1e-6,
        )
        on_numpy.partial_fit(X, given.get("style"), sequence_ids=ids)  # and trains on
    assert isinstance(on_numpy._fitted_layers()[0].flat, np.ndarray)


@pytest.mark.parametrize("namespace, device_name, dtype_name", DEVICE_COMBINATIONS)
@pytest.mark.parametrize("estimator", ["crbm", *STYLE_MODELS])
def test_input_of_another_namespace_is_a_clear_error(
    namespace, device_name, dtype_name, estimator
):
    xp, device = _array_api_for_tests(namespace, device_name, dtype_name)
    X, ids = _data(dtype_name)
    with sklearn.config_context(array_api_dispatch=True):
        model = _small_model(estimator)
        given = _given(model, ids)
        model.fit(_to(xp, device, X), given.get("style"), sequence_ids=ids)
        with pytest.raises(ValueError, match="same namespace"):
            model.transform(X, **given, sequence_ids=ids)
    with pytest.raises(ValueError, match="array_api_dispatch=True"):
        model.score(X, given.get("style"), sequence_ids=ids)


@pytest.mark.parametrize("namespace, device_name, dtype_name", COMBINATIONS)
@pytest.mark.parametrize("estimator", list(STYLE_MODELS))
def test_style_models_fit_and_run_on_the_input_device_as_on_numpy(
    namespace, device_name, dtype_name, estimator, dispatch
):
    xp, device = _array_api_for_tests(namespace, device_name, dtype_name)
    X, ids = _data(dtype_name)
    styles = _styles(ids)
    X_xp = _to(xp, device, X)
    model = _small_model(estimator).fit(X_xp, styles, sequence_ids=ids)
    model.partial_fit(X_xp, styles, sequence_ids=ids)
    assert model.n_iter_ == 3
    _same_place(model._fitted_layers()[0].flat, X_xp)
    _same_place(model.seed_windows_, X_xp)
    blend = np.full((4, 2), 0.5)  # half of each style, every frame
    for output in (
        model.sample(4, style="high", n_sequences=3, random_state=0),
        model.sample(4, style=blend, history=X_xp[:2, ...], random_state=0),
    ):
        _same_place(output, X_xp)
    # the likelihood's estimate is float64 in any case, as ConditionalRBM's
    estimate = model.estimate_log_likelihood(X_xp, style=styles, sequence_ids=ids)
    xp_out, _, device_out = get_namespace_and_device(estimate.log_likelihood)
    assert (xp_out, device_out) == get_namespace_and_device(X_xp)[::2]
    # A model fitted on numpy, moved over, computes what it computes on numpy;
    # its labels stay a numpy array (they may be strings).
    with sklearn.config_context(array_api_dispatch=False):
        reference = _small_model(estimator, n_iter=5).fit(X, styles, sequence_ids=ids)
    moved = move_estimator_to(reference, xp, device)
    assert isinstance(moved.classes_, np.ndarray)
    rtol = 1e-4 if dtype_name == "float32" else 1e-10
    # style given, and unknown (each sequence's posterior, or the mixture)
    for method, given in itertools.product(
        ["transform", "predict_next", "score_samples"], [{"style": styles}, {}]
    ):
        got = getattr(moved, method)(X_xp, **given, sequence_ids=ids)
        _same_place(got, X_xp)
        with sklearn.config_context(array_api_dispatch=False):
            expected = getattr(reference, method)(X, **given, sequence_ids=ids)
        np.testing.assert_allclose(_numpy(got), expected, rtol=rtol, atol=rtol)
    proba = moved.predict_proba(X_xp, sequence_ids=ids)
    _same_place(proba, X_xp)
    with sklearn.config_context(array_api_dispatch=False):
        expected_proba = reference.predict_proba(X, sequence_ids=ids)
        expected_styles = reference.predict(X, sequence_ids=ids)
    np.testing.assert_allclose(_numpy(proba), expected_proba, rtol=rtol, atol=rtol)
    np.testing.assert_array_equal(
        moved.predict(X_xp, sequence_ids=ids), expected_styles
    )


def _context(ids, dtype_name):
    """A control signal per frame: the sequence's sign, and a ramp."""
    ramp = np.linspace(-1, 1, len(ids))
    sign = np.where(ids % 2 == 1, 1.0, -1.0)
    return np.column_stack([sign, ramp]).astype(dtype_name or "float64")


@pytest.mark.parametrize("namespace, device_name, dtype_name", COMBINATIONS)
def test_a_model_of_a_context_runs_on_the_input_device_as_on_numpy(
    namespace, device_name, dtype_name, dispatch
):
    xp, device = _array_api_for_tests(namespace, device_name, dtype_name)
    X, ids = _data(dtype_name)
    context = _context(ids, dtype_name)
    X_xp, context_xp = _to(xp, device, X), _to(xp, device, context)
    model = _small_model("crbm").fit(X_xp, sequence_ids=ids, context=context_xp)
    model.partial_fit(X_xp, sequence_ids=ids, context=context_xp)
    assert model.n_iter_ == 3 and model.n_context_ == 2
    _same_place(model._fitted_layers()[0].flat, X_xp)
    for output in (
        model.sample(4, context=context_xp[:1, ...], n_sequences=3, random_state=0),
        model.sample(4, context=context[:4], history=X_xp[:2, ...], random_state=0),
    ):
        _same_place(output, X_xp)
    X_missing = X[ids == 3].copy()
    X_missing[10:, :2] = np.nan
    imputer = CRBMImputer(model, n_particles=2, random_state=0)
    imputer.fit(X_xp, sequence_ids=ids, context=context_xp)
    filled = imputer.transform(
        _to(xp, device, X_missing), context=_to(xp, device, context[ids == 3])
    )
    _same_place(filled, X_xp)
    # fitted on numpy and moved over, it computes what it computes on numpy
    with sklearn.config_context(array_api_dispatch=False):
        reference = _small_model("crbm", n_iter=5).fit(
            X, sequence_ids=ids, context=context
        )
    moved = move_estimator_to(reference, xp, device)
    rtol = 1e-4 if dtype_name == "float32" else 1e-10
    for method in ["transform", "predict_next", "score_samples"]:
        got = getattr(moved, method)(X_xp, sequence_ids=ids, context=context_xp)
        _same_place(got, X_xp)
        with sklearn.config_context(array_api_dispatch=False):
            expected = getattr(reference, method)(X, sequence_ids=ids, context=context)
        np.testing.assert_allclose(_numpy(got), expected, rtol=rtol, atol=rtol)


def _imputer_data(dtype_name):
    """Training data, and its last sequence with channels and frames missing."""
    X, ids = _data(dtype_name)
    X_missing = X[ids == 3].copy()
    X_missing[10:, :2] = np.nan  # two channels lost
    X_missing[20:24, :] = np.nan  # wholly missing frames
    X_missing[0, 3] = np.nan  # in the first frame
    return X, ids, X_missing


@pytest.mark.parametrize("namespace, device_name, dtype_name", DEVICE_COMBINATIONS)
@pytest.mark.parametrize(
    "imputer, fitted",
    [
        (NearestNeighborImputer(), ("_fit_X", "_squared_norms", "mean_")),
        (
            AutoregressiveImputer(order=2),
            ("coef_", "intercept_", "covariance_", "mean_", "frame_covariance_"),
        ),
        (AutoregressiveImputer(order=0, covariance_type="diag"), ("covariance_",)),
    ],
    ids=["nearest", "autoregressive", "autoregressive-diag-order0"],
)
def test_baseline_imputers_fill_on_the_input_device_as_on_numpy(
    namespace, device_name, dtype_name, imputer, fitted, dispatch
):
    xp, device = _array_api_for_tests(namespace, device_name, dtype_name)
    X, ids, X_missing = _imputer_data(dtype_name)
    # two test sequences of different lengths
    X_missing = np.concatenate([X_missing, X_missing[:25]])
    test_ids = np.repeat([0, 1], [40, 25])
    X_missing[40, :] = np.nan  # a second sequence that starts wholly missing
    train = X[ids < 3]
    sequences = {"sequence_ids": ids[ids < 3]}
    with sklearn.config_context(array_api_dispatch=False):
        reference = clone(imputer).fit(train, **sequences)
        expected = reference.transform(X_missing, sequence_ids=test_ids)
    train_xp = _to(xp, device, train)
    on_device = clone(imputer).fit(train_xp, **sequences)
    rtol = 1e-4 if dtype_name == "float32" else 1e-10
    for name in fitted:
        _same_place(getattr(on_device, name), train_xp)
        np.testing.assert_allclose(
            _numpy(getattr(on_device, name)),
            getattr(reference, name),
            rtol=rtol,
            atol=rtol,
        )
    X_xp = _to(xp, device, X_missing)
    filled = on_device.transform(X_xp, sequence_ids=test_ids)
    _same_place(filled, X_xp)
    assert not np.isnan(expected).any()
    np.testing.assert_allclose(_numpy(filled), expected, rtol=rtol, atol=rtol)
    with pytest.raises(ValueError, match="must use the same namespace"):
        on_device.transform(X_missing)
    with sklearn.config_context(array_api_dispatch=False):
        with pytest.raises(TypeError, match="was fitted on"):
            on_device.transform(X_missing)


def _moved_imputers(xp, device, X, ids, model, **params):
    """A numpy imputer around ``model`` and the same on ``xp``'s ``device``."""
    imputer = CRBMImputer(FrozenEstimator(model), random_state=0, **params)
    moved = move_estimator_to(model, xp, device)
    on_device = CRBMImputer(FrozenEstimator(moved), random_state=0, **params)
    on_device.fit(_to(xp, device, X), sequence_ids=ids)
    with sklearn.config_context(array_api_dispatch=False):
        imputer.fit(X, sequence_ids=ids)
    return imputer, on_device


@pytest.mark.parametrize("namespace, device_name, dtype_name", DEVICE_COMBINATIONS)
def test_crbm_imputer_fills_on_the_input_device_as_on_numpy(
    namespace, device_name, dtype_name, dispatch
):
    xp, device = _array_api_for_tests(namespace, device_name, dtype_name)
    X, ids, X_missing = _imputer_data(dtype_name)
    X_xp = _to(xp, device, X_missing)
    missing = np.isnan(X_missing)
    with sklearn.config_context(array_api_dispatch=False):
        model = ConditionalRBM(6, order=2, n_iter=5, random_state=0)
        model.fit(X, sequence_ids=ids)
    # mean field alone (no Gibbs sampling, one chain): deterministic, also
    # with the offset correction and the observation gain
    for inference in (
        dict(offset_shrinkage=None, observation_gain=1.0),
        dict(offset_shrinkage=5.0, observation_gain=2.0),
    ):
        imputer, on_device = _moved_imputers(
            xp, device, X, ids, model, n_gibbs=0, n_particles=1, **inference
        )
        _same_place(on_device.mean_, X_xp)
        filled = on_device.transform(X_xp)
        _same_place(filled, X_xp)
        rtol = 1e-4 if dtype_name == "float32" else 1e-10
        with sklearn.config_context(array_api_dispatch=False):
            expected = imputer.transform(X_missing)
        np.testing.assert_allclose(_numpy(filled), expected, rtol=rtol, atol=rtol)
    # the defaults (particles, resampling, offsets): observed values untouched,
    # the same fills for the same random_state
    imputer, on_device = _moved_imputers(xp, device, X, ids, model)
    filled = on_device.transform(X_xp)
    _same_place(filled, X_xp)
    filled = _numpy(filled)
    assert not np.isnan(filled).any()
    np.testing.assert_array_equal(filled[~missing], X_missing[~missing])
    np.testing.assert_array_equal(_numpy(on_device.transform(X_xp)), filled)
    draws = on_device.sample(X_xp, 2)
    _same_place(draws, X_xp)
    assert draws.shape == (2, *X_missing.shape)


@pytest.mark.parametrize("namespace, device_name, dtype_name", DEVICE_COMBINATIONS)
def test_crbm_imputer_draws_agree_with_numpy_in_distribution(
    namespace, device_name, dtype_name, dispatch
):
    xp, device = _array_api_for_tests(namespace, device_name, dtype_name)
    X, ids, X_missing = _imputer_data(dtype_name)
    missing = np.isnan(X_missing)
    with sklearn.config_context(array_api_dispatch=False):
        model = ConditionalRBM(6, order=2, n_iter=5, random_state=0)
        model.fit(X, sequence_ids=ids)
        # strong weights, so that Gibbs sampling makes the fills vary
        model.components_ = 30 * model.components_
    params = dict(n_gibbs=5, n_particles=4, offset_shrinkage=10.0)
    imputer, on_device = _moved_imputers(xp, device, X, ids, model, **params)
    n = 40
    with sklearn.config_context(array_api_dispatch=False):
        expected = imputer.sample(X_missing, n)[:, missing]
    got = _numpy(on_device.sample(_to(xp, device, X_missing), n))[:, missing]
    spread = expected.std(axis=0)
    assert spread.mean() > 0.01  # the draws do vary
    standard_error = np.sqrt((spread**2 + got.var(axis=0)) / n)
    assert np.all(
        np.abs(got.mean(axis=0) - expected.mean(axis=0)) < 5 * standard_error + 1e-4
    )
    assert 0.7 < got.std(axis=0).mean() / spread.mean() < 1.4


@pytest.mark.parametrize(
    "namespace, device_name, dtype_name",
    [c for c in DEVICE_COMBINATIONS if c[0] == "array_api_strict"],
)
def test_particle_resampling_is_numpy_s_given_the_same_draws(
    namespace, device_name, dtype_name, dispatch
):
    xp, device = _array_api_for_tests(namespace, device_name, dtype_name)
    X, ids = _data(dtype_name)
    with sklearn.config_context(array_api_dispatch=False):
        model = ConditionalRBM(6, order=2, n_iter=5, random_state=0)
        model.fit(X, sequence_ids=ids)
        model.autoregressive_ = 30 * model.autoregressive_  # pasts matter
    moved = move_estimator_to(model, xp, device)
    n_particles, n_sequences = 4, 3
    # 2 groups of 4 particles per sequence, each with its own past
    past = np.random.default_rng(1).normal(size=(8, n_sequences, 3, X.shape[1]))
    past = past.astype(X.dtype)
    frames, observed = X[:n_sequences], X[:n_sequences] > 0
    results = []
    for estimator, to in ((model, np.asarray), (moved, partial(_to, xp, device))):
        history = History.from_frames(estimator._fitted_layers(), to(past))
        chains = _ancestors(
            history.frame_rbms(),
            to(frames),
            to(observed),
            n_particles,
            ArrayRandom(7, array_ops(to(frames)))
            if to is not np.asarray
            else np.random.default_rng(7),
        )
        history.reorder(chains)
        results.append((_numpy(chains), _numpy(history.windows[0])))
    (chains, windows), (chains_xp, windows_xp) = results
    assert (chains != np.arange(8)[:, None]).any()  # some pasts were copied
    np.testing.assert_array_equal(chains_xp, chains)
    np.testing.assert_array_equal(windows_xp, windows)


@pytest.mark.parametrize("namespace, device_name, dtype_name", DEVICE_COMBINATIONS)
def test_crbm_imputer_trains_a_stack_on_the_input_device(
    namespace, device_name, dtype_name, dispatch
):
    xp, device = _array_api_for_tests(namespace, device_name, dtype_name)
    X, ids, X_missing = _imputer_data(dtype_name)
    missing = np.isnan(X_missing)
    stack = StackedCRBM((8, 6), order=2, n_iter=2, random_state=0)
    imputer = CRBMImputer(stack, n_gibbs=3, n_particles=3, random_state=0)
    imputer.fit(_to(xp, device, X), sequence_ids=ids)
    _same_place(imputer.estimator_.layers_[0].components_, _to(xp, device, X))
    filled = imputer.transform(_to(xp, device, X_missing))
    _same_place(filled, _to(xp, device, X_missing))
    filled = _numpy(filled)
    assert not np.isnan(filled).any()
    np.testing.assert_array_equal(filled[~missing], X_missing[~missing])
    # as the baseline imputers: scikit-learn's error under dispatch, ours without
    with pytest.raises(ValueError, match="same namespace.*move_estimator_to"):
        imputer.transform(X_missing)
    with sklearn.config_context(array_api_dispatch=False):
        with pytest.raises(TypeError, match="was fitted on.*move_estimator_to"):
            imputer.transform(X_missing)


@pytest.mark.parametrize("namespace, device_name, dtype_name", DEVICE_COMBINATIONS)
def test_stack_fits_and_runs_on_the_input_device_as_on_numpy(
    namespace, device_name, dtype_name, dispatch
):
    xp, device = _array_api_for_tests(namespace, device_name, dtype_name)
    X, ids = _data(dtype_name)
    X_xp = _to(xp, device, X)
    settings = dict(order=2, n_iter=3, random_state=0)
    stack = StackedCRBM((8, 6), **settings).fit(X_xp, sequence_ids=ids)
    stack.partial_fit(X_xp, sequence_ids=ids)
    for layer in stack.layers_:
        _same_place(layer.components_, X_xp)
    for output in (
        stack.transform(X_xp, sequence_ids=ids),
        stack.score_samples(X_xp, sequence_ids=ids),
        stack.sample(4, n_sequences=2, random_state=0),
    ):
        _same_place(output, X_xp)
    with sklearn.config_context(array_api_dispatch=False):
        model = StackedCRBM((8, 6), **settings).fit(X, sequence_ids=ids)
        expected_score = model.score(X, sequence_ids=ids)
    moved = move_estimator_to(model, xp, device)
    rtol = 1e-4 if dtype_name == "float32" else 1e-10
    for method in ("transform", "predict_next"):
        np.testing.assert_allclose(
            _numpy(getattr(moved, method)(X_xp, sequence_ids=ids)),
            getattr(model, method)(X, sequence_ids=ids),
            rtol=rtol,
            atol=rtol,
        )
    # a bound from ten draws per frame: other draws, nearly the same mean
    assert abs(moved.score(X_xp, sequence_ids=ids) - expected_score) < 0.05


@pytest.mark.parametrize("namespace, device_name, dtype_name", DEVICE_COMBINATIONS)
def test_autoregressive_start_lands_on_the_input_device(
    namespace, device_name, dtype_name, dispatch
):
    xp, device = _array_api_for_tests(namespace, device_name, dtype_name)
    X, ids = _data(dtype_name)
    settings = dict(order=2, n_iter=1, init="autoregressive", random_state=0)
    settings["visible_variance"] = "learned"
    X_xp = _to(xp, device, X)
    model = ConditionalRBM(6, **settings).fit(X_xp, sequence_ids=ids)
    with sklearn.config_context(array_api_dispatch=False):
        expected = ConditionalRBM(6, **settings).fit(X, sequence_ids=ids)
    for name in ("autoregressive_", "intercept_visible_", "visible_variance_"):
        _same_place(getattr(model, name), X_xp)
        # the same ridge start; one epoch of other random numbers moves it little
        np.testing.assert_allclose(
            _numpy(getattr(model, name)), getattr(expected, name), atol=2e-3
        )


@pytest.mark.parametrize("namespace, device_name, dtype_name", DEVICE_COMBINATIONS)
@pytest.mark.parametrize("n_components", [6, 30])  # exact; one shared annealing
def test_binary_model_without_history_scores_as_on_numpy(
    namespace, device_name, dtype_name, n_components, dispatch
):
    xp, device = _array_api_for_tests(namespace, device_name, dtype_name)
    X, ids = _data(dtype_name)
    X = (X > 0).astype(X.dtype)
    with sklearn.config_context(array_api_dispatch=False):
        model = ConditionalRBM(
            n_components, order=0, visible_type="binary", n_iter=2, random_state=0
        ).fit(X, sequence_ids=ids)
        expected = model.score(X, sequence_ids=ids)
    moved = move_estimator_to(model, xp, device)
    X_xp = _to(xp, device, X)
    tolerance = 1e-4 if n_components == 6 else 0.01
    assert moved.score(X_xp, sequence_ids=ids) == pytest.approx(expected, abs=tolerance)
    _same_place(moved.sample(2, n_sequences=2, random_state=0), X_xp)


@pytest.mark.parametrize("namespace, device_name, dtype_name", DEVICE_COMBINATIONS)
def test_early_stopping_validates_on_the_input_device(
    namespace, device_name, dtype_name, dispatch
):
    xp, device = _array_api_for_tests(namespace, device_name, dtype_name)
    X, ids = make_oscillations(n_sequences=6, n_frames=40, random_state=0)
    X = X.astype(dtype_name)
    settings = dict(order=2, n_iter=20, early_stopping=True, random_state=0)
    settings["validation_interval"] = 5
    model = ConditionalRBM(6, **settings).fit(_to(xp, device, X), sequence_ids=ids)
    with sklearn.config_context(array_api_dispatch=False):
        expected = ConditionalRBM(6, **settings).fit(X, sequence_ids=ids)
    # the same held-out sequences and start; other random numbers in training
    np.testing.assert_allclose(
        model.validation_scores_, expected.validation_scores_, atol=0.05
    )
    _same_place(model.components_, _to(xp, device, X))


@pytest.mark.parametrize("namespace, device_name, dtype_name", DEVICE_COMBINATIONS)
def test_imputer_refuses_a_frozen_model_of_another_namespace_clearly(
    namespace, device_name, dtype_name
):
    xp, device = _array_api_for_tests(namespace, device_name, dtype_name)
    X, ids = _data(dtype_name)
    with sklearn.config_context(array_api_dispatch=True):
        model = ConditionalRBM(6, order=2, n_iter=1, random_state=0)
        model.fit(_to(xp, device, X), sequence_ids=ids)
    imputer = CRBMImputer(FrozenEstimator(model))
    with pytest.raises(TypeError, match="move_estimator_to"):
        imputer.fit(X, sequence_ids=ids)
    # moved to numpy, the same model fills
    imputer = CRBMImputer(FrozenEstimator(move_estimator_to(model, np, None)))
    X_missing = X.copy()
    X_missing[5:9, 1] = np.nan
    filled = imputer.fit(X, sequence_ids=ids).transform(X_missing, sequence_ids=ids)
    assert np.isfinite(filled).all()


# ------------------------------------------------------- the default sizes
# ConditionalRBM() has 200 hidden units (FactoredCRBM() 600) and CRBMImputer()
# 20 particles per draw: training minibatches, generation of many sequences
# and fill-in then draw 4,096 or more hidden states at once, where the sampler
# tests float64 activations in float32 (issue 30: a crash on float64 data
# that 6 or 30 hidden units never reach).  Both dtypes, on a strict namespace
# and on PyTorch; a few epochs of short sequences.
DEFAULT_SIZE_COMBINATIONS = [
    (namespace, device_name, dtype_name)
    for namespace, device_name in (("array_api_strict", "CPU_DEVICE"), ("torch", "cpu"))
    if _available(namespace, device_name)
    for dtype_name in ("float32", "float64")
]


DEFAULT_SIZES = {
    "crbm": [200],
    "stack": [200, 200],
    "factored": [600],
    "labelled": [200],
}


def _default_model(estimator):
    """The model of ``estimator`` at its default sizes, 2 epochs."""
    model = MODELS[estimator](n_iter=2, random_state=0)
    assert list(np.atleast_1d(model.n_components)) == DEFAULT_SIZES[estimator]
    return model


def _check_outputs(outputs, shapes, reference):
    for name, output in outputs.items():
        _same_place(output, reference)
        assert tuple(output.shape) == shapes[name], name
        assert np.isfinite(_numpy(output)).all(), name


@pytest.mark.parametrize(
    "namespace, device_name, dtype_name", DEFAULT_SIZE_COMBINATIONS
)
@pytest.mark.parametrize("estimator", list(MODELS))
def test_every_path_runs_at_the_default_size(
    namespace, device_name, dtype_name, estimator, dispatch
):
    xp, device = _array_api_for_tests(namespace, device_name, dtype_name)
    X, ids = _data(dtype_name)
    X_xp = _to(xp, device, X)
    model = _default_model(estimator)
    given, style = _given(model, ids), _one_style(model)
    model.fit(X_xp, given.get("style"), sequence_ids=ids)
    model.partial_fit(X_xp, given.get("style"), sequence_ids=ids)
    n_frames, n_features = X.shape
    sizes = DEFAULT_SIZES[estimator]
    outputs = {
        "transform": model.transform(X_xp, **given, sequence_ids=ids),
        "predict_next": model.predict_next(X_xp, **given, sequence_ids=ids),
        "score_samples": model.score_samples(X_xp, **given, sequence_ids=ids),
        "sample one": model.sample(4, random_state=0, **style),
        # 30 sequences: 6,000 hidden states per Gibbs step
        "sample many": model.sample(
            4, n_sequences=30, hidden_noise=1.0, random_state=0, **style
        ),
        "sample history": model.sample(
            4, history=X_xp[: model.history_length, ...], random_state=0, **style
        ),
    }
    shapes = {
        "transform": (n_frames, sizes[-1]),
        "predict_next": (n_frames, n_features),
        "score_samples": (n_frames,),
        "sample one": (4, n_features),
        "sample many": (120, n_features),
        "sample history": (4, n_features),
    }
    _check_outputs(outputs, shapes, X_xp)
    # the deterministic outputs are those of the same parameters on numpy
    on_numpy = move_estimator_to(model, np, None)
    rtol = 1e-4 if dtype_name == "float32" else 1e-10
    with sklearn.config_context(array_api_dispatch=False):
        for method in ("transform", "predict_next"):
            np.testing.assert_allclose(
                _numpy(outputs[method]),
                getattr(on_numpy, method)(X, **given, sequence_ids=ids),
                rtol=rtol,
                atol=rtol,
            )


@pytest.mark.parametrize(
    "namespace, device_name, dtype_name", DEFAULT_SIZE_COMBINATIONS
)
@pytest.mark.parametrize("estimator", list(MODELS))
def test_crbm_imputer_fills_sequences_of_different_lengths_at_the_default_size(
    namespace, device_name, dtype_name, estimator, dispatch
):
    xp, device = _array_api_for_tests(namespace, device_name, dtype_name)
    X, ids, X_missing = _imputer_data(dtype_name)
    # two short test sequences of different lengths, the second starting
    # missing: 20 particles of 2 sequences draw 8,000 hidden states at once
    X_missing = np.concatenate([X_missing[8:20], X_missing[:7]])
    X_missing[12, :] = np.nan
    test_ids = np.repeat([0, 1], [12, 7])
    missing = np.isnan(X_missing)
    model = _default_model(estimator)
    imputer = CRBMImputer(model, n_gibbs=3, random_state=0)
    assert imputer.n_particles == 20 and imputer.n_draws == 1  # the defaults
    imputer.fit(_to(xp, device, X), _given(model, ids).get("style"), sequence_ids=ids)
    X_xp = _to(xp, device, X_missing)
    # a model of styles infers the style in transform and is given it in sample
    outputs = {
        "transform": imputer.transform(X_xp, sequence_ids=test_ids),
        "sample": imputer.sample(X_xp, 2, sequence_ids=test_ids, **_one_style(model)),
    }
    _check_outputs(
        outputs, {"transform": X_missing.shape, "sample": (2, *X_missing.shape)}, X_xp
    )
    for filled in (_numpy(outputs["transform"]), *_numpy(outputs["sample"])):
        np.testing.assert_array_equal(filled[~missing], X_missing[~missing])
