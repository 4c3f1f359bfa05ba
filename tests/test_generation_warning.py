"""sample warns with a GenerationWarning when generated motion dies out or blows up."""

import pickle
import re
import warnings

import numpy as np
import pytest
import sklearn

import sklearn_crbm
from sklearn_crbm import ConditionalRBM, FactoredCRBM, LabelledCRBM, StackedCRBM
from sklearn_crbm.datasets import make_oscillations, make_walker
from sklearn_crbm.exceptions import GenerationWarning, TrainingDivergedError
from sklearn_crbm.metrics._liveliness import (
    BLOWN_DEVIATIONS,
    BLOWN_REACH,
    DEAD_FRACTION,
    LIVELINESS_FRAMES,
    generated_liveliness,
    lifeless_message,
    reference_amplitude,
)
from sklearn_crbm.preprocessing import make_motion_pipeline


@pytest.fixture(scope="module")
def oscillations():
    return make_oscillations(n_sequences=4, n_frames=150, random_state=0)


def _statistics(model):
    return model.generation_statistics_


def _middle(take):
    """The ``LIVELINESS_FRAMES`` frames in the middle of a take."""
    start = (len(take) - LIVELINESS_FRAMES) // 2
    return take[start : start + LIVELINESS_FRAMES]


def test_a_take_that_rests_at_its_ends_is_judged_by_its_middle():
    """Takes that wave between rests: waving like them is alive, resting dead."""
    t = np.arange(400)
    waving = (t >= 100) & (t < 300)  # the last 100 frames rest
    X = np.column_stack([np.sin(t / 3.0) * waving, np.cos(t / 3.0) * waving])
    X = np.vstack([X, X]) + 0.001 * np.random.default_rng(0).standard_normal((800, 2))
    ids = np.repeat([0, 1], 400)
    model = ConditionalRBM(4, n_iter=1, random_state=0).fit(X, sequence_ids=ids)
    stats = _statistics(model)
    keeps_waving = np.column_stack([np.sin(t / 3.0), np.cos(t / 3.0)])[:150]
    assert lifeless_message(keeps_waving, 150, stats) == ""
    resting = np.zeros((150, 2)) + 0.001 * keeps_waving
    assert "died out" in lifeless_message(resting, 150, stats)


def test_fit_keeps_the_training_statistics(oscillations):
    X, ids = oscillations
    model = ConditionalRBM(8, n_iter=2, random_state=0).fit(X, sequence_ids=ids)
    stats = _statistics(model)
    assert np.allclose(stats.mean, X.mean(axis=0))
    assert stats.scale == pytest.approx(X.std(axis=0).max())
    middle = [_middle(X[ids == k]) for k in range(4)]
    expected = np.mean([np.sqrt(part.var(axis=0).mean()) for part in middle])
    assert stats.amplitude == pytest.approx(expected)
    assert stats.n_frames == len(X)


def test_partial_fit_joins_the_statistics_of_its_calls(oscillations):
    X, ids = oscillations
    first, second = ids < 2, ids >= 2
    model = ConditionalRBM(8, random_state=0)
    model.partial_fit(X[first], sequence_ids=ids[first])
    model.partial_fit(X[second], sequence_ids=ids[second])
    whole = ConditionalRBM(8, n_iter=1, random_state=0).fit(X, sequence_ids=ids)
    joined, expected = _statistics(model), _statistics(whole)
    assert np.allclose(joined.mean, expected.mean)
    assert joined.amplitude == pytest.approx(expected.amplitude)  # equal lengths
    assert joined.n_frames == len(X)


def _statistics_of(frames):
    return sklearn.utils.Bunch(
        mean=np.zeros(frames.shape[1]), scale=1.0, amplitude=1.0, n_frames=1
    )


