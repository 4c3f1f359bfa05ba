"""The one on-line loop behind generation and fill-in (``sklearn_crbm._engines._online``)."""

import pickle

import joblib
import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from sklearn_crbm import ConditionalRBM, StackedCRBM
from sklearn_crbm._engines._gibbs import gibbs_frames
from sklearn_crbm._engines._online import (
    DRIFT_FRAMES,
    TOP_LAYER,
    WHOLE_STACK,
    History,
    Observed,
    _drift_step,
    run_online,
)
from sklearn_crbm.datasets import make_oscillations
from sklearn_crbm.layers._crbm import CRBMLayer
from sklearn_crbm.models._base import FittedParameter
from sklearn_crbm.utils._sequences import check_sequence_ids

X, IDS = make_oscillations(n_sequences=3, n_frames=30, random_state=0)


def _layers(orders=((2, 2), (1, 3)), seed=0):
    rng = np.random.default_rng(seed)
    layers, n_visible = [], 6
    for k, (order, hidden_order) in enumerate(orders):
        kind = "gaussian" if k == 0 else "binary"
        params = CRBMLayer(
            n_visible, 5 - k, order, hidden_order, kind, np.float64
        ).initialize(rng)
        params.flat[...] = 0.5 * rng.standard_normal(params.flat.shape)
        params.dynamic *= params.dynamic_mask()
        layers.append(params)
        n_visible = params.n_components
    return layers


def test_history_from_frames_passes_up_with_edge_padding():
    layers = _layers()
    frames = X[None, None, :4]  # one chain, one sequence, four frames
    history = History.from_frames(layers, frames)
    bottom, top = history.windows
    assert_array_equal(bottom[0, 0], X[[3, 2]])  # most recent first
    # layer 1 sees layer 0's hidden probabilities, each frame given its own
    # past with the first frame repeated where the past runs out
    padded = [X[max(t - 1, 0)] for t in range(4)], [X[max(t - 2, 0)] for t in range(4)]
    history_rows = np.hstack([np.array(padded[0]), np.array(padded[1])])
    hidden = layers[0].frame_rbms(history_rows).hidden_probabilities(X[:4])
    # layer 0 has two lags: frames 2 and 3 have a full past; the window of
    # layer 1 (three lags) repeats the oldest of them
    assert_allclose(top[0, 0], hidden[[3, 2, 2]], rtol=1e-12)


def test_one_layer_schemes_are_one_gibbs_run():
    (layer,) = _layers(orders=((2, 2),))
    seed = np.stack([X[:2], X[30:32]])[None]
    runs = {}
    for scheme in (TOP_LAYER, WHOLE_STACK):
        run = run_online(
            [layer],
            np.random.default_rng(0),
            history=History.from_frames([layer], seed),
            n_steps=4,
            n_gibbs=3,
            scheme=scheme,
            start_jitter=0.01,
        )
        runs[scheme] = np.stack([frames for _, frames in run])
    assert runs[TOP_LAYER].shape == (4, 1, 2, 6)  # steps, chains, sequences
    assert_array_equal(runs[TOP_LAYER], runs[WHOLE_STACK])

    # the same chains written out: jitter, then gibbs_frames, frame by frame
    rng = np.random.default_rng(0)
    past = list(seed[0].transpose(1, 0, 2))
    for step in range(4):
        history = np.hstack([past[-1], past[-2]])
        start = past[-1] + 0.01 * rng.standard_normal(past[-1].shape)
        frame = gibbs_frames(layer.frame_rbms(history), start, 3, rng)
        assert_allclose(runs[TOP_LAYER][step, 0], frame, rtol=1e-12)
        past.append(frame)


