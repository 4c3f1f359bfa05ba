"""Held-out log-likelihood per frame: CRBM against linear-Gaussian AR(3) (issue 15).

Protocol: for each split of ``_splits.py``, the mean over every frame of the
held-out walk and jog with 3 past frames in its own trial of ``log p(x_t |
x_{t-3..t-1})`` in nats (``ConditionalRBM.score_samples``: exact
enumeration of the hidden units when that is cheaper, annealed importance
sampling otherwise).

- ``learned``: ConditionalRBM(200, order=3, visible_variance="learned",
  cd_steps=5, init=--init, history_noise=...), one per training seed,
  trained on the split's training trials but one walk and one jog kept for
  validation; the number of epochs (a checkpoint among ``--checkpoints``)
  and the history noise (among ``--history-noise``) are those with the
  best validation log-likelihood, so the test trials choose nothing;
- ``residual RBM`` (``--rows residual``, a diagnostic): the ridge AR(3) of
  the training trials, then an RBM (200 hidden units, learned variances,
  CD-5) trained on its residuals divided by their per-channel standard
  deviations ``s``, epochs chosen on validation as above.  It is exactly a
  CRBM of order 3 (variances ``(s sigma)^2``, autoregressive weights
  those of the AR, past-to-hidden weights ``-W diag(1 / (s sigma)) A``
  and hidden biases ``b - W (c / (s sigma))``, so that the hidden units
  see the residual), written into a ``ConditionalRBM`` and scored as the
  others: what a CRBM whose hidden units model the AR's residuals gets;
- ``centred`` (``--rows centred``): ``ConditionalRBM(200, order=3,
  init="autoregressive", visible_variance="residual", centering=True)``,
  the ridge AR's residual variances kept fixed and the gradient taken in
  centred coordinates; epochs and history noise chosen on validation as
  for ``learned``; ``uncentred`` is the same without ``centering``;
- ``default``: the defaults (unit variances) of ``fillin_baselines.py``,
  1000 epochs, for ``--default-seeds``;
- baselines: the ridge AR(3) of ``AutoregressiveImputer`` (alpha 1) with
  unit variance (the CRBM's fixed-variance assumption), per-channel
  variances, and its full residual covariance, scored exactly on the same
  frames; and a control for the learned rows, the per-channel AR fitted
  on the same trials as the CRBM with its variances multiplied by the
  factor (among ``VARIANCE_FACTORS``) that scores best on the validation
  trials;
- for every learned row, the same model without its hidden units
  (``W`` and the past-to-hidden weights set to 0: exactly a linear AR with
  the model's autoregressive weights, biases and variances): what the
  hidden units add.

Prints the table and writes JSON to
``benchmarks/results/likelihood_baselines.json``::

    python benchmarks/likelihood_baselines.py
    python benchmarks/likelihood_baselines.py --seeds 0 --splits paper
    python benchmarks/likelihood_baselines.py --rows centred uncentred \
        --history-noise 0 0.1 0.2 --checkpoints 10 20 40 60 100 --test-ais 500 16
    python benchmarks/likelihood_baselines.py --init autoregressive \
        --history-noise 0 0.2 0.4 0.8 --checkpoints 1 2 3 5 10 25 50 100 \
        --default-seeds --output benchmarks/results/likelihood_ar_init.json
"""

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import copy  # noqa: E402
import json  # noqa: E402
import tempfile  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from _splits import (  # noqa: E402
    EARLIER_DEFAULTS,
    SPLITS,
    Split,
    cached_model,
)
from scipy.stats import multivariate_normal, norm  # noqa: E402

from sklearn_crbm import ConditionalRBM  # noqa: E402
from sklearn_crbm.impute import AutoregressiveImputer  # noqa: E402
from sklearn_crbm.utils._autoregression import ridge_autoregression  # noqa: E402
from sklearn_crbm.utils._sequences import check_sequence_ids, frame_history  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
ORDER = 3


