"""Tests of FactoredCRBM: the style-gated factored CRBM (Taylor & Hinton, 2009)."""

import itertools
import pickle

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from scipy.special import logsumexp

from sklearn_crbm import CRBMImputer, FactoredCRBM
from sklearn_crbm.datasets import make_styled_oscillations


def styled_data(random_state=0, switching=True, n_sequences=8):
    return make_styled_oscillations(
        n_sequences, switching=switching, random_state=random_state
    )


def small_model(**params):
    defaults = dict(
        n_components=16,  # fewer units stay at the start's saddle (gates near 0)
        n_factors=12,
        n_style_features=6,
        order=2,
        cd_steps=1,
        learning_rate=0.1,
        n_iter=400,
        n_gibbs=20,
        random_state=0,
    )
    return FactoredCRBM(**{**defaults, **params})


@pytest.fixture(scope="module")
def fitted():
    X, ids, styles = styled_data()
    return small_model().fit(X, styles, sequence_ids=ids)


def test_fit_learns_the_styles(fitted):
    assert_array_equal(fitted.classes_, ["high", "low"])
    assert fitted.n_iter_ == 400 and fitted._layer.is_finite()
    X, ids, styles = styled_data(random_state=1)
    flipped = np.where(styles == "low", "high", "low")
    right = fitted.predict_next(X, style=styles, sequence_ids=ids)
    wrong = fitted.predict_next(X, style=flipped, sequence_ids=ids)
    assert np.mean((X - right)[:, 0] ** 2) < 0.25 * np.mean((X - wrong)[:, 0] ** 2)
    assert fitted.score(X, styles, sequence_ids=ids) > fitted.score(
        X, flipped, sequence_ids=ids
    )


def test_fitted_attributes_view_the_layer(fitted):
    layer = fitted._layer
    assert fitted.visible_factors_.shape == (6, 12)
    assert fitted.hidden_factors_.shape == (16, 12)
    assert fitted.past_visible_factors_.shape == (12, 12)
    assert fitted.label_features_.shape == (2, 6)
    assert fitted.style_factors_.shape == (6, 12)
    assert np.shares_memory(fitted.hidden_factors_, layer.flat)
    assert not hasattr(fitted, "style_hidden_")  # shared: one matrix
    separate = small_model(shared_style_weights=False, n_iter=2)
    X, ids, styles = styled_data()
    separate.fit(X, styles, sequence_ids=ids)
    assert separate.style_hidden_.shape == (6, 12)
    assert separate._layer.flat.size > fitted._layer.flat.size


def test_labels_of_any_kind_and_label_weights():
    X, ids, styles = styled_data()
    codes = np.where(styles == "high", 7, 3)
    model = small_model(n_iter=2).fit(X, codes, sequence_ids=ids)
    assert_array_equal(model.classes_, [3, 7])
    # label weights are mappings: a 2-D y is one column per label factor
    weights = np.stack([styles == "high", styles == "low"], axis=1).astype(float)
    with pytest.raises(ValueError, match=r"2 label factors.*\{label: weight\}"):
        small_model(n_iter=2).fit(X, weights, sequence_ids=ids)
    blends = [dict(zip(["high", "low"], row, strict=True)) for row in weights]
    model = small_model(n_iter=2).fit(X, blends, sequence_ids=ids)
    assert_array_equal(model.classes_, ["high", "low"])
    assert model.sample(5, style="low", n_gibbs=2).shape == (5, 6)


def exact_log_likelihood(model, X, ids, weights):
    """``log p(x_t | past, y_t)`` from the energy, summed over every ``h``."""
    layer = model._layer
    d, order = layer.n_features, layer.order
    states = np.array(list(itertools.product([0, 1], repeat=layer.n_components)))
    result = []
    for t in range(len(X)):
        start = np.flatnonzero(ids == ids[t])[0]
        p = np.concatenate([X[max(t - q, start)] for q in range(1, order + 1)])
        z = weights[t] @ layer.label_features
        g = z @ layer.style_factors
        c_hat = layer.visible_bias + layer.visible_from_factors @ (
            (p @ layer.past_visible_factors) * g
        )
        b_hat = layer.hidden_bias + layer.hidden_from_factors @ (
            (p @ layer.past_hidden_factors) * g
        )
        # W_t = W_h diag(g) W_v.T; u = W_t.T h for every h
        u = (states @ layer.hidden_factors * g) @ layer.visible_factors.T
        v = X[t]
        joint = -0.5 * np.sum((v - c_hat - u) ** 2, axis=1) + states @ b_hat
        joint += u @ c_hat + 0.5 * np.sum(u**2, axis=1)
        log_z = logsumexp(states @ b_hat + u @ c_hat + 0.5 * np.sum(u**2, axis=1))
        result.append(logsumexp(joint) - log_z - 0.5 * d * np.log(2 * np.pi))
    return np.array(result)


