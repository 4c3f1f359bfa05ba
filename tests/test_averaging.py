"""``average_fraction``: fit keeps the mean of its last epochs' parameters.

Pinned against the epochs themselves: ``fit`` runs the same epochs as
repeated ``partial_fit`` (which does not average), so the fitted parameters
must equal the mean of the parameters those calls leave, over the last
``ceil(average_fraction * n_iter)`` of them.
"""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.utils._param_validation import InvalidParameterError

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.datasets import make_oscillations
from sklearn_crbm.layers._crbm import CRBMLayer
from sklearn_crbm.layers._parameters import ParameterAverage

GROUPS = (
    "components_",
    "intercept_hidden_",
    "intercept_visible_",
    "autoregressive_",
    "past_to_hidden_",
)


@pytest.fixture(scope="module")
def data():
    return make_oscillations(n_sequences=3, n_frames=40, random_state=0)


def epoch_parameters(X, ids, n_epochs, **params):
    """The fitted parameters after each of ``n_epochs`` partial_fit calls."""
    model = ConditionalRBM(**params)
    epochs = []
    for _ in range(n_epochs):
        model.partial_fit(X, sequence_ids=ids)
        epoch = {name: getattr(model, name).copy() for name in GROUPS}
        epoch["log_variance"] = np.log(model.visible_variance_)
        epochs.append(epoch)
    return epochs


@pytest.mark.parametrize(
    "params",
    [
        dict(),
        dict(history_noise=0.5, cd_steps=2, hidden_order=3),
        dict(visible_variance="learned"),
        # centred training averages the standard form, not its coordinates
        dict(centering=True, visible_variance="residual"),
    ],
    ids=["default", "noisy-cd2", "learned", "centred"],
)
@pytest.mark.parametrize("n_iter, fraction", [(8, 0.3), (6, 0.5), (5, 0.99)])
def test_fit_keeps_the_mean_of_its_last_epochs(data, params, n_iter, fraction):
    X, ids = data
    params = dict(n_components=6, order=2, random_state=0, **params)
    fitted = ConditionalRBM(n_iter=n_iter, average_fraction=fraction, **params)
    fitted.fit(X, sequence_ids=ids)
    epochs = epoch_parameters(X, ids, n_iter, **params)
    last = epochs[-math.ceil(fraction * n_iter) :]
    assert 1 < len(last) <= n_iter
    for name in (*GROUPS, "log_variance"):
        mean = np.mean([epoch[name] for epoch in last], axis=0)
        actual = (
            np.log(fitted.visible_variance_)
            if name == "log_variance"
            else getattr(fitted, name)
        )
        assert_allclose(actual, mean, rtol=1e-9, atol=1e-12, err_msg=name)
    # and not the last epoch's, nor the mean of one epoch more or fewer
    wrongs = [last[-1:], last[1:]]
    if len(last) < n_iter:
        wrongs.append(epochs[-len(last) - 1 :])
    for wrong in wrongs:
        mean = np.mean([epoch["components_"] for epoch in wrong], axis=0)
        assert not np.allclose(fitted.components_, mean, rtol=1e-6, atol=0)


@pytest.mark.parametrize("n_iter, fraction", [(6, 0.0), (4, 0.2)])
def test_averaging_fewer_than_two_epochs_keeps_the_last(data, n_iter, fraction):
    X, ids = data
    params = dict(n_components=6, order=2, random_state=0)
    fitted = ConditionalRBM(n_iter=n_iter, average_fraction=fraction, **params)
    fitted.fit(X, sequence_ids=ids)
    last = epoch_parameters(X, ids, n_iter, **params)[-1]
    for name in GROUPS:
        assert_allclose(getattr(fitted, name), last[name], rtol=1e-12, err_msg=name)


def test_partial_fit_does_not_average(data):
    X, ids = data
    models = [
        ConditionalRBM(6, order=2, average_fraction=fraction, random_state=0)
        for fraction in (0.0, 0.9)
    ]
    for model in models:
        for _ in range(3):
            model.partial_fit(X, sequence_ids=ids)
    assert_array_equal(models[0].components_, models[1].components_)


def test_early_stopping_keeps_its_best_epoch_unaveraged(data):
    X, ids = data
    fitted = [
        ConditionalRBM(
            6,
            order=2,
            n_iter=20,
            early_stopping=True,
            validation_fraction=0.34,
            validation_interval=5,
            average_fraction=fraction,
            random_state=0,
        ).fit(X, sequence_ids=ids)
        for fraction in (0.0, 0.5)
    ]
    assert_array_equal(fitted[0].components_, fitted[1].components_)
    assert fitted[0].validation_scores_ == fitted[1].validation_scores_


def test_averaging_is_reproducible_and_keeps_the_dtype(data):
    X, ids = data
    fits = [
        ConditionalRBM(6, order=2, n_iter=6, random_state=0).fit(
            X.astype(np.float32), sequence_ids=ids
        )
        for _ in range(2)
    ]
    assert fits[0].components_.dtype == np.float32
    assert fits[0].components_.flags.c_contiguous
    assert_array_equal(fits[0].components_, fits[1].components_)


@pytest.mark.parametrize("bad", [1.0, 1.5, -0.1, "half"])
def test_bad_average_fraction_is_rejected(data, bad):
    X, ids = data
    with pytest.raises(InvalidParameterError, match="average_fraction"):
        ConditionalRBM(4, average_fraction=bad).fit(X, sequence_ids=ids)


def test_the_running_mean_is_the_mean():
    rng = np.random.default_rng(0)
    params = CRBMLayer(3, 4, 2, 2, "gaussian", np.float64)
    samples = rng.normal(size=(7, params.flat.size))
    average = ParameterAverage()
    for sample in samples:
        params.flat[...] = sample
        average.add(params)
    assert average.count == 7
    assert_allclose(average.mean.flat, samples.mean(axis=0), rtol=1e-13)
    assert average.mean.flat is not params.flat


def test_paper_schedule_does_not_average():
    assert ConditionalRBM.paper_schedule().average_fraction == 0.0