def test_lifeless_message_names_dead_and_blown_sequences():
    t = np.arange(200)[:, None]
    lively = np.sqrt(2) * np.sin(2 * np.pi * t / 25) * np.ones((1, 2))  # 4 cycles
    dying = lively * np.exp(-t / 20)
    blown = lively.copy()
    blown[150, 1] = BLOWN_DEVIATIONS + 1
    frames = np.concatenate([lively, dying, blown])
    stats = _statistics_of(frames)
    liveliness = generated_liveliness(frames, 200, stats)
    assert liveliness[0] == pytest.approx(1.0, abs=0.01)
    assert liveliness[1] < DEAD_FRACTION
    message = lifeless_message(frames, 200, stats)
    assert "Sequence 2 of 3 blew up (values up to 11 training" in message
    assert "Sequence 1 of 3 died out" in message and "raise n_iter" in message
    assert lifeless_message(lively, 200, stats) == ""
    not_finite = lively.copy()
    not_finite[10, 0] = np.nan
    assert "blew up (values up to inf" in lifeless_message(not_finite, 200, stats)


def test_a_channel_is_blown_only_beyond_where_its_training_values_went():
    """A channel of small spread with rare far values (a toe) is judged
    against how far its training values went, the others as before."""
    rng = np.random.default_rng(0)
    X = rng.normal(scale=[1.0, 0.3], size=(1000, 2))
    X[100, 1] = 13.0  # one training value beyond BLOWN_DEVIATIONS widest spreads
    model = ConditionalRBM(4, order=1, n_iter=1, random_state=0).fit(X)
    stats = _statistics(model)
    np.testing.assert_allclose(stats.reach, np.abs(X - X.mean(axis=0)).max(axis=0))
    like_training = X[:200].copy()
    assert np.abs(like_training - stats.mean).max() > BLOWN_DEVIATIONS * stats.scale
    assert lifeless_message(like_training, 200, stats) == ""
    beyond = like_training.copy()
    beyond[100, 1] = stats.mean[1] + BLOWN_REACH * stats.reach[1] * 1.01
    assert "Sequence 0 of 1 blew up" in lifeless_message(beyond, 200, stats)
    ordinary = like_training.copy()  # the other channel's limit is unchanged
    ordinary[100, 0] = stats.mean[0] + 1.01 * BLOWN_DEVIATIONS * stats.scale
    assert "blew up" in lifeless_message(ordinary, 200, stats)


def test_partial_fit_bounds_the_reach_of_its_calls(oscillations):
    X, ids = oscillations
    model = ConditionalRBM(8, random_state=0)
    for part in (ids < 2, ids >= 2):
        model.partial_fit(X[part], sequence_ids=ids[part])
    exact = np.abs(X - X.mean(axis=0)).max(axis=0)
    bound = _statistics(model).reach
    assert np.all(bound >= exact - 1e-12)
    assert np.all(bound <= exact + 2 * np.abs(X.mean(axis=0)).max() + 1)


def test_short_sequences_are_judged_only_for_blowing_up():
    frames = np.zeros((LIVELINESS_FRAMES - 1, 2))
    stats = _statistics_of(frames)
    assert np.isnan(generated_liveliness(frames, len(frames), stats)).all()
    assert lifeless_message(frames, len(frames), stats) == ""


def test_an_under_trained_model_warns_at_sample(oscillations):
    X, ids = oscillations
    model = ConditionalRBM(n_iter=5, random_state=0).fit(X, sequence_ids=ids)
    with pytest.warns(GenerationWarning, match=r"Sequences 0, 1 of 2 died out") as w:
        model.sample(LIVELINESS_FRAMES, n_sequences=2, random_state=0)
    assert w[0].filename == __file__  # points at the caller's line


def test_a_model_that_blows_up_warns(oscillations):
    X, ids = oscillations
    model = ConditionalRBM(8, order=1, n_iter=2, random_state=0)
    model.fit(X, sequence_ids=ids)
    model.autoregressive_ = 1.5 * np.eye(X.shape[1])[None]
    with pytest.warns(GenerationWarning, match="blew up"):
        model.sample(30, random_state=0)