def test_score_samples_is_exact_for_a_tiny_model():
    X, ids, styles = styled_data(n_sequences=2)
    model = small_model(n_components=5, n_iter=3).fit(X, styles, sequence_ids=ids)
    rng = np.random.default_rng(0)
    layer = model._layer
    layer.flat[...] = 0.5 * rng.standard_normal(layer.flat.shape)
    weights = rng.dirichlet([1, 1], size=len(X))  # blends, frame by frame
    expected = exact_log_likelihood(model, X, ids, weights)
    assert_allclose(model.score_samples(X, style=weights, sequence_ids=ids), expected)
    one_hot = np.eye(2)[np.searchsorted(model.classes_, styles)]
    assert_allclose(
        model.score_samples(X, style=styles, sequence_ids=ids),
        exact_log_likelihood(model, X, ids, one_hot),
    )
    # annealing agrees with enumeration to within its error
    annealed = FactoredCRBM(**{**model.get_params(), "ais_steps": 500})
    annealed.__dict__.update({k: v for k, v in vars(model).items() if k.endswith("_")})
    annealed._layer = layer
    result = annealed._log_likelihood(
        X, _sequences(ids), method="ais", context=np.asarray(weights)
    )
    assert abs(result.log_likelihood.mean() - expected.mean()) < 0.05


def _sequences(ids):
    from sklearn_crbm.utils import check_sequence_ids

    return check_sequence_ids(ids, len(ids))


def test_predict_names_each_sequences_style(fitted):
    X, ids, styles = styled_data(random_state=2, switching=False)
    proba = fitted.predict_proba(X, sequence_ids=ids)
    assert proba.shape == (len(X), 2)
    assert_allclose(proba.sum(axis=1), 1)
    assert_array_equal(fitted.predict(X, sequence_ids=ids), styles)
    # every frame of a sequence gets its sequence's posterior
    for sequence in np.unique(ids):
        rows = proba[ids == sequence]
        assert_allclose(rows, np.broadcast_to(rows[0], rows.shape))
    skewed = FactoredCRBM(**{**fitted.get_params(), "priors": [1.0, 0.0]})
    skewed.__dict__.update(
        {k: v for k, v in vars(fitted).items() if k not in ("priors",)}
    )
    assert_array_equal(skewed.predict(X, sequence_ids=ids), "high")


def test_sample_a_style_a_blend_and_a_transition(fitted):
    X, ids, styles = styled_data()
    seed = X[:5]
    high = fitted.sample(60, history=seed, style="high", random_state=0)
    low = fitted.sample(60, history=seed, style="low", random_state=0)
    assert high[:, 0].mean() > 0.5 and low[:, 0].mean() < -0.5
    transition = np.repeat([[0.0, 1.0], [1.0, 0.0]], 30, axis=0)  # low, then high
    frames = fitted.sample(60, history=seed, style=transition, random_state=0)
    assert frames[5:30, 0].mean() < -0.5 and frames[35:, 0].mean() > 0.5
    blend = fitted.sample(
        60, history=seed, style=np.full((60, 2), 0.5), n_sequences=3, random_state=0
    )
    assert blend.shape == (180, 6) and np.all(np.isfinite(blend))
    again = fitted.sample(60, history=seed, style="high", random_state=0)
    assert_array_equal(again, high)


@pytest.mark.parametrize(
    "style, message",
    [
        ("medium", "not seen in fit"),
        (np.full((10, 2), -0.5), "non-negative"),
        (np.full((10, 2), 0.4), "sum to 1"),
        (np.full((10, 3), 1 / 3), r"shape \(n_frames, 2\)"),
        (np.full((9, 2), 0.5), "9 frames' styles but 10"),
        (np.array([[np.nan, 1.0]] * 10), "NaN"),
    ],
)
def test_bad_styles_at_sample_are_clear_errors(fitted, style, message):
    with pytest.raises(ValueError, match=message):
        fitted.sample(10, style=style)