def test_fill_in_clamps_observed_channels_on_a_stack():
    layers = _layers()
    missing = np.zeros(X.shape, dtype=bool)
    missing[5:, :2] = True
    missing[12] = True
    observed = Observed(
        X=np.where(missing, 0.0, X),
        missing=missing,
        sequences=check_sequence_ids(IDS, len(X)),
    )
    seen = np.zeros(len(X), dtype=bool)
    for step, frames in run_online(
        layers,
        np.random.default_rng(0),
        observed=observed,
        n_chains=4,
        n_particles=2,
        n_gibbs=2,
        scheme=WHOLE_STACK,
    ):
        # every sequence at every step (all three are 30 frames long)
        rows = 30 * np.arange(3) + step
        seen[rows] = True
        assert frames.shape == (4, 3, 6)
        assert np.isfinite(frames).all()
        # observed entries come back as they are, whole frames included
        assert_array_equal(
            frames[:, ~missing[rows]],
            np.broadcast_to(X[rows][~missing[rows]], (4, (~missing[rows]).sum())),
        )
        # missing entries are drawn, not left at their placeholder 0
        assert np.all(frames[:, missing[rows]] != 0)
    assert seen.all()


def test_a_stack_clamps_only_with_the_whole_stack_scheme():
    layers = _layers()
    observed = Observed(
        X=X, missing=np.zeros(X.shape, bool), sequences=check_sequence_ids(IDS, len(X))
    )
    with pytest.raises(ValueError, match="whole_stack"):
        next(
            run_online(
                layers, np.random.default_rng(0), observed=observed, scheme=TOP_LAYER
            )
        )


def test_history_length_is_public_on_both_models():
    assert ConditionalRBM(order=3, hidden_order=5).history_length == 5
    assert ConditionalRBM(order=0).history_length == 0
    assert StackedCRBM((4, 3, 2), order=2).history_length == 6


def test_stacked_sample_takes_n_jobs_and_sample_visibles():
    stack = StackedCRBM((6, 4), order=1, n_iter=3, random_state=0)
    stack.fit(X, sequence_ids=IDS)
    serial = stack.sample(3, n_sequences=300, n_gibbs=2, random_state=0)
    with joblib.parallel_backend("threading"):  # two blocks of 150 sequences
        parallel = stack.sample(3, n_sequences=300, n_gibbs=2, random_state=0, n_jobs=2)
    assert_array_equal(serial, parallel)
    drawn = stack.sample(4, n_sequences=2, sample_visibles=True, random_state=0)
    assert drawn.shape == (8, 6) and np.isfinite(drawn).all()
    assert not np.allclose(drawn, stack.sample(4, n_sequences=2, random_state=0))


def test_fitted_attributes_view_the_packed_parameters():
    model = ConditionalRBM(5, order=2, n_iter=2, random_state=0).fit(
        X, sequence_ids=IDS
    )
    # every fitted weight but visible_variance_, computed from its log
    names = [
        name
        for name, attribute in vars(ConditionalRBM).items()
        if isinstance(attribute, FittedParameter) and name != "visible_variance_"
    ]
    assert {"components_", "autoregressive_", "past_to_hidden_"} <= set(names)
    for name in names:
        if name == "visible_variance_" or getattr(model, name).size == 0:
            continue  # exp of the packed log-variances; no context
        assert np.shares_memory(getattr(model, name), model._layer.flat)
        loaded = pickle.loads(pickle.dumps(model))
        assert np.shares_memory(getattr(loaded, name), loaded._layer.flat)
        assert_array_equal(getattr(loaded, name), getattr(model, name))
    before = model.transform(X)
    model.components_ = 2 * model.components_  # assignment writes the model
    assert not np.allclose(model.transform(X), before)
    with pytest.raises(ValueError, match=r"components_ has shape \(5, 6\)"):
        model.components_ = np.zeros((4, 6))
    assert not hasattr(ConditionalRBM(), "components_")


def test_drift_is_smooth_with_the_spread_asked():
    """The hidden drift has the standard deviation asked for, decorrelates
    over about DRIFT_FRAMES frames, and changes smoothly from frame to frame."""
    rng = np.random.default_rng(0)
    like = np.zeros((400, 50))
    drift, values = None, []
    for _ in range(300):
        drift = _drift_step(drift, like, rng, 0.5)
        values.append(drift[1])
    z = np.array(values[100:])  # (frames, chains, units)
    assert z.std() == pytest.approx(0.5, rel=0.05)
    lag = DRIFT_FRAMES
    correlation = np.mean(z[lag:] * z[:-lag]) / z.var()
    assert 0.3 < correlation < 0.9
    # far smoother than white noise of the same spread (third difference 0.5 sqrt(20))
    assert np.diff(z, 3, axis=0).std() < 0.1 * 0.5 * np.sqrt(20)
