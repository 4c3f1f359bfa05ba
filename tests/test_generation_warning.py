"""sample warns with a GenerationWarning when generated motion dies out or blows up."""

import pickle
import re
import warnings

import numpy as np
import pytest
import sklearn

import sklearn_crbm
from sklearn_crbm import ConditionalRBM, FactoredCRBM, StackedCRBM
from sklearn_crbm._base import (
    BLOWN_DEVIATIONS,
    DEAD_FRACTION,
    LIVELINESS_FRAMES,
    generated_liveliness,
    lifeless_message,
)
from sklearn_crbm.datasets import make_oscillations, make_walker
from sklearn_crbm.exceptions import GenerationWarning, TrainingDivergedError
from sklearn_crbm.preprocessing import make_motion_pipeline


@pytest.fixture(scope="module")
def oscillations():
    return make_oscillations(n_sequences=4, n_frames=150, random_state=0)


def _statistics(model):
    return model.generation_statistics_


def test_fit_keeps_the_training_statistics(oscillations):
    X, ids = oscillations
    model = ConditionalRBM(8, n_iter=2, random_state=0).fit(X, sequence_ids=ids)
    stats = _statistics(model)
    assert np.allclose(stats.mean, X.mean(axis=0))
    assert stats.scale == pytest.approx(X.std(axis=0).max())
    last = [X[ids == k][-LIVELINESS_FRAMES:] for k in range(4)]
    expected = np.mean([np.sqrt(part.var(axis=0).mean()) for part in last])
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
