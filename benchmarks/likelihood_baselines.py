"""Held-out log-likelihood of the CRBM against linear-Gaussian AR(3) models.

On the splits of ``fillin_baselines.py``: the mean held-out ``log p(x_t |
past)`` (nats per frame) of the ridge AR(3) with unit, per-channel and full
residual variance (closed form); ``ConditionalRBM()``; the density model
(``init="autoregressive"``, ``visible_variance="residual"``, centred, clean
histories, 60 epochs), also without ``W`` and past-to-hidden weights; the
CRBMs by forward and reverse annealing (``--ais STEPS CHAINS``, 50 x 2).

Run from the repository root (models shared with ``fillin_baselines.py``)::

    python benchmarks/likelihood_baselines.py
    python benchmarks/likelihood_baselines.py --ais 500 16
"""

import copy

import _common as common
import numpy as np
from scipy.stats import multivariate_normal

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.impute import AutoregressiveImputer

ORDER = 3
MODELS = {
    "CRBM, the defaults": {},
    "CRBM, density model": dict(
        init="autoregressive",
        visible_variance="residual",
        centering=True,
        history_noise=0.0,
        n_iter=60,
        average_fraction=0.0,
    ),
}


def ar_log_likelihoods(split, frames):
    """Mean held-out log p(x_t | past) of the ridge AR(3), three noise models."""
    out = {}
    for name, covariance_type in (
        ("AR(3), unit variance", "diag"),
        ("AR(3), per-channel variances", "diag"),
        ("AR(3), full covariance", "full"),
    ):
        ar = AutoregressiveImputer(order=ORDER, covariance_type=covariance_type)
        ar.fit(split.X_train, sequence_ids=split.train_ids)
        X = split.X_test
        mean = ar.intercept_ + sum(
            X[frames - q] @ ar.coef_[q - 1].T for q in range(1, ORDER + 1)
        )
        covariance = np.eye(X.shape[1]) if "unit" in name else ar.covariance_
        density = multivariate_normal(np.zeros(X.shape[1]), covariance)
        out[name] = float(density.logpdf(X[frames] - mean).mean())
    return out


def crbm_scores(model, X, ids, frames):
    """Forward and reverse annealed estimates, and the score without hidden units."""
    result = model.estimate_log_likelihood(X, sequence_ids=ids)
    linear = copy.deepcopy(model)
    linear.components_ = 0 * model.components_
    linear.past_to_hidden_ = 0 * model.past_to_hidden_
    return dict(
        forward=float(result.log_likelihood[frames].mean()),
        reverse=float(result.lower[frames].mean()),
        without_hidden=float(linear.score_samples(X, sequence_ids=ids)[frames].mean()),
    )


def main(argv=None):
    p = common.parser(__doc__)
    splits = common.SPLITS
    p.add_argument("--splits", nargs="+", default=[*splits], choices=splits)
    p.add_argument("--ais", type=int, nargs=2, metavar=("STEPS", "CHAINS"))
    args = p.parse_args(argv)
    common.announce()
    results, rows = {}, []
    for name in args.splits:
        split = common.Split(args.data_home, name)
        frames = common.frames_with_history(split.test_ids, ORDER)
        X_train, X_test = (X.astype(np.float32) for X in (split.X_train, split.X_test))
        ar = ar_log_likelihoods(split, frames)
        rows += [dict(split=name, model=model, mean=v) for model, v in ar.items()]
        crbm = {}
        for model_name, params in MODELS.items():
            for seed in args.seeds:
                model = ConditionalRBM(random_state=seed, **params)
                model, _ = common.cached_fit(model, X_train, split.train_ids)
                if args.ais:
                    model.set_params(ais_steps=args.ais[0], ais_chains=args.ais[1])
                scores = crbm_scores(model, X_test, split.test_ids, frames)
                crbm.setdefault(model_name, {})[seed] = scores
                print(f"  {name} {model_name} seed {seed}: {scores}", flush=True)
            rows.append(seed_summary(name, model_name, crbm[model_name]))
        results[name] = dict(n_frames=len(frames), ar=ar, crbm=crbm)
    columns = ["split", "model", ("mean", "mean over seeds", ".2f"),
               ("low", "lowest seed", ".2f"), ("high", "highest seed", ".2f"),
               ("gap", "forward - reverse, largest", ".3f"),
               ("without_hidden", "without hidden units", ".2f")]  # fmt: skip
    title = "\nHeld-out log p(x_t | past), nats per frame (forward annealing)"
    table = common.print_table(rows, columns, title=title)
    payload = dict(args=vars(args), splits=results, table=table)
    common.write_json("likelihood_baselines", args.output, **payload)
    return rows


def seed_summary(split, model, per_seed):
    forward = [s["forward"] for s in per_seed.values()]
    row = dict(
        split=split,
        model=model,
        mean=float(np.mean(forward)),
        low=min(forward),
        high=max(forward),
        gap=max(s["forward"] - s["reverse"] for s in per_seed.values()),
    )
    if "density" in model:
        without = [s["without_hidden"] for s in per_seed.values()]
        row["without_hidden"] = float(np.mean(without))
    return row


if __name__ == "__main__":
    main()