def ar_log_likelihoods(split):
    """Mean held-out log p(x_t | past) of the AR(3) with three noise models."""
    frames = check_sequence_ids(split.test_ids, len(split.X_test)).valid_frames(ORDER)
    out = {}
    for name, covariance_type in (
        ("AR(3), unit variance", "diag"),
        ("AR(3), per-channel variances", "diag"),
        ("AR(3), full covariance", "full"),
    ):
        ar = AutoregressiveImputer(order=ORDER, covariance_type=covariance_type)
        ar.fit(split.X_train, sequence_ids=split.train_ids)
        history = frame_history(split.X_test, frames, ORDER)
        weights = ar.coef_.transpose(0, 2, 1).reshape(-1, split.X_test.shape[1])
        mean = history @ weights + ar.intercept_
        covariance = np.eye(len(ar.intercept_)) if "unit" in name else ar.covariance_
        residual = split.X_test[frames] - mean
        out[name] = float(
            multivariate_normal(np.zeros(len(covariance)), covariance)
            .logpdf(residual)
            .mean()
        )
    return out, frames


VARIANCE_FACTORS = (1.0, 1.1, 1.25, 1.5, 2.0, 3.0)


def calibrated_ar(split):
    """The per-channel AR of the CRBM's training trials, variances scaled on validation.

    Returns the test log-likelihood and the factor.
    """
    (X, ids), (X_val, val_ids) = validation_split(split)
    ar = AutoregressiveImputer(order=ORDER, covariance_type="diag")
    ar.fit(X, sequence_ids=ids)

    def mean_log_likelihood(Z, z_ids, factor):
        frames = check_sequence_ids(z_ids, len(Z)).valid_frames(ORDER)
        weights = ar.coef_.transpose(0, 2, 1).reshape(-1, Z.shape[1])
        mean = frame_history(Z, frames, ORDER) @ weights + ar.intercept_
        std = np.sqrt(factor * np.diag(ar.covariance_))
        return float(norm.logpdf(Z[frames], mean, std).sum(axis=1).mean())

    factor = max(VARIANCE_FACTORS, key=lambda k: mean_log_likelihood(X_val, val_ids, k))
    return mean_log_likelihood(split.X_test, split.test_ids, factor), factor


def validation_split(split):
    """The training trials without their last walk and last jog, and those two."""
    ids = split.train_ids
    trials = np.unique(ids)
    lengths = np.array([np.sum(ids == t) for t in trials])
    # the jogs are the short trials (about 40 frames, walks about 100)
    jogs, walks = trials[lengths < 70], trials[lengths >= 70]
    held = np.isin(ids, [walks[-1], jogs[-1]])
    return (split.X_train[~held], ids[~held]), (split.X_train[held], ids[held])


# The CRBM rows trained with checkpoints, by name: their parameters beyond
# 200 hidden units, order 3, the seed and the history noise.
ROW_PARAMETERS = {
    "learned": dict(visible_variance="learned", cd_steps=5),
    "centred": dict(visible_variance="residual", init="autoregressive", centering=True),
    "uncentred": dict(visible_variance="residual", init="autoregressive"),
}


def row_model(row, seed, init="random", history_noise=0.8):
    # the earlier defaults' training, with the row's noise level
    earlier = dict(EARLIER_DEFAULTS, history_noise=history_noise)
    model = ConditionalRBM(200, order=ORDER, init=init, random_state=seed, **earlier)
    return model.set_params(**ROW_PARAMETERS[row])


def chosen_by_validation(
    split, seed, checkpoints, init="random", noises=(0.8,), row="learned"
):
    """Train with checkpoints; the one with the best validation log-likelihood.

    Returns the model, its ``(history noise, epochs)`` and every validation
    score, by history noise and epoch.
    """
    (X, ids), (X_val, val_ids) = validation_split(split)
    X, X_val = X.astype(np.float32), X_val.astype(np.float32)
    frames = check_sequence_ids(val_ids, len(X_val)).valid_frames(ORDER)
    best = (-np.inf, None, None)
    scores = {}
    for noise in noises:
        model = row_model(row, seed, init, noise)
        for epoch in range(1, max(checkpoints) + 1):
            model.partial_fit(X, sequence_ids=ids)
            if epoch in checkpoints:
                value = float(
                    model.score_samples(X_val, sequence_ids=val_ids)[frames].mean()
                )
                scores.setdefault(noise, {})[epoch] = value
                if value > best[0]:
                    best = (value, (noise, epoch), copy.deepcopy(model))
    return best[2], best[1], scores


