"""n_iter="auto": the updates of CMU 35 for small corpora, a cap for large ones."""

import math

import numpy as np
import pytest

from sklearn_crbm import ConditionalRBM, FactoredCRBM, LabelledCRBM
from sklearn_crbm._engines._training import Schedule, UpdateBudget
from sklearn_crbm.datasets import load_cmu35, make_oscillations

BUDGET = ConditionalRBM._update_budget


def _trainable(sequence_ids, order=3):
    lengths = np.unique(sequence_ids, return_counts=True)[1]
    return int(np.sum(np.maximum(lengths - order, 0)))


@pytest.mark.parametrize("subset", ["all", "train"])
def test_cmu35_trains_the_1000_epochs_it_always_did(data_home, subset):
    cmu = load_cmu35(data_home, subset=subset)
    frames = _trainable(cmu.sequence_ids)
    assert math.ceil(frames / 100) >= 26  # 26 (train) or 28 (all) minibatches
    assert ConditionalRBM()._n_epochs(frames) == 1000
    # and momentum counts its own epochs, as it always did
    assert BUDGET.epoch_updates(frames, 100) is None


@pytest.mark.parametrize(
    "n_frames, epochs",
    [(2500, 1000), (2400, 1042), (876, 2778), (40, 25000)],
)
def test_small_corpora_get_25000_updates(n_frames, epochs):
    assert ConditionalRBM()._n_epochs(n_frames) == epochs
    batches = math.ceil(n_frames / 100)
    assert epochs * batches >= BUDGET.min_updates or epochs == BUDGET.epochs


@pytest.mark.parametrize(
    "n_frames, epochs",
    [(10_000, 1000), (10_001, 990), (132_297, 75), (384_931, 25), (10**8, 1)],
)
def test_large_corpora_get_at_most_100000_updates(n_frames, epochs):
    assert ConditionalRBM()._n_epochs(n_frames) == epochs
    assert epochs * math.ceil(n_frames / 100) <= BUDGET.max_updates or epochs == 1


def test_a_capped_schedule_starts_momentum_at_the_same_fraction_of_training():
    budget = UpdateBudget(1000, max_updates=100_000)
    assert budget.epoch_updates(10_000, 100) is None
    assert budget.epoch_updates(132_297, 100) == 100
    schedule = Schedule(
        learning_rate=1e-3,
        momentum=0.9,
        momentum_delay=5,
        weight_decay=0.0,
        cd_steps=1,
        batch_size=100,
        batching="shuffled",
        history_noise=0.0,
        history_noise_fraction=1.0,
        epoch_updates=100,
    )
    # after 5 of 1000 epochs of 100 updates, within the first of 75 real epochs
    assert schedule.momentum_of_update(499, 1323) == 0.0
    assert schedule.momentum_of_update(500, 1323) == 0.9
    plain = Schedule(**{**schedule.__dict__, "epoch_updates": None})
    assert plain.momentum_of_update(5 * 1323 - 1, 1323) == 0.0
    assert plain.momentum_of_update(5 * 1323, 1323) == 0.9


def test_fit_and_early_stopping_train_the_auto_epochs(monkeypatch):
    X, ids = make_oscillations(n_sequences=2, n_frames=40, random_state=0)
    monkeypatch.setattr(ConditionalRBM, "_update_budget", UpdateBudget(1000, 1200))
    model = ConditionalRBM(4, batch_size=1000, random_state=0)
    model.fit(X, sequence_ids=ids)
    early = ConditionalRBM(
        4,
        batch_size=1000,
        early_stopping=True,
        validation_interval=600,
        random_state=0,
    ).fit(np.vstack([X, X]), sequence_ids=np.r_[ids, ids + 2])
    assert model.n_iter_ == 1200  # one minibatch an epoch
    assert early.n_iter_ == 1200


def test_fit_caps_the_updates_of_the_frames_an_epoch_trains(monkeypatch):
    X, ids = make_oscillations(n_sequences=2, n_frames=40, random_state=0)
    budget = UpdateBudget(10, max_updates=8)
    monkeypatch.setattr(ConditionalRBM, "_update_budget", budget)
    model = ConditionalRBM(4, order=2, batch_size=19, random_state=0)
    model.fit(X, sequence_ids=ids)
    assert model.n_iter_ == 2  # 76 frames: 4 minibatches an epoch
    # an epoch of every frame twice: 8 minibatches
    monkeypatch.setattr(
        ConditionalRBM,
        "_training_frames",
        lambda self, frames, _: np.r_[frames, frames],
    )
    assert model.fit(X, sequence_ids=ids).n_iter_ == 1


def test_an_uncapped_auto_fit_is_the_fit_of_its_epochs(monkeypatch):
    X, ids = make_oscillations(n_sequences=2, n_frames=40, random_state=0)
    monkeypatch.setattr(ConditionalRBM, "_update_budget", UpdateBudget(12, 0, 100))
    auto = ConditionalRBM(4, batch_size=30, random_state=0).fit(X, sequence_ids=ids)
    fixed = ConditionalRBM(4, batch_size=30, n_iter=12, random_state=0)
    fixed.fit(X, sequence_ids=ids)
    np.testing.assert_array_equal(auto.components_, fixed.components_)


def test_an_explicit_n_iter_is_kept():
    X, ids = make_oscillations(n_sequences=2, n_frames=40, random_state=0)
    model = ConditionalRBM(4, n_iter=7, random_state=0).fit(X, sequence_ids=ids)
    assert model.n_iter_ == 7


@pytest.mark.parametrize(
    "estimator, walks_frames, walks_epochs",
    # the Bandai walks: 151 balanced minibatches an epoch (FactoredCRBM,
    # 30,200 updates in 200 epochs), 11,211 trainable frames (LabelledCRBM)
    [(FactoredCRBM(), 15_100, 200), (LabelledCRBM(), 11_211, 1000)],
)
def test_style_models_keep_their_epochs_on_the_walks_and_cap_a_corpus(
    estimator, walks_frames, walks_epochs
):
    assert estimator._n_epochs(walks_frames) == walks_epochs
    corpus_frames = 132_297  # the Bandai dataset-2 development corpus
    epochs = estimator._n_epochs(corpus_frames)
    assert epochs < walks_epochs
    assert epochs * math.ceil(corpus_frames / 100) <= (
        estimator._update_budget.max_updates
    )
