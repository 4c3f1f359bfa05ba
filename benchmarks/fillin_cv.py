"""Fill-in settings compared by cross-validation on the training trials alone.

The 31 training trials of the paper's split (its test trials are never
read) in 3 folds of whole trials, walks and jogs in each; per fold the
baselines of ``fillin_baselines.py`` and one CRBM per seed (``--model``,
``--imputer``) fitted on the other folds, each trial filled with its left
leg, then its upper body, erased from half-way.  Per seed, per kind of
trial-cell and pooled: the mean ``log(CRBM error / best baseline error)``,
its 95% bootstrap interval and the trial-cells won.

Run from the repository root (fitted models are cached)::

    python benchmarks/fillin_cv.py
    python benchmarks/fillin_cv.py --model '{"batch_size": 200}'
"""

import json

import numpy as np
from _common import (
    Split,
    announce,
    crbm_imputer,
    fill_errors,
    fitted_baselines,
    log_ratio_columns,
    log_ratio_row,
    parser,
    print_table,
    style_folds,
    write_json,
)

from sklearn_crbm.model_selection import make_fillin_cases

N_FOLDS = 3


def fold_cells(split, fold, seeds, model_params, imputer_params):
    """Every trial-cell of one fold: its kind, the CRBM's and best baseline's error."""
    cmu = split.cmu
    names = {cmu.sequence_names[t]: cmu.sequence_names[t] for t in fold}
    cases = make_fillin_cases(cmu, split.preprocessor, trials=names)
    train = ~np.isin(split.train_ids, fold)
    X, ids = split.X_train[train].astype(np.float32), split.train_ids[train]
    base = fill_errors(fitted_baselines(X, ids), cases).values()
    cells = []
    for seed in seeds:
        imputer, _ = crbm_imputer(X, ids, seed, model_params, imputer_params)
        for (trial, part), error in fill_errors({0: imputer}, cases)[0].items():
            style = cmu.motion[list(cmu.sequence_names).index(trial)]
            kind = f"{style}/{'leg' if part == 'left leg' else 'upper'}"
            cell = dict(seed=seed, trial=trial, kind=kind, error=error)
            best = min(row[trial, part] for row in base)
            cells.append(dict(cell, best_baseline=best))
    return cells


def summary_rows(cells, seeds):
    """Per seed, per kind of trial-cell and pooled: the log ratio's mean and more."""
    log_ratio = {s: {} for s in seeds}
    for c in cells:
        ratio = np.log(c["error"] / c["best_baseline"])
        log_ratio[c["seed"]].setdefault(c["kind"], []).append(ratio)
    per_seed = [
        dict(
            seed=s,
            total=sum(c["error"] for c in cells if c["seed"] == s),
            mean=float(np.mean(np.concatenate(list(log_ratio[s].values())))),
        )
        for s in seeds
    ]
    kinds = sorted(log_ratio[seeds[0]])
    rows = [log_ratio_row(kind, [log_ratio[s][kind] for s in seeds]) for kind in kinds]
    pooled = [np.concatenate([log_ratio[s][k] for k in kinds]) for s in seeds]
    return per_seed, [*rows, log_ratio_row("all trial-cells", pooled)]


def main(argv=None):
    p = parser(__doc__, seeds=(0, 1, 2, 3))
    p.add_argument("--model", default="{}", help="ConditionalRBM parameters, JSON")
    p.add_argument("--imputer", default="{}", help="CRBMImputer parameters, JSON")
    args = p.parse_args(argv)
    announce()
    model_params, imputer_params = json.loads(args.model), json.loads(args.imputer)
    split = Split(args.data_home, "paper")
    styles = np.asarray(split.cmu.motion)
    folds = style_folds(styles, np.unique(split.train_ids), N_FOLDS)
    cells = []
    for k, fold in enumerate(folds):
        cells += fold_cells(split, fold, args.seeds, model_params, imputer_params)
        print(f"  fold {k} done", flush=True)
    per_seed, rows = summary_rows(cells, args.seeds)
    print_table(
        per_seed,
        [
            "seed",
            ("total", "total error", ".1f"),
            ("mean", "mean log(CRBM / best baseline)", "+.3f"),
        ],
        title="\n3-fold cross-validation on the paper split's training trials",
    )
    table = print_table(rows, log_ratio_columns(), title="\nBy kind of trial-cell")
    names = [[split.cmu.sequence_names[t] for t in fold] for fold in folds]
    payload = dict(args=vars(args), folds=names, per_seed=per_seed, log_ratios=rows)
    write_json("fillin_cv", args.output, **payload, cells=cells, table=table)
    return rows


if __name__ == "__main__":
    main()
