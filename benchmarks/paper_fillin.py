"""The paper's fill-in experiment (§4.4) on CMU subject 35, against nearest neighbour.

Train on the 31 training trials (the paper's encoding); erase the left leg
or the upper body of 35_29 and 35_18 from half-way; fill in on-line; the
paper's error and degrees, the CRBM by the mean of ``--n-repeats`` single
draws (the paper's walk: leg 8.78, nearest neighbour 11.68; upper body
20.52, 22.20).  ``--variants``: ``paper`` (``paper_schedule()``, one chain)
and ``defaults``; beside ``KNNImputer(5)`` and ``IterativeImputer``.  Per
variant and cell: the mean log ratio to nearest neighbour over seeds with
its 95% interval, and the seeds that beat it.

Run from the repository root (fitted models are cached)::

    python benchmarks/paper_fillin.py
    python benchmarks/paper_fillin.py --variants defaults --seeds 0 --n-repeats 10
"""

import _common as common
import numpy as np
from sklearn.experimental import enable_iterative_imputer  # noqa: F401
from sklearn.impute import IterativeImputer, KNNImputer

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.impute import NearestNeighborImputer
from sklearn_crbm.model_selection import compare_imputers

PAPER_FILLIN = dict(n_particles=1, offset_shrinkage=None, observation_gain=1.0)
VARIANTS = {
    "paper": (ConditionalRBM.paper_schedule, PAPER_FILLIN),
    "defaults": (ConditionalRBM, {}),
}


def baselines(X):
    return {
        "NearestNeighborImputer": NearestNeighborImputer().fit(X),
        "KNNImputer(5)": KNNImputer(n_neighbors=5).fit(X),
        "IterativeImputer": IterativeImputer(max_iter=10, random_state=0).fit(X),
    }


def crbm_scores(split, variant, seed, n_repeats):
    make_model, imputer_params = VARIANTS[variant]
    X = split.X_train.astype(np.float32)
    model = make_model(random_state=seed)
    model, seconds = common.cached_fit(model, X, split.train_ids)
    imputer = common.frozen_imputer(model, X, split.train_ids, seed, **imputer_params)
    print(f"  {variant} seed {seed}: fitted in {seconds:.0f} s", flush=True)
    scores = compare_imputers(
        {0: imputer}, split.cases, n_repeats=n_repeats, random_state=seed
    )
    return scores[0]


def main(argv=None):
    p = common.parser(__doc__)
    p.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=VARIANTS)
    p.add_argument("--n-repeats", type=int, default=100, help="single draws")
    args = p.parse_args(argv)
    common.announce()
    split = common.Split(args.data_home, "paper")
    base = compare_imputers(baselines(split.X_train), split.cases)
    errors = {
        name: {c: s[c]["error"] for c in common.CELLS} for name, s in base.items()
    }
    crbm = {
        v: {s: crbm_scores(split, v, s, args.n_repeats) for s in args.seeds}
        for v in args.variants
    }
    nearest = base["NearestNeighborImputer"]
    summary = []
    for variant, per_seed in crbm.items():
        for seed, scores in per_seed.items():
            errors[f"{variant}, seed {seed}"] = {
                c: scores[c]["error"] for c in common.CELLS
            }
        for cell in common.CELLS:
            log_ratios = [
                np.log(s[cell]["error"] / nearest[cell]["error"])
                for s in per_seed.values()
            ]
            summary.append(common.log_ratio_row(f"{variant}, {cell}", log_ratios))
    common.print_errors(
        errors,
        "\nThe paper's error (CRBM: mean of single draws), lower is better",
        with_paper=True,
    )
    table = common.print_table(
        summary,
        common.log_ratio_columns("nearest neighbour"),
        title="\nCRBM against the paper's baseline, over seeds",
    )
    payload = dict(args=vars(args), baselines=base, crbm=crbm, summary=summary)
    common.write_json("paper_fillin", args.output, **payload, table=table)


if __name__ == "__main__":
    main()