def residual_rbm(split, seed, checkpoints):
    """The AR(3), then an RBM on its whitened residuals, as one ConditionalRBM.

    Returns the CRBM whose RBM epochs (among ``checkpoints``) score best on
    the validation trials, its epochs and every validation score.
    """
    (X, ids), (X_val, val_ids) = validation_split(split)
    X, X_val = X.astype(np.float32), X_val.astype(np.float32)
    ar = ridge_autoregression(
        X.astype(np.float64),
        check_sequence_ids(ids, len(X)).valid_frames(ORDER),
        ORDER,
        1.0,
    )
    s = np.sqrt(np.mean(np.square(ar.residual), axis=0))
    rbm = ConditionalRBM(
        200, order=0, visible_variance="learned", cd_steps=5, random_state=seed
    )
    crbm = ConditionalRBM(200, order=ORDER, visible_variance="learned").partial_fit(
        X, sequence_ids=ids
    )
    frames = check_sequence_ids(val_ids, len(X_val)).valid_frames(ORDER)
    best, scores = (-np.inf, None, None), {}
    for epoch in range(1, max(checkpoints) + 1):
        rbm.partial_fit((ar.residual / s).astype(np.float32))
        if epoch in checkpoints:
            _write_residual_crbm(crbm, ar, s, rbm)
            value = float(
                crbm.score_samples(X_val, sequence_ids=val_ids)[frames].mean()
            )
            scores[epoch] = value
            if value > best[0]:
                best = (value, epoch, copy.deepcopy(crbm))
    return best[2], best[1], scores