def test_lively_generation_does_not_warn(oscillations):
    X, ids = oscillations
    model = ConditionalRBM(8, order=1, n_iter=2, random_state=0)
    model.fit(X, sequence_ids=ids)
    # the training data itself, as a stand-in for lively generated motion
    assert lifeless_message(X[: 2 * 150], 150, _statistics(model)) == ""
    with warnings.catch_warnings():
        warnings.simplefilter("error", GenerationWarning)
        model.sample(LIVELINESS_FRAMES - 1, random_state=0)  # too short to judge


@pytest.mark.parametrize(
    "make",
    [
        lambda: StackedCRBM((8, 8), n_iter=5, random_state=0),
        lambda: FactoredCRBM(8, n_factors=4, n_iter=5, random_state=0),
    ],
)
def test_every_estimator_warns(make):
    X, ids = make_oscillations(n_sequences=4, n_frames=150, random_state=0)
    model = make()
    needs_labels = isinstance(model, FactoredCRBM)
    labels = np.where(ids < 2, "a", "b")
    model.fit(X, *([labels] if needs_labels else []), sequence_ids=ids)
    params = dict(style="a") if needs_labels else {}
    with pytest.warns(GenerationWarning, match="died out"):
        model.sample(LIVELINESS_FRAMES, n_sequences=2, random_state=0, **params)


def test_motion_pipeline_sample_warns():
    walker = make_walker(n_sequences=2, n_frames=120, random_state=0)
    pipe = make_motion_pipeline(walker.skeleton, ConditionalRBM(8, n_iter=5))
    with sklearn.config_context(enable_metadata_routing=True):
        pipe.fit(walker.data, sequence_ids=walker.sequence_ids)
    with pytest.warns(GenerationWarning, match="died out") as caught:
        pipe.sample(LIVELINESS_FRAMES, random_state=0)
    assert caught[0].filename == __file__


def test_a_model_pickled_before_the_statistics_samples_without_judging(oscillations):
    X, ids = oscillations
    model = ConditionalRBM(n_iter=5, random_state=0).fit(X, sequence_ids=ids)
    state = model.__getstate__()
    del state["generation_statistics_"]
    old = ConditionalRBM.__new__(ConditionalRBM)
    old.__setstate__(pickle.loads(pickle.dumps(state)))
    with warnings.catch_warnings():
        warnings.simplefilter("error", GenerationWarning)
        old.sample(LIVELINESS_FRAMES, random_state=0)


def _slow_and_fast(oscillations, slow=0.3):
    """Two styles of the oscillations: "fast" as they are, "slow" at ``slow``
    times their amplitude (about the mean)."""
    X, ids = oscillations
    styles = np.where(ids < 2, "fast", "slow")
    mean = X.mean(axis=0)
    X = np.where(styles[:, None] == "slow", mean + slow * (X - mean), X)
    return X, ids, styles


def _middle_amplitude(part):
    return np.sqrt(_middle(part).var(axis=0).mean())


@pytest.mark.parametrize("estimator", [FactoredCRBM, LabelledCRBM])
def test_style_models_keep_each_styles_amplitude(oscillations, estimator):
    X, ids, styles = _slow_and_fast(oscillations)
    model = estimator(8, n_iter=2, random_state=0)
    model.fit(X, styles, sequence_ids=ids)
    stats = _statistics(model)
    for k, style in enumerate(model.classes_):
        own = [_middle_amplitude(X[ids == i]) for i in np.unique(ids[styles == style])]
        assert stats.label_amplitude[k] == pytest.approx(np.mean(own))
    np.testing.assert_allclose(stats.label_weight, [2 * LIVELINESS_FRAMES] * 2)
    assert stats.amplitude == pytest.approx(stats.label_amplitude.mean())


