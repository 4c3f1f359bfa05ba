"""Filling in against every simple baseline, 5 training seeds, two splits (issue 15).

Protocol (the paper's §4.4, as ``paper_fillin.py``, with a second split):

- for each split of ``_splits.py`` (``paper``: walk 35_29 and jog 35_18
  held out; ``second``: walk 35_05 and jog 35_22), preprocess on the
  training trials and erase the left leg or the upper body of each held-out
  trial from half-way to the end;
- baselines, each fitted on the training trials: the paper's
  NearestNeighborImputer, scikit-learn's KNNImputer with 1, 5 and 10
  neighbours, and AutoregressiveImputer (linear-Gaussian AR(3), on-line
  conditional mean; full residual covariance, and diagonal);
- CRBM models (``--models``), one per training seed: ``default`` is
  ``CRBMImputer(ConditionalRBM(200, order=3, n_iter=1000))`` with every
  other parameter of both at its default, ``paper`` the same with
  ``ConditionalRBM.paper_schedule(n_iter=1000)``, ``unaveraged`` the
  defaults before ``average_fraction`` (the last epoch's parameters:
  ``_splits.UNAVERAGED``), ``every-channel`` the defaults before
  ``history_noise_fraction`` (``history_noise=0.8`` on every channel, not
  averaged: ``_splits.EARLIER_DEFAULTS``), ``ar-init`` that
  with ``init="autoregressive"`` and ``ar-init-learned`` that with
  ``visible_variance="learned"`` and ``cd_steps=5`` (both with
  ``--ar-history-noise`` if given), ``centred`` ``every-channel`` with
  ``centering=True``, ``density`` the centred density model of
  ``likelihood_baselines.py`` (``init="autoregressive"``,
  ``visible_variance="residual"``, ``centering=True``, clean histories, 60
  epochs; ``--n-iter`` ignored), ``bare`` ``ConditionalRBM()`` with
  every parameter but ``random_state`` at its default (``--n-iter``
  ignored); ``transform`` is called once, as a user would.  Each model
  also fills with the paper's on-line procedure (``--fillins paper``: one
  chain, no offset correction, no observation gain:
  ``CRBMImputer(n_particles=1, offset_shrinkage=None,
  observation_gain=1)``), the defaults before the offset correction;
- error: the paper's (per-frame mean squared error over the erased
  channels, summed over the erased frames, z-scored units).

A CRBM cell "wins" when its error is below every baseline's.  Trained
imputers are cached (``--cache-dir``, keyed by their parameters and the
data), shared with ``likelihood_baselines.py``.  Prints the tables and
writes JSON to ``benchmarks/results/fillin_baselines.json``::

    python benchmarks/fillin_baselines.py
    python benchmarks/fillin_baselines.py --seeds 0 --splits paper --models default
"""

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import tempfile  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from _splits import (  # noqa: E402
    CELLS,
    EARLIER_DEFAULTS,
    SPLITS,
    UNAVERAGED,
    Split,
    cached_model,
)
from sklearn.frozen import FrozenEstimator  # noqa: E402
from sklearn.impute import KNNImputer  # noqa: E402

from sklearn_crbm import ConditionalRBM  # noqa: E402
from sklearn_crbm.impute import (  # noqa: E402
    AutoregressiveImputer,
    CRBMImputer,
    NearestNeighborImputer,
)
from sklearn_crbm.metrics import fillin_error  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
PAPER = {"walk/leg": (8.78, 11.68), "walk/upper": (20.52, 22.20)}
# CRBMImputer settings a model fills with; the rows of "paper" are named
# "<model>, paper's fill-in".
FILLINS = {
    "default": {},
    "paper": dict(n_particles=1, offset_shrinkage=None, observation_gain=1.0),
}


# The density model of likelihood_baselines.py's "centred" row, with the
# history noise and epochs its validation trials chose for most seeds.
DENSITY = dict(
    init="autoregressive",
    visible_variance="residual",
    centering=True,
    history_noise=0.0,
    n_iter=60,
    average_fraction=0.0,
)


def baselines():
    return {
        "NearestNeighborImputer": NearestNeighborImputer(),
        "KNNImputer(1)": KNNImputer(n_neighbors=1),
        "KNNImputer(5)": KNNImputer(n_neighbors=5),
        "KNNImputer(10)": KNNImputer(n_neighbors=10),
        "AR(3), full covariance": AutoregressiveImputer(order=3),
        "AR(3), diagonal": AutoregressiveImputer(order=3, covariance_type="diag"),
    }


def crbm_model(name, seed, n_iter, ar_history_noise=None):
    """The ConditionalRBM of model ``name`` (see the module docstring)."""
    if name == "paper":
        return ConditionalRBM.paper_schedule(n_iter=n_iter, random_state=seed)
    if name == "bare":
        return ConditionalRBM(random_state=seed)
    model = ConditionalRBM(200, order=3, n_iter=n_iter, random_state=seed)
    if name in ("every-channel", "centred") or name.startswith("ar-init"):
        model.set_params(**EARLIER_DEFAULTS)  # measured at the defaults of then
    if name == "unaveraged":
        model.set_params(**UNAVERAGED)
    if name.startswith("ar-init"):
        model.set_params(init="autoregressive")
        if ar_history_noise is not None:
            model.set_params(history_noise=ar_history_noise)
    if name == "ar-init-learned":
        model.set_params(visible_variance="learned", cd_steps=5)
    if name == "centred":
        model.set_params(centering=True)
    if name == "density":
        model.set_params(**DENSITY)
    return model