def test_bad_labels_at_fit_and_short_history_are_clear_errors(fitted):
    X, ids, styles = styled_data()
    with pytest.raises(ValueError, match="requires y"):
        small_model().fit(X, sequence_ids=ids)
    with pytest.raises(ValueError, match="one style label per frame"):
        small_model().fit(X, styles[:-1], sequence_ids=ids)
    labels = np.where(styles == "high", 1.0, 0.0)
    labels[3] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        small_model().fit(X, labels, sequence_ids=ids)
    with pytest.raises(ValueError, match="at least 2 frames"):
        fitted.sample(5, history=X[:1], style="high")
    with pytest.raises(ValueError, match="not seen in fit"):
        fitted.score(X, np.where(styles == "high", "x", "low"), sequence_ids=ids)


def test_same_random_state_same_model_and_pickle_round_trip():
    X, ids, styles = styled_data()
    one = small_model(n_iter=5).fit(X, styles, sequence_ids=ids)
    two = small_model(n_iter=5).fit(X, styles, sequence_ids=ids)
    assert_array_equal(one._layer.flat, two._layer.flat)
    loaded = pickle.loads(pickle.dumps(one))
    assert_array_equal(
        loaded.sample(10, style="low", random_state=1),
        one.sample(10, style="low", random_state=1),
    )


def test_partial_fit_and_float32(fitted):
    X, ids, styles = styled_data()
    model = small_model()
    for _ in range(3):
        model.partial_fit(X.astype(np.float32), styles, sequence_ids=ids)
    assert model.n_iter_ == 3
    assert model.hidden_factors_.dtype == np.float32
    assert model.sample(5, style="low", n_gibbs=2).dtype == np.float32
    with pytest.raises(ValueError, match="not seen in fit"):
        model.partial_fit(X, np.full(len(X), "other"), sequence_ids=ids)


def test_start_values_are_the_released_codes():
    """Every weight from 0.01 N(0, 1) in the order of the groups (R too), biases 0."""
    from sklearn_crbm.layers._factored import FactoredLayer

    layer = FactoredLayer(5, 7, 4, 3, 2, 2, np.float64).initialize(
        np.random.default_rng(0)
    )
    rng = np.random.default_rng(0)
    for group in layer.groups:
        value = getattr(layer, group.name)
        if group.decayed:
            assert_array_equal(value, 0.01 * rng.standard_normal(value.shape))
        else:
            assert_array_equal(value, 0.0)
    assert layer.label_features.shape == (2, 3)


def test_learning_rates_per_group_and_momentum_are_the_released_codes():
    """A tenth of the rate for past->visible factors and R; the rest in full,
    past->hidden and style->factor weights included; momentum 0.9 from epoch 6."""
    from sklearn_crbm._engines._training import Schedule
    from sklearn_crbm.layers._factored import FactoredLayer

    for shared in (True, False):
        layer = FactoredLayer(5, 7, 4, 3, 2, 2, np.float64, shared_style_weights=shared)
        rates = layer.views(layer.rates())
        tenth = {"past_visible_factors", "visible_from_factors", "label_features"}
        for name, rate in rates.items():
            assert_array_equal(rate, 0.1 if name in tenth else 1.0)
    schedule = Schedule.of(FactoredCRBM())
    assert [schedule.momentum_at(done) for done in (0, 4, 5, 199)] == [0, 0, 0.9, 0.9]


def test_balanced_frames_repeat_each_style_to_the_most_frequents_count():
    """Each style repeated round(n_max / n) times, next to its frames; a frame's
    style is its largest label weight."""
    from sklearn_crbm.models._factored import balanced_frames

    frames = np.array([2, 3, 4, 5, 7, 8, 9])
    weights = np.zeros((10, 3))
    weights[:, 0] = 1.0  # frames 2-5 and 7: style 0 (five frames)
    weights[[8, 9], :] = [[0.2, 0.8, 0.0], [0.0, 0.6, 0.4]]  # style 1 (two)
    assert_array_equal(
        balanced_frames(frames, weights), [2, 3, 4, 5, 7, 8, 8, 9, 9]
    )  # 5 / 2 rounds to 2 copies; the empty style 2 takes none
    weights[[8, 9], :] = [0.0, 0.0, 1.0]
    weights[[2, 3], :] = [0.0, 1.0, 0.0]
    # styles of 3, 2 and 2 frames: 3/2 rounds to 2
    assert_array_equal(
        balanced_frames(frames, weights), [2, 2, 3, 3, 4, 5, 7, 8, 8, 9, 9]
    )