def test_a_slow_style_is_judged_against_its_own_takes(oscillations):
    X, ids, styles = _slow_and_fast(oscillations)
    model = FactoredCRBM(8, n_factors=4, n_iter=2, random_state=0)
    stats = _statistics(model.fit(X, styles, sequence_ids=ids))
    slow_takes = X[styles == "slow"]  # real motion of the slow style
    slow, fast = np.eye(2)[[1]], np.eye(2)[[0]]
    pooled = generated_liveliness(slow_takes, 150, stats)
    assert np.all(pooled < DEAD_FRACTION)  # the pooled reference calls it dead
    own = generated_liveliness(slow_takes, 150, stats, slow)
    # the reference is the takes' middles, and their ends move as much
    assert own.mean() == pytest.approx(1, rel=0.01)
    assert lifeless_message(slow_takes, 150, stats, labels=slow) == ""
    # the fast style's motion at the slow style's amplitude has died out
    message = lifeless_message(slow_takes, 150, stats, labels=fast)
    assert "Sequences 0, 1 of 2 died out" in message
    assert "as the training sequences of the style asked for" in message
    for names in (np.array(["fast", "slow"]), np.array(["fast", "slow"], object)):
        named = lifeless_message(slow_takes, 150, stats, labels=fast, label_names=names)
        assert "of the style asked for ('fast')" in named
    blend = lifeless_message(
        slow_takes,
        150,
        stats,
        labels=np.array([[0.75, 0.25]]),
        label_names=np.array(["fast", "slow"]),
    )
    assert "of the style asked for ('fast' 0.75, 'slow' 0.25)" in blend
    # a blend is judged against the mean of its styles' amplitudes
    half = reference_amplitude(stats, np.full((1, 2), 0.5))
    assert half == pytest.approx(stats.label_amplitude.mean())


def test_unlabelled_statistics_and_labels_give_the_pooled_reference(oscillations):
    X, ids = oscillations
    model = ConditionalRBM(8, n_iter=2, random_state=0).fit(X, sequence_ids=ids)
    stats = _statistics(model)
    assert "label_amplitude" not in stats
    assert reference_amplitude(stats, np.eye(2)[[0]]) == stats.amplitude


def test_partial_fit_joins_each_styles_amplitude(oscillations):
    X, ids, styles = _slow_and_fast(oscillations)
    model = FactoredCRBM(8, n_factors=4, random_state=0)
    for part in (ids % 2 == 0, ids % 2 == 1):  # one take of each style per call
        model.partial_fit(X[part], styles[part], sequence_ids=ids[part])
    whole = FactoredCRBM(8, n_factors=4, n_iter=1, random_state=0)
    whole.fit(X, styles, sequence_ids=ids)
    joined, expected = _statistics(model), _statistics(whole)
    np.testing.assert_allclose(joined.label_amplitude, expected.label_amplitude)
    np.testing.assert_allclose(joined.label_weight, expected.label_weight)


def test_sample_judges_a_style_model_by_the_style_asked_for(oscillations):
    X, ids, styles = _slow_and_fast(oscillations)
    model = FactoredCRBM(n_iter=5, random_state=0).fit(X, styles, sequence_ids=ids)
    with pytest.warns(GenerationWarning, match=r"of the style asked for \('fast'\)"):
        model.sample(LIVELINESS_FRAMES, style="fast", n_sequences=2, random_state=0)


def test_the_exceptions_module_is_public():
    assert sklearn_crbm.exceptions.GenerationWarning is GenerationWarning
    assert issubclass(GenerationWarning, UserWarning)
    assert sklearn_crbm.TrainingDivergedError is TrainingDivergedError
    assert re.match("sklearn_crbm", TrainingDivergedError.__module__)


def test_binary_visibles_blow_up_only_when_not_finite():
    X = np.zeros((1000, 5))
    X[[7, 107, 207, 307, 407], range(5)] = 1.0  # one spike a channel: a tiny scale
    model = ConditionalRBM(8, visible_type="binary", n_iter=2, random_state=0)
    model.fit(X)
    frames = model.sample(30, random_state=0)
    assert np.abs(frames - X.mean(axis=0)).max() > BLOWN_DEVIATIONS * X.std(0).max()
    with warnings.catch_warnings():
        warnings.simplefilter("error", GenerationWarning)
        model.sample(30, random_state=0)
