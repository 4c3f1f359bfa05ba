"""Model selection: what the held-out log-likelihood picks, against the fill-in error.

``GridSearchCV(scoring=None)`` with ``ConditionalRBM`` on CMU 35, fold by
fold: 3 folds of whole trials (walks and jogs in each); ``--sizes`` hidden
units x ``--orders``, ``--n-iter`` epochs (``--model``); per model and fold
``score`` (nats per frame) and its time, and ``CRBMImputer``'s fill-in
error (``--imputer``; left leg, then upper body, erased from half-way).
Reports the Spearman correlation of score and minus fill-in error (order
>= 1), the pick and its fill-in against the grid's best.

Run from the repository root (fitted models are cached)::

    python benchmarks/model_selection.py
    python benchmarks/model_selection.py --sizes 10 50 --orders 1 3
"""

import json
import time

import numpy as np
import sklearn
from _common import (
    announce,
    cached_fit,
    frozen_imputer,
    parser,
    print_table,
    style_folds,
    write_json,
)
from scipy.stats import spearmanr

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.datasets import load_cmu35
from sklearn_crbm.model_selection import erasure_mask, paper_body_parts
from sklearn_crbm.preprocessing import make_motion_preprocessor

N_FOLDS = 3


class Fold:
    """The training and held-out trials of one fold, preprocessed."""

    def __init__(self, cmu, trials):
        test = np.isin(cmu.sequence_ids, trials)
        self.train_ids, self.test_ids = cmu.sequence_ids[~test], cmu.sequence_ids[test]
        pre = make_motion_preprocessor(cmu.skeleton)
        with sklearn.config_context(enable_metadata_routing=True):
            self.Z_train = pre.fit_transform(
                cmu.data[~test], sequence_ids=self.train_ids
            )
            self.Z_test = pre.transform(cmu.data[test], sequence_ids=self.test_ids)
        names = pre.get_feature_names_out()
        self.masks = {
            part: erasure_mask(
                self.Z_test,
                bones=bones,
                feature_names=names,
                sequence_ids=self.test_ids,
                strict=False,
            )
            for part, bones in paper_body_parts(cmu.skeleton).items()
        }

    def fillin_error(self, model, seed, params):
        """Mean squared error per erased entry, the two body parts averaged."""
        imputer = frozen_imputer(model, self.Z_train, self.train_ids, seed, **params)
        errors = []
        for mask in self.masks.values():
            filled = imputer.transform(
                np.where(mask, np.nan, self.Z_test), sequence_ids=self.test_ids
            )
            errors.append(np.mean(np.square(filled - self.Z_test)[mask]))
        return float(np.mean(errors))


def measure(fold, size, order, args, model_params, imputer_params):
    model = ConditionalRBM(
        size, order=order, n_iter=args.n_iter, random_state=args.seed, **model_params
    )
    model, fit_seconds = cached_fit(model, fold.Z_train, fold.train_ids)
    start = time.perf_counter()
    score = model.score(fold.Z_test, sequence_ids=fold.test_ids)
    return dict(
        score=score,
        time_ratio=(time.perf_counter() - start) / fit_seconds,
        fillin=fold.fillin_error(model, args.seed, imputer_params),
    )


def main(argv=None):
    p = parser(__doc__, seeds=None)
    p.add_argument("--sizes", type=int, nargs="+", default=[10, 50, 200, 400])
    p.add_argument("--orders", type=int, nargs="+", default=[0, 1, 3, 6])
    p.add_argument("--n-iter", type=int, default=500)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--model", default="{}", help="ConditionalRBM parameters, JSON")
    p.add_argument("--imputer", default="{}", help="CRBMImputer parameters, JSON")
    args = p.parse_args(argv)
    announce()
    model_params, imputer_params = json.loads(args.model), json.loads(args.imputer)
    cmu = load_cmu35(args.data_home)
    styles = np.asarray(cmu.motion)
    results = {}
    for k, trials in enumerate(style_folds(styles, range(len(styles)), N_FOLDS)):
        fold = Fold(cmu, trials)
        for order in args.orders:
            for size in args.sizes:
                r = measure(fold, size, order, args, model_params, imputer_params)
                results.setdefault((size, order), []).append(r)
                print(f"  fold {k}, {size} x {order}: {r}", flush=True)
    rows = [
        dict(
            config=f"{size} x {order}",
            order=order,
            **{key: float(np.mean([r[key] for r in runs])) for key in runs[0]},
        )
        for (size, order), runs in results.items()
    ]
    table = print_table(
        rows,
        [
            ("config", "hidden x order", "s"),
            ("score", "score (nats/frame)", ".3f"),
            ("fillin", "fill-in error", ".3f"),
            ("time_ratio", "score / fit time", ".3f"),
        ],
        title=f"\nCMU 35, {N_FOLDS} folds, {args.n_iter} epochs, seed {args.seed}",
    )
    with_history = [r for r in rows if r["order"] >= 1]
    scores = [r["score"] for r in with_history]
    spearman = spearmanr(scores, [-r["fillin"] for r in with_history]).statistic
    picked = max(rows, key=lambda r: r["score"])
    summary = dict(
        spearman=float(spearman),
        picked=picked["config"],
        picked_over_best=picked["fillin"] / min(r["fillin"] for r in rows),
        largest_time_ratio=max(r["time_ratio"] for r in rows),
    )
    print(
        f"Spearman(score, -fill-in error), order >= 1: {summary['spearman']:.3f}; "
        f"the search picks {picked['config']}, whose fill-in error is "
        f"{summary['picked_over_best']:.3f} x the grid's best; scoring takes at "
        f"most {summary['largest_time_ratio']:.3f} x the fit's time"
    )
    payload = dict(args=vars(args), rows=rows, summary=summary, table=table)
    write_json("model_selection", args.output, **payload)


if __name__ == "__main__":
    main()