def test_styles_are_balanced_by_default():
    """The default trains on style-balanced frames (the released code's copies)."""
    X, ids, styles = styled_data(switching=False)
    keep = (styles == "high") | (ids < 2)  # four sequences high, one low
    X, ids, styles = X[keep], ids[keep], styles[keep]
    fits = {
        balance: small_model(n_iter=3, balance_styles=balance).fit(
            X, styles, sequence_ids=ids
        )
        for balance in (True, False)
    }
    default = small_model(n_iter=3).fit(X, styles, sequence_ids=ids)
    assert_array_equal(default.style_factors_, fits[True].style_factors_)
    assert not np.allclose(fits[True].style_factors_, fits[False].style_factors_)


def _bounded_update(max_step, statistics):
    """One momentum step of a small layer, bounded; ``(before, after, update)``."""
    from sklearn_crbm._engines._training import StepBound
    from sklearn_crbm.layers._factored import FactoredLayer
    from sklearn_crbm.layers._parameters import MomentumUpdate

    layer = FactoredLayer(5, 7, 4, 3, 2, 2, np.float64)
    layer.initialize(np.random.default_rng(0))
    before = layer.copy()
    update = StepBound(MomentumUpdate(layer), max_step)
    for name, value in statistics.items():
        getattr(update.statistics, name)[...] = value
    update.apply(0.9, 0.01, 0.0)
    return before, layer, update


def test_step_bound_scales_down_only_the_steps_beyond_it():
    huge, small = 100.0, 1e-6
    before, after, update = _bounded_update(
        0.25,
        {"style_factors": huge, "visible_factors": small, "hidden_bias": huge},
    )
    velocity = update.velocity
    for name in ("style_factors", "visible_factors", "hidden_bias"):
        assert_allclose(
            getattr(after, name) - getattr(before, name), getattr(velocity, name)
        )
    limit = 0.25 * np.linalg.norm(before.style_factors)
    assert_allclose(np.linalg.norm(velocity.style_factors), limit)
    assert_allclose(velocity.visible_factors, small)  # within the bound: as it was
    assert_allclose(velocity.hidden_bias, huge)  # biases are not bounded


def test_step_bound_keeps_training_from_running_away(data_home):
    """Bandai walks, a learning rate 20 times the default: the three-way
    weights run away within a few epochs of momentum, unless bounded."""
    import sklearn

    from sklearn_crbm._engines._training import TrainingDivergedError
    from sklearn_crbm.datasets import load_bandai_walks
    from sklearn_crbm.preprocessing import make_motion_preprocessor

    walks = load_bandai_walks(data_home)
    train = walks.takes[walks.sequence_ids] <= 5
    X, ids = walks.data[train], walks.sequence_ids[train]
    with sklearn.config_context(enable_metadata_routing=True):
        Z = make_motion_preprocessor(walks.skeleton).fit_transform(X, sequence_ids=ids)
    styles = walks.target_names[walks.target[train]]
    params = dict(n_factors=50, n_style_features=20, cd_steps=1, learning_rate=0.2)
    params.update(momentum_delay=2, n_iter=10, random_state=0)
    with pytest.raises(TrainingDivergedError, match="Lower the learning rate, and"):
        FactoredCRBM(100, max_step=None, **params).fit(Z, styles, sequence_ids=ids)
    model = FactoredCRBM(100, **params).fit(Z, styles, sequence_ids=ids)
    # finite, and learning: the untrained reconstruction error is 64
    assert model._layer.is_finite() and model.reconstruction_error_ < 52


def test_divergence_says_what_to_change():
    from sklearn_crbm._engines._training import Schedule, _divergence_message

    schedule = Schedule.of(FactoredCRBM(learning_rate=0.3))
    message = _divergence_message(schedule, 7)
    assert message.startswith("Training diverged at epoch 7")
    for advice in (
        "learning_rate=0.3",
        "Lower the learning rate",
        "max_step (now 0.25)",
    ):
        assert advice in message
    assert "max_step" not in _divergence_message(
        Schedule(**{**vars(schedule), "max_step": None}), 7
    )


