"""Held-out log-likelihood per frame: CRBM against linear-Gaussian AR(3) (issue 15).

Protocol: for each split of ``_splits.py`` and training seed, the CRBMs of
``fillin_baselines.py`` (trained on the split's training trials, cached and
shared with it) score the held-out walk and jog: the mean over every frame
with 3 past frames in its own trial of ``log p(x_t | x_{t-3..t-1})`` in nats
(``ConditionalRBM.score``: exact enumeration of the hidden units when that
is cheaper, annealed importance sampling otherwise).  Baselines: the ridge
AR(3) of ``AutoregressiveImputer`` (alpha 1) with unit variance (the CRBM's
fixed-variance assumption), per-channel variances, and its full residual
covariance, scored exactly on the same frames.

Prints the table and writes JSON to
``benchmarks/results/likelihood_baselines.json``::

    python benchmarks/likelihood_baselines.py
    python benchmarks/likelihood_baselines.py --seeds 0 --splits paper
"""

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import tempfile  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from _splits import SPLITS, Split  # noqa: E402
from fillin_baselines import fitted_imputer  # noqa: E402
from scipy.stats import multivariate_normal  # noqa: E402

from sklearn_crbm.impute import AutoregressiveImputer  # noqa: E402
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


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data-home", default=str(REPO.parent / "shared" / "data"))
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3, 4])
    parser.add_argument("--splits", nargs="+", default=list(SPLITS), choices=SPLITS)
    parser.add_argument(
        "--models",
        nargs="+",
        default=["default", "paper"],
        choices=["default", "paper"],
    )
    parser.add_argument("--n-iter", type=int, default=1000)
    parser.add_argument(
        "--cache-dir", default=str(Path(tempfile.gettempdir()) / "sklearn_crbm_issue15")
    )
    parser.add_argument(
        "--output",
        default=str(REPO / "benchmarks" / "results" / "likelihood_baselines.json"),
    )
    args = parser.parse_args(argv)

    results = {"args": vars(args), "splits": {}}
    for split_name in args.splits:
        split = Split(args.data_home, split_name)
        base, frames = ar_log_likelihoods(split)
        crbm = {}
        for model in args.models:
            for seed in args.seeds:
                imputer, _ = fitted_imputer(
                    args.cache_dir, split, model, seed, args.n_iter
                )
                scores = imputer.estimator_.score_samples(
                    split.X_test, sequence_ids=split.test_ids
                )
                crbm.setdefault(model, {})[seed] = float(np.mean(scores[frames]))
        results["splits"][split_name] = dict(
            trials=split.trials, n_frames=len(frames), baselines=base, crbm=crbm
        )
        print(
            f"\nSplit '{split_name}' (walk {split.trials[0]}, jog {split.trials[1]} "
            f"held out, {len(frames)} frames): log p(x_t | past), nats per frame"
        )
        for name, value in base.items():
            print(f"| {name:34s} | {value:>9.2f} |")
        for model, per_seed in crbm.items():
            for seed, value in per_seed.items():
                print(f"| {f'CRBM {model}, seed {seed}':34s} | {value:>9.2f} |")
    output = Path(args.output)
    output.parent.mkdir(parents=True, exist_ok=True)
    output.write_text(json.dumps(results, indent=2))
    print(f"\nwrote {output}")
    return results


if __name__ == "__main__":
    main()