def fitted_imputer(cache_dir, split, model, seed, n_iter, ar_history_noise=None):
    """``CRBMImputer(model).fit(X_train)`` and the training seconds, cached."""
    model = crbm_model(model, seed, n_iter, ar_history_noise)
    X = split.X_train.astype(np.float32)
    return frozen_imputer(cache_dir, model, X, split.train_ids, seed)


def frozen_imputer(cache_dir, model, X, sequence_ids, seed):
    """``CRBMImputer(model).fit(X)`` and the training seconds, the fit cached.

    ``fit`` would train a clone of the model; the cached fitted clone goes in
    through ``FrozenEstimator`` instead (the same imputer, without retraining
    for every run).
    """
    fitted, seconds = cached_model(cache_dir, model, X, sequence_ids)
    imputer = CRBMImputer(FrozenEstimator(fitted), random_state=seed)
    return imputer.fit(X, sequence_ids=sequence_ids), seconds


def errors(imputer, cases):
    """The fill-in error of every case (``make_fillin_cases``), by its key."""
    out = {}
    for cell, case in cases.items():
        filled = imputer.transform(case.X_missing)
        out[cell] = float(fillin_error(case.X, filled, missing_mask=case.missing_mask))
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data-home", default=str(REPO.parent / "shared" / "data"))
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3, 4])
    parser.add_argument("--splits", nargs="+", default=list(SPLITS), choices=SPLITS)
    parser.add_argument(
        "--models",
        nargs="+",
        default=["default", "paper"],
        choices=[
            "default",
            "paper",
            "unaveraged",
            "ar-init",
            "ar-init-learned",
            "bare",
            "centred",
            "density",
            "every-channel",
        ],
    )
    parser.add_argument(
        "--fillins", nargs="+", default=list(FILLINS), choices=list(FILLINS)
    )
    parser.add_argument("--n-iter", type=int, default=1000)
    parser.add_argument("--ar-history-noise", type=float, default=None)
    parser.add_argument(
        "--cache-dir", default=str(Path(tempfile.gettempdir()) / "sklearn_crbm_issue15")
    )
    parser.add_argument(
        "--output",
        default=str(REPO / "benchmarks" / "results" / "fillin_baselines.json"),
    )
    args = parser.parse_args(argv)

    results = {"args": vars(args), "splits": {}}
    for split_name in args.splits:
        split = Split(args.data_home, split_name)
        base = {
            name: errors(
                fit_baseline(imputer, split.X_train, split.train_ids), split.cases
            )
            for name, imputer in baselines().items()
        }
        best = {c: min(row[c] for row in base.values()) for c in CELLS}
        crbm = {}
        for model in args.models:
            for seed in args.seeds:
                imputer, seconds = fitted_imputer(
                    args.cache_dir,
                    split,
                    model,
                    seed,
                    args.n_iter,
                    args.ar_history_noise,
                )
                for fillin in args.fillins:
                    row = model if fillin == "default" else f"{model}, paper's fill-in"
                    imputer.set_params(**FILLINS[fillin])
                    crbm.setdefault(row, {})[seed] = errors(imputer, split.cases)
                print(
                    f"  {split_name} {model} seed {seed}: trained in {seconds:.0f} s",
                    flush=True,
                )
        results["splits"][split_name] = dict(
            trials=split.trials, baselines=base, best_baseline=best, crbm=crbm
        )
        report(split_name, split.trials, base, best, crbm)
    output = Path(args.output)
    output.parent.mkdir(parents=True, exist_ok=True)
    output.write_text(json.dumps(results, indent=2))
    print(f"\nwrote {output}")
    return results


def fit_baseline(imputer, X, sequence_ids):
    """``imputer`` fitted on ``X``: AutoregressiveImputer needs the sequences."""
    if isinstance(imputer, AutoregressiveImputer):
        return imputer.fit(X, sequence_ids=sequence_ids)
    return imputer.fit(X)


def report(split_name, trials, base, best, crbm):
    print(
        f"\nSplit '{split_name}' (walk {trials[0]}, jog {trials[1]} held out): "
        "the paper's error, lower is better"
    )
    header = f"| {'method':50s} |" + "".join(f" {c:>10s} |" for c in CELLS)
    print(header)
    print("|" + "-" * 52 + "|" + "------------|" * len(CELLS))
    if split_name == "paper":
        cells = [
            f"{PAPER[c][0]:.2f}/{PAPER[c][1]:.2f}" if c in PAPER else "-" for c in CELLS
        ]
        print(
            f"| {'paper: CRBM/nearest neighbour':50s} |"
            + "".join(f" {cell:>10s} |" for cell in cells)
        )
    for name, row in base.items():
        print(f"| {name:50s} |" + "".join(f" {row[c]:>10.2f} |" for c in CELLS))
    for model, per_seed in crbm.items():
        for seed, row in per_seed.items():
            print(
                f"| {f'CRBM {model}, seed {seed}':50s} |"
                + "".join(
                    f" {('**' if row[c] < best[c] else '') + format(row[c], '.2f'):>10s} |"
                    for c in CELLS
                )
            )
        wins = {c: sum(row[c] < best[c] for row in per_seed.values()) for c in CELLS}
        print(
            f"| {f'CRBM {model}: seeds beating all':50s} |"
            + "".join(f" {f'{wins[c]}/{len(per_seed)}':>10s} |" for c in CELLS)
        )


if __name__ == "__main__":
    main()