def _write_residual_crbm(crbm, ar, s, rbm):
    """Set ``crbm`` to the AR plus ``rbm`` on the residuals divided by ``s``."""
    scale = s * np.sqrt(rbm.visible_variance_.astype(np.float64))
    W = rbm.components_.astype(np.float64)
    crbm.visible_variance_ = scale**2
    crbm.intercept_visible_ = ar.intercept + s * rbm.intercept_visible_
    crbm.autoregressive_ = ar.coef
    crbm.components_ = W
    crbm.intercept_hidden_ = rbm.intercept_hidden_ - W @ (ar.intercept / scale)
    crbm.past_to_hidden_ = -np.einsum("jd,qdk->qjk", W / scale, ar.coef)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data-home", default=str(REPO.parent / "shared" / "data"))
    parser.add_argument("--seeds", type=int, nargs="*", default=[0, 1, 2, 3, 4])
    parser.add_argument("--default-seeds", type=int, nargs="*", default=[0])
    parser.add_argument("--splits", nargs="+", default=list(SPLITS), choices=SPLITS)
    parser.add_argument(
        "--checkpoints", type=int, nargs="+", default=[10, 25, 50, 100, 200]
    )
    parser.add_argument(
        "--init", choices=["random", "autoregressive"], default="random"
    )
    parser.add_argument("--history-noise", type=float, nargs="+", default=[0.8])
    parser.add_argument(
        "--rows",
        nargs="+",
        default=["learned"],
        choices=["learned", "residual", "centred", "uncentred"],
        help="CRBM rows for --seeds: learned variances (--init), residual RBM, "
        "the ridge AR's residual variances with and without centering",
    )
    parser.add_argument(
        "--test-ais",
        type=int,
        nargs=2,
        default=None,
        metavar=("STEPS", "CHAINS"),
        help="annealing of the test scores (default: the models' 50 x 2)",
    )
    parser.add_argument(
        "--cache-dir", default=str(Path(tempfile.gettempdir()) / "sklearn_crbm_issue15")
    )
    parser.add_argument(
        "--output",
        default=str(REPO / "benchmarks" / "results" / "likelihood_baselines.json"),
    )
    args = parser.parse_args(argv)
    if not hasattr(ConditionalRBM, "estimate_log_likelihood"):
        raise SystemExit(
            "this ConditionalRBM's score_samples is not a normalised log-likelihood "
            "yet (needs the held-out likelihood of issue 16)"
        )

    results = {"args": vars(args), "splits": {}}
    for split_name in args.splits:
        split = Split(args.data_home, split_name)
        base, frames = ar_log_likelihoods(split)
        calibrated, factor = calibrated_ar(split)
        base[f"AR(3), per-channel variances x {factor:g} (validation)"] = calibrated
        X_test = split.X_test.astype(np.float32)
        rows = {}
        for seed in args.seeds:
            for row in (r for r in args.rows if r in ROW_PARAMETERS):
                model, (noise, epochs), validation = chosen_by_validation(
                    split,
                    seed,
                    set(args.checkpoints),
                    args.init,
                    args.history_noise,
                    row,
                )
                name = f"learned, init={args.init}" if row == "learned" else row
                rows.setdefault(name, {})[seed] = dict(
                    **test_scores(model, X_test, split.test_ids, frames, args.test_ais),
                    epochs=epochs,
                    history_noise=noise,
                    validation=validation,
                )
                print(
                    f"  {split_name} {row} seed {seed}: history noise {noise}, "
                    f"{epochs} epochs",
                    flush=True,
                )
            if "residual" in args.rows:
                model, epochs, validation = residual_rbm(
                    split, seed, set(args.checkpoints)
                )
                rows.setdefault("residual RBM", {})[seed] = dict(
                    **test_scores(model, X_test, split.test_ids, frames, args.test_ais),
                    epochs=epochs,
                    history_noise=0.0,
                    validation=validation,
                )
                print(
                    f"  {split_name} residual seed {seed}: {epochs} epochs", flush=True
                )
        for seed in args.default_seeds:
            model, _ = cached_model(
                args.cache_dir,
                ConditionalRBM(200, order=ORDER, n_iter=1000, random_state=seed),
                split.X_train.astype(np.float32),
                split.train_ids,
            )
            test = model.score_samples(X_test, sequence_ids=split.test_ids)
            rows.setdefault("default", {})[seed] = dict(
                log_likelihood=float(test[frames].mean())
            )
        results["splits"][split_name] = dict(
            trials=split.trials, n_frames=len(frames), baselines=base, crbm=rows
        )
        report(split_name, split.trials, len(frames), base, rows)
    output = Path(args.output)
    output.parent.mkdir(parents=True, exist_ok=True)
    output.write_text(json.dumps(results, indent=2))
    print(f"\nwrote {output}")
    return results


def test_scores(model, X_test, test_ids, frames, ais):
    """Mean test log-likelihood, forward and reverse (RAISE) annealing."""
    if ais is not None:
        model.set_params(ais_steps=ais[0], ais_chains=ais[1])
    result = model.estimate_log_likelihood(X_test, sequence_ids=test_ids)
    linear = copy.deepcopy(model)
    linear.components_ = 0 * linear.components_
    linear.past_to_hidden_ = 0 * linear.past_to_hidden_
    return dict(
        log_likelihood=float(result.log_likelihood[frames].mean()),
        reverse=float(result.lower[frames].mean()),
        without_hidden_units=float(
            linear.score_samples(X_test, sequence_ids=test_ids)[frames].mean()
        ),
    )


def report(split_name, trials, n_frames, base, rows):
    print(
        f"\nSplit '{split_name}' (walk {trials[0]}, jog {trials[1]} held out, "
        f"{n_frames} frames): log p(x_t | past), nats per frame"
    )
    for name, value in base.items():
        print(f"| {name:64s} | {value:>9.2f} |")
    for model, per_seed in rows.items():
        for seed, row in per_seed.items():
            label = f"CRBM {model}, seed {seed}" + (
                f" (noise {row['history_noise']:g}, {row['epochs']} epochs)"
                if "epochs" in row
                else ""
            )
            reverse = (
                f" (reverse {row['reverse']:.2f}, without hidden units "
                f"{row['without_hidden_units']:.2f})"
                if "reverse" in row
                else ""
            )
            print(f"| {label:64s} | {row['log_likelihood']:>9.2f} |{reverse}")


if __name__ == "__main__":
    main()
