"""Filling in: the defaults against every simple baseline, by mean log ratio.

The paper's §4.4 on two splits of CMU 35 (``paper``: 35_29, 35_18 held
out; ``second``: 35_05, 35_22), the paper's encoding and error: left leg or
upper body erased from half-way, filled on-line by ``CRBMImputer`` around
``ConditionalRBM(random_state=seed)`` (``--model``, ``--imputer``) and by
``NearestNeighborImputer``, ``KNNImputer`` (1, 5, 10) and
``AutoregressiveImputer`` (full, diagonal).  Per kind of cell and pooled:
the mean over seeds of ``log(CRBM error / best baseline error)`` with its
95% bootstrap interval, and the seed-cells won.

Run from the repository root (fitted models are cached)::

    python benchmarks/fillin_baselines.py
    python benchmarks/fillin_baselines.py --seeds 0 --splits paper \\
        --imputer '{"n_particles": 1, "offset_shrinkage": null}'
"""

import json

import _common as common
import numpy as np


def measure(split, seeds, model_params, imputer_params):
    """The errors of the baselines and of the CRBM of every seed, by cell."""
    X = split.X_train.astype(np.float32)
    base = common.fill_errors(common.fitted_baselines(X, split.train_ids), split.cases)
    crbm = {}
    for seed in seeds:
        imputer, seconds = common.crbm_imputer(
            X, split.train_ids, seed, model_params, imputer_params
        )
        crbm[seed] = common.fill_errors({seed: imputer}, split.cases)[seed]
        print(f"  {split.name} seed {seed}: fitted in {seconds:.0f} s", flush=True)
    return base, crbm


def errors_by_method(base, crbm):
    best = {c: min(row[c] for row in base.values()) for c in common.CELLS}
    seeds = {f"CRBM, seed {seed}": row for seed, row in crbm.items()}
    return {**base, "best baseline": best, **seeds}


def log_ratio_rows(results):
    """Per kind of cell and pooled: mean log ratio, its interval, seed-cells won."""
    rows, pooled = [], []
    for split, (base, crbm) in results.items():
        seeds = sorted(crbm)
        for cell in common.CELLS:
            best = min(row[cell] for row in base.values())
            ratios = np.log([crbm[s][cell] / best for s in seeds])
            pooled.append(ratios)
            rows.append(common.log_ratio_row(f"{split} {cell}", ratios))
    rows.append(common.log_ratio_row("all cells", np.array(pooled).T))
    return rows


def main(argv=None):
    p = common.parser(__doc__)
    splits = common.SPLITS
    p.add_argument("--splits", nargs="+", default=[*splits], choices=splits)
    p.add_argument("--model", default="{}", help="ConditionalRBM parameters, JSON")
    p.add_argument("--imputer", default="{}", help="CRBMImputer parameters, JSON")
    args = p.parse_args(argv)
    common.announce()
    model_params, imputer_params = json.loads(args.model), json.loads(args.imputer)
    results = {}
    for name in args.splits:
        split = common.Split(args.data_home, name)
        results[name] = measure(split, args.seeds, model_params, imputer_params)
        common.print_errors(
            errors_by_method(*results[name]),
            f"\nSplit {name} ({', '.join(split.trials)} held out): the paper's "
            "error, lower is better",
            with_paper=name == "paper",
        )
    ratios = log_ratio_rows(results)
    table = common.print_table(
        ratios,
        common.log_ratio_columns(),
        title="\nCRBM against the best baseline, over seeds",
    )
    splits = {name: dict(baselines=b, crbm=c) for name, (b, c) in results.items()}
    payload = dict(args=vars(args), splits=splits, log_ratios=ratios, table=table)
    common.write_json("fillin_baselines", args.output, **payload)
    return ratios


if __name__ == "__main__":
    main()
