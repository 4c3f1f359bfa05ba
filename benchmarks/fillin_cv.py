"""Fill-in settings compared without the test trials: cross-validation on the training trials.

The held-out cells of ``fillin_baselines.py`` are the final check of issue
15; a setting chosen by them is chosen on the test data.  This benchmark
compares settings on the training trials alone.

Protocol:

- the 31 training trials of the paper's split (its walk 35_29 and jog 35_18
  are never read), preprocessed as in ``_splits.py``;
- 3 folds of whole trials, walks and jogs in each (every third walk and
  every third jog, in trial order);
- per fold, every baseline of ``fillin_baselines.py`` and one CRBM per
  training seed (``ConditionalRBM(200, order=3, n_iter=1000)`` with its
  defaults, changed by a variant's model parameters) are fitted on the
  other two folds; the CRBM fills with ``CRBMImputer``'s defaults, changed
  by the variant's imputer parameters, ``transform`` called once;
- each trial of the fold is filled twice, with its left leg and with its
  upper body erased from half-way to the end (62 trial-cells per seed);
- per variant and seed: the total error (the paper's), the mean over the
  trial-cells of log(CRBM error / best baseline's error), and the number of
  trial-cells in which the CRBM beats every baseline.

A variant is ``--variant MODEL_JSON IMPUTER_JSON``; the default compares
the defaults with nothing else.  Models are cached with ``fillin_baselines.py``'s
(``--cache-dir``).  Prints a table and writes
``benchmarks/results/fillin_cv.json``::

    python benchmarks/fillin_cv.py
    python benchmarks/fillin_cv.py --variant '{}' '{}' \\
        --variant '{"batch_size": 200}' '{}' --variant '{}' '{"observation_gain": 2}'
"""

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import tempfile  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from _common import DEFAULT_DATA_HOME, print_table, write_json  # noqa: E402
from _splits import Split  # noqa: E402
from fillin_baselines import (  # noqa: E402
    baselines,
    crbm_model,
    errors,
    fit_baseline,
    frozen_imputer,
)

from sklearn_crbm.datasets import load_cmu35  # noqa: E402
from sklearn_crbm.model_selection import make_fillin_cases  # noqa: E402

N_FOLDS = 3


def style_folds(cmu, trials):
    """Trial indices per fold: every ``N_FOLDS``-th walk and jog, in order."""
    folds = [[] for _ in range(N_FOLDS)]
    for style in np.unique(cmu.motion[trials]):
        for k, trial in enumerate(t for t in trials if cmu.motion[t] == style):
            folds[k % N_FOLDS].append(int(trial))
    return folds


def by_cell_type(scores):
    """Per variant and (style, part): mean log ratio and wins over every seed."""
    groups = {}
    for (name, _), cells in scores.items():
        for c in cells:
            groups.setdefault((name, f"{c['style']} / {c['part']}"), []).append(c)
    rows = []
    for (name, kind), cells in groups.items():
        ratio = np.array([c["error"] / c["best_baseline"] for c in cells])
        rows.append(
            dict(
                variant=name,
                cells=kind,
                log_ratio=float(np.mean(np.log(ratio))),
                won=int(np.sum(ratio < 1)),
                n_cells=len(cells),
            )
        )
    order = list(dict.fromkeys(name for name, _ in scores))
    return sorted(rows, key=lambda row: (order.index(row["variant"]), row["cells"]))


def variant_name(model_params, imputer_params):
    parts = [f"{k}={v}" for k, v in {**model_params, **imputer_params}.items()]
    return ", ".join(parts) or "defaults"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data-home", default=str(DEFAULT_DATA_HOME))
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    parser.add_argument(
        "--variant",
        nargs=2,
        action="append",
        metavar=("MODEL_JSON", "IMPUTER_JSON"),
        help="ConditionalRBM and CRBMImputer parameters (JSON objects); repeat",
    )
    parser.add_argument(
        "--cache-dir", default=str(Path(tempfile.gettempdir()) / "sklearn_crbm_issue15")
    )
    parser.add_argument("--output", default=None)
    args = parser.parse_args(argv)
    variants = [
        (json.loads(m), json.loads(i)) for m, i in (args.variant or [("{}", "{}")])
    ]

    split = Split(args.data_home, "paper")
    cmu = load_cmu35(args.data_home)
    names_list = list(cmu.sequence_names)
    X = split.X_train.astype(np.float32)
    folds = style_folds(cmu, np.unique(split.train_ids))
    # per (variant, seed): the log ratios, wins and errors over every trial-cell
    scores = {}
    for k, fold in enumerate(folds):
        names = {cmu.sequence_names[t]: cmu.sequence_names[t] for t in fold}
        cases = make_fillin_cases(cmu, split.preprocessor, trials=names)
        train = ~np.isin(split.train_ids, fold)
        X_fit, ids_fit = X[train], split.train_ids[train]
        base = [
            errors(fit_baseline(b, X_fit, ids_fit), cases) for b in baselines().values()
        ]
        best = {key: min(row[key] for row in base) for key in cases}
        for model_params, imputer_params in variants:
            name = variant_name(model_params, imputer_params)
            for seed in args.seeds:
                model = crbm_model("default", seed, n_iter=1000)
                imputer, _ = frozen_imputer(
                    args.cache_dir,
                    model.set_params(**model_params),
                    X_fit,
                    ids_fit,
                    seed,
                )
                imputer.set_params(**imputer_params)
                for key, error in errors(imputer, cases).items():
                    scores.setdefault((name, seed), []).append(
                        dict(
                            fold=k,
                            trial=key[0],
                            style=str(cmu.motion[names_list.index(key[0])]),
                            part=key[1],
                            error=error,
                            best_baseline=best[key],
                        )
                    )
            print(f"  fold {k}: {name} done", flush=True)

    rows = []
    for (name, seed), cells in scores.items():
        crbm = np.array([c["error"] for c in cells])
        best = np.array([c["best_baseline"] for c in cells])
        rows.append(
            dict(
                variant=name,
                seed=seed,
                total=float(crbm.sum()),
                log_ratio=float(np.mean(np.log(crbm / best))),
                won=int(np.sum(crbm < best)),
                n_cells=len(cells),
            )
        )
    print_table(
        rows,
        [
            ("variant", "variant", "s"),
            ("seed", "seed", "d"),
            ("total", "total error", ".1f"),
            ("log_ratio", "mean log(CRBM / best baseline)", "+.3f"),
            ("won", "trial-cells won", "d"),
            ("n_cells", "of", "d"),
        ],
        title="\nFill-in, 3-fold cross-validation on the paper split's training trials",
    )
    print_table(
        by_cell_type(scores),
        [
            ("variant", "variant", "s"),
            ("cells", "trial-cells", "s"),
            ("log_ratio", "mean log(CRBM / best baseline)", "+.3f"),
            ("won", "won", "d"),
            ("n_cells", "of", "d"),
        ],
        title="\nBy kind of trial-cell, all seeds together",
    )
    write_json(
        "fillin_cv",
        dict(
            args=vars(args),
            folds=[[cmu.sequence_names[t] for t in fold] for fold in folds],
            rows=rows,
            cells={f"{name} | seed {seed}": c for (name, seed), c in scores.items()},
        ),
        args.output,
    )
    return rows


if __name__ == "__main__":
    main()