@pytest.mark.parametrize("ramp", [5, 0])
def test_momentum_rises_over_the_ramp_after_the_delay(monkeypatch, ramp):
    from sklearn_crbm import ConditionalRBM
    from sklearn_crbm.layers._parameters import MomentumUpdate

    seen = []
    apply = MomentumUpdate.apply

    def recording(self, momentum, *args):
        seen.append(momentum)
        return apply(self, momentum, *args)

    monkeypatch.setattr(MomentumUpdate, "apply", recording)
    X, ids, styles = styled_data()
    n_batches = -(-(len(X) - 2 * 8) // 100)  # trainable frames per minibatch
    small_model(n_iter=12, momentum_ramp=ramp).fit(X, styles, sequence_ids=ids)
    per_epoch = seen[::n_batches]
    ramped = [0.15, 0.3, 0.45, 0.6, 0.75] if ramp else [0.9] * 5
    assert_allclose(per_epoch, [0.0] * 5 + ramped + [0.9] * 2)
    assert len(seen) == 12 * n_batches

    seen.clear()  # the CRBM has no ramp: momentum starts whole
    ConditionalRBM(n_components=4, order=2, n_iter=7).fit(X, sequence_ids=ids)
    assert sorted(set(seen)) == [0.0, 0.9] and seen.index(0.9) == 5 * n_batches


def test_imputer_fills_in_with_the_style_given_or_inferred(fitted):
    X_train, ids_train, styles_train = styled_data()
    X, ids, styles = styled_data(random_state=1, switching=False)
    one = ids == 1  # a "high" sequence
    X_missing = X[one].copy()
    X_missing[30:, 0] = np.nan
    imputer = CRBMImputer(
        fitted, n_particles=10, offset_shrinkage=None, random_state=0
    ).fit(X_train, styles_train, sequence_ids=ids_train)
    errors = {}
    for style in ("high", "low", None):
        filled = imputer.transform(X_missing, style=style)
        assert_array_equal(filled[:, 1:], X[one][:, 1:])
        errors[style] = np.mean((filled[30:, 0] - X[one][30:, 0]) ** 2)
    assert errors["high"] < 0.1 * errors["low"]
    assert errors[None] < 0.1 * errors["low"]
    with pytest.raises(ValueError, match="needs y"):
        CRBMImputer(fitted).fit(X_train, sequence_ids=ids_train)


class _MeanField:
    """A stand-in for the hidden sampler: probabilities instead of states."""

    def __init__(self, rbms):
        self.rbms = rbms

    def __call__(self, visible, rng, out, work, **_):
        return self.rbms.hidden_probabilities(visible, out=out)


@pytest.mark.parametrize("shared", [True, False])
def test_cd_statistics_are_the_gradient_of_the_free_energy_difference(
    monkeypatch, shared
):
    """With probabilities for states, CD-1's statistics are the gradient of
    ``-F(v) + F(v_recon)`` (the reconstruction held fixed)."""
    from sklearn_crbm.layers import _factored as _factored_layer
    from sklearn_crbm.layers._factored import FactoredLayer

    monkeypatch.setattr(_factored_layer, "HiddenSampler", _MeanField)
    rng = np.random.default_rng(0)
    layer = FactoredLayer(3, 4, 5, 2, 3, 2, np.float64, shared_style_weights=shared)
    layer.flat[...] = 0.5 * rng.standard_normal(layer.flat.shape)
    visible = rng.standard_normal((6, 3))
    history = rng.standard_normal((6, 6))
    context = rng.dirichlet([1, 1, 1], size=6)
    workspace = layer.new_workspace(6)
    out = layer.zeros_like()
    layer.cd_statistics(
        visible, history, context, 1, rng, out=out, scale=1.0, workspace=workspace
    )
    reconstruction = workspace.reconstruction.copy()

    def objective(flat):
        trial = layer.copy()
        trial.flat[...] = flat
        rbms = trial.frame_rbms(history, context)
        return np.sum(
            rbms.negative_free_energy(visible)
            - rbms.negative_free_energy(reconstruction)
        )

    step = 1e-6
    numeric = np.array(
        [
            (objective(layer.flat + step * e) - objective(layer.flat - step * e))
            / (2 * step)
            for e in np.eye(layer.flat.size)
        ]
    )
    assert_allclose(out.flat, numeric, rtol=1e-5, atol=1e-6)
