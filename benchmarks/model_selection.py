"""Choosing n_components and order by held-out log-likelihood, on CMU subject 35.

What ``GridSearchCV(scoring=None)`` does with a ConditionalRBM, measured:

- data: all 33 trials of CMU subject 35 (23 walks, 10 jogs), in 3 trial-wise
  folds with walks and jogs in every fold (the k-th walk and the k-th jog go
  to fold ``k % 3``); preprocessing (exponential maps, body-centred root,
  z-scores) fitted on the training trials of each fold;
- grid: ``--sizes`` hidden units (10, 50, 200, 400) x ``--orders`` (0, 1, 3,
  6), ``--n-iter`` epochs (500), ``random_state=--seed``, other parameters
  at their defaults;
- per fitted model and held-out fold: ``score`` (the mean held-out
  log-likelihood per frame, nats: exact for few hidden units, annealed
  importance sampling otherwise), its CPU time against the fit's; the
  held-out fill-in error (CRBMImputer on the fitted model, the paper's
  protocol: the left leg, then the upper body, erased from half-way through
  every held-out trial; mean squared error per erased entry in z-score
  units, the two parts averaged); and a generation statistic (from the
  first ``history_length`` frames of every held-out trial, 150 frames are
  generated; the relative error of their forward speed and gait frequency
  against the trial's own, averaged);
- the Spearman correlation over the grid between the score and minus the
  fill-in error (positive: a higher score goes with a smaller error), over
  the models with ``order >= 1`` and over all;
- the configuration ``GridSearchCV(scoring=None)`` picks: the highest mean
  test score over the folds (its ``best_index_``), computed here from the
  same per-fold scores rather than by refitting every model;
- a linear-Gaussian autoregressive baseline on the same scale: ridge
  AR(order) (penalty 10) with a per-channel residual variance (at least
  0.01), its closed-form held-out log-likelihood per frame.

Every (configuration, fold) result is cached as JSON under
``benchmarks/results/model_selection_cache/``, so a subset
(``--sizes 10 50 --orders 1 --folds 0``) can run first and the full grid
later reuses it.  Run from the repository root, with one BLAS thread::

    OPENBLAS_NUM_THREADS=1 python benchmarks/model_selection.py
    OPENBLAS_NUM_THREADS=1 python benchmarks/model_selection.py --sizes 10 50 --orders 0 1

Prints a table and writes ``benchmarks/results/model_selection_hn{noise}.json``
(``--history-noise``, default the estimator's).
"""

import argparse
import json
import time

import numpy as np
import sklearn
from _common import DEFAULT_DATA_HOME, RESULTS, print_table, write_json
from scipy.stats import spearmanr
from sklearn.frozen import FrozenEstimator

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.datasets import load_cmu35
from sklearn_crbm.impute import CRBMImputer
from sklearn_crbm.metrics import fillin_error, gait_statistics
from sklearn_crbm.model_selection import erasure_mask, paper_body_parts
from sklearn_crbm.preprocessing import make_motion_preprocessor

CACHE = RESULTS / "model_selection_cache"
N_GENERATED = 150
# The AR baseline: ridge penalty, and the smallest residual variance per channel.
RIDGE, VARIANCE_FLOOR = 10.0, 0.01


def trial_folds(motion, n_folds=3):
    """Fold of every trial: the k-th walk and the k-th jog go to fold k % n_folds."""
    folds = np.empty(len(motion), dtype=int)
    for style in np.unique(motion):
        members = np.flatnonzero(motion == style)
        folds[members] = np.arange(len(members)) % n_folds
    return folds


def load_fold(data_home, fold):
    cmu = load_cmu35(data_home, subset="all")
    trial_fold = trial_folds(np.asarray(cmu.motion))
    test = trial_fold[cmu.sequence_ids] == fold
    with sklearn.config_context(enable_metadata_routing=True):
        pre = make_motion_preprocessor(cmu.skeleton)
        train_ids, test_ids = cmu.sequence_ids[~test], cmu.sequence_ids[test]
        Z_train = pre.fit_transform(cmu.data[~test], sequence_ids=train_ids)
        Z_test = pre.transform(cmu.data[test], sequence_ids=test_ids)
    return dict(
        Z_train=np.asarray(Z_train),
        train_ids=train_ids,
        Z_test=np.asarray(Z_test),
        test_ids=test_ids,
        names=np.asarray(pre.get_feature_names_out()),
        scaler=pre[-1],
        unscaled_names=np.asarray(pre[:-1].get_feature_names_out()),
        parts=paper_body_parts(cmu.skeleton),
        test_trials=sorted(set(cmu.sequence_names[np.unique(test_ids)])),
    )


def fillin(model, data, seed):
    """Mean squared error per erased entry (z-scores), left leg and upper body."""
    imputer = _imputer_for(model, data, seed)
    errors = {}
    for part, bones in data["parts"].items():
        mask = erasure_mask(
            data["Z_test"],
            bones=bones,
            feature_names=data["names"],
            sequence_ids=data["test_ids"],
            strict=False,
        )
        X_missing = data["Z_test"].copy()
        X_missing[mask] = np.nan
        filled = imputer.transform(X_missing, sequence_ids=data["test_ids"])
        errors[part] = float(np.mean(np.square(filled - data["Z_test"])[mask]))
        errors[f"{part} (paper)"] = float(
            fillin_error(data["Z_test"], filled, missing_mask=mask)
        )
    return errors


def _imputer_for(model, data, seed):
    """CRBMImputer on the fitted model, without training it again."""
    imputer = CRBMImputer(FrozenEstimator(model), random_state=seed)
    try:
        return imputer.fit(data["Z_train"], sequence_ids=data["train_ids"])
    except TypeError:  # a CRBMImputer that does not know FrozenEstimator yet
        imputer = CRBMImputer(model, random_state=seed)
        imputer.estimator_ = model
        imputer.mean_ = data["Z_train"].mean(axis=0)
        imputer.n_features_in_ = model.n_features_in_
        return imputer


def generation_error(model, data, seed):
    """Relative error of generated speed and gait frequency against each trial."""
    width = max(model.history_length, 1)
    ids = data["test_ids"]
    starts = [np.flatnonzero(ids == i)[:width] for i in np.unique(ids)]
    seeds = np.stack([data["Z_test"][rows] for rows in starts])
    generated = model.sample(N_GENERATED, history=seeds, random_state=seed)
    generated_ids = np.repeat(np.arange(len(seeds)), N_GENERATED)

    def statistics(Z, sequence_ids):
        raw = data["scaler"].inverse_transform(Z)
        return gait_statistics(
            raw, sequence_ids=sequence_ids, feature_names=data["unscaled_names"]
        )

    truth = statistics(data["Z_test"], ids)
    made = statistics(generated, generated_ids)
    relative = np.abs(made - truth) / np.abs(truth)
    finite = np.isfinite(relative).all(axis=1)
    return float(np.mean(relative[finite])) if finite.any() else float("nan")


def ar_log_likelihood(data, order):
    """Held-out log p(x_t | past) per frame of a ridge Gaussian AR(order)."""

    def design(Z, ids):
        rows = [
            np.flatnonzero(ids == i)[order:] for i in np.unique(ids)
        ]  # frames with a full history
        rows = np.concatenate(rows)
        past = [Z[rows - q] for q in range(1, order + 1)]
        return np.column_stack([np.ones(len(rows)), *past]), Z[rows]

    A, y = design(data["Z_train"], data["train_ids"])
    # ridge: plain least squares on 62 x order inputs extrapolates wildly on
    # held-out trials whose channels leave the training range
    coef = np.linalg.solve(A.T @ A + RIDGE * np.eye(A.shape[1]), A.T @ y)
    # floored: a channel that hardly moves in training must not be trusted
    # to within less than a tenth of its standard deviation
    variance = np.maximum(np.mean(np.square(y - A @ coef), axis=0), VARIANCE_FLOOR)
    A_test, y_test = design(data["Z_test"], data["test_ids"])
    residual = y_test - A_test @ coef
    log_density = -0.5 * (np.log(2 * np.pi * variance) + residual**2 / variance)
    return float(np.mean(log_density.sum(axis=1)))


def history_noise(args):
    """The ``history_noise`` of the grid: the option, else the estimator's default."""
    if args.history_noise is None:
        return ConditionalRBM().history_noise
    return args.history_noise


def run_one(data, n_components, order, fold, args):
    noise = history_noise(args)
    key = f"h{n_components}_o{order}_f{fold}_it{args.n_iter}_s{args.seed}_hn{noise:g}"
    path = CACHE / f"{key}.json"
    if path.exists() and not args.no_cache:
        return json.loads(path.read_text())
    model = ConditionalRBM(
        n_components,
        order=order,
        n_iter=args.n_iter,
        history_noise=noise,
        random_state=args.seed,
    )
    start = time.process_time()
    model.fit(data["Z_train"], sequence_ids=data["train_ids"])
    fit_time = time.process_time() - start
    start = time.process_time()
    score = model.score(data["Z_test"], sequence_ids=data["test_ids"])
    score_time = time.process_time() - start
    result = dict(
        n_components=n_components,
        order=order,
        fold=fold,
        score=score,
        fit_time=fit_time,
        score_time=score_time,
        n_test_frames=len(data["Z_test"]),
        **fillin(model, data, args.seed),
        generation_error=generation_error(model, data, args.seed),
    )
    CACHE.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(result, indent=1))
    return result


def summarise(results, sizes, orders):
    rows = []
    for order in orders:
        for size in sizes:
            runs = [
                r for r in results if r["n_components"] == size and r["order"] == order
            ]
            if not runs:
                continue
            fill = [0.5 * (r["left leg"] + r["upper body"]) for r in runs]
            rows.append(
                dict(
                    config=f"{size} x {order}",
                    n_components=size,
                    order=order,
                    n_folds=len(runs),
                    score=np.mean([r["score"] for r in runs]),
                    score_sd=np.std([r["score"] for r in runs]),
                    score_time=np.mean([r["score_time"] for r in runs]),
                    fit_time=np.mean([r["fit_time"] for r in runs]),
                    time_ratio=np.mean([r["score_time"] / r["fit_time"] for r in runs]),
                    fillin=np.mean(fill),
                    left_leg=np.mean([r["left leg"] for r in runs]),
                    upper_body=np.mean([r["upper body"] for r in runs]),
                    generation=np.nanmean([r["generation_error"] for r in runs]),
                )
            )
    return rows


def correlation(rows, minimum_order):
    chosen = [r for r in rows if r["order"] >= minimum_order]
    if len(chosen) < 3:
        return float("nan")
    rho = spearmanr([r["score"] for r in chosen], [-r["fillin"] for r in chosen])
    return float(rho.statistic)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data-home", default=str(DEFAULT_DATA_HOME))
    parser.add_argument("--sizes", type=int, nargs="+", default=[10, 50, 200, 400])
    parser.add_argument("--orders", type=int, nargs="+", default=[0, 1, 3, 6])
    parser.add_argument("--folds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--n-iter", type=int, default=500)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--history-noise",
        type=float,
        default=None,
        help="ConditionalRBM's history_noise (default: the estimator's default)",
    )
    parser.add_argument("--no-cache", action="store_true", help="refit everything")
    parser.add_argument("--output", default=None)
    args = parser.parse_args(argv)

    results, baselines = [], []
    for fold in args.folds:
        data = load_fold(args.data_home, fold)
        print(f"fold {fold}: test trials {', '.join(data['test_trials'])}", flush=True)
        for order in sorted(set(args.orders) | {1, 3, 6}):
            if order >= 1:
                baselines.append(
                    dict(order=order, fold=fold, score=ar_log_likelihood(data, order))
                )
        for order in args.orders:
            for size in args.sizes:
                result = run_one(data, size, order, fold, args)
                results.append(result)
                print(
                    f"  {size:4d} hidden, order {order}: score {result['score']:8.3f} "
                    f"({result['score_time']:.2f} s, fit {result['fit_time']:.1f} s), "
                    f"fill-in {result['left leg']:.3f} / {result['upper body']:.3f}, "
                    f"generation {result['generation_error']:.3f}",
                    flush=True,
                )

    rows = summarise(results, args.sizes, args.orders)
    print_table(
        rows,
        [
            ("config", "hidden x order", "s"),
            ("score", "score (nats/frame)", ".3f"),
            ("score_sd", "sd over folds", ".3f"),
            ("score_time", "score CPU s", ".2f"),
            ("fit_time", "fit CPU s", ".1f"),
            ("time_ratio", "score / fit", ".3f"),
            ("left_leg", "fill-in leg", ".3f"),
            ("upper_body", "fill-in upper", ".3f"),
            ("fillin", "fill-in mean", ".3f"),
            ("generation", "gen. speed/freq err", ".3f"),
        ],
        title=(
            f"CMU 35, folds {args.folds}, {args.n_iter} epochs, seed {args.seed}, "
            f"history_noise {history_noise(args):g}"
        ),
    )
    ar_rows = [
        dict(
            order=order,
            score=np.mean([b["score"] for b in baselines if b["order"] == order]),
        )
        for order in sorted({b["order"] for b in baselines})
    ]
    print_table(
        ar_rows,
        [("order", "AR order", "d"), ("score", "AR log-lik (nats/frame)", ".3f")],
        title="Linear-Gaussian AR baseline (ridge 10, per-channel variance >= 0.01)",
    )
    best = max(rows, key=lambda r: r["score"]) if rows else None
    best_fill = min(r["fillin"] for r in rows) if rows else float("nan")
    summary = dict(
        spearman_order_ge_1=correlation(rows, 1),
        spearman_all=correlation(rows, 0),
        picked=best["config"] if best else None,
        picked_fillin=best["fillin"] if best else None,
        best_fillin=best_fill,
        picked_over_best=(best["fillin"] / best_fill) if best else None,
        max_score_time_ratio=max((r["time_ratio"] for r in rows), default=None),
        total_score_time=sum(r["score_time"] for r in results),
        total_fit_time=sum(r["fit_time"] for r in results),
    )
    print(
        f"Spearman(score, -fill-in): order >= 1 {summary['spearman_order_ge_1']:.3f}, "
        f"all {summary['spearman_all']:.3f}\n"
        f"GridSearchCV(scoring=None) picks {summary['picked']}: fill-in "
        f"{summary['picked_fillin']:.3f} against the grid's best {best_fill:.3f} "
        f"({summary['picked_over_best']:.3f} x)\n"
        f"scoring / training CPU time: at most {summary['max_score_time_ratio']:.3f} "
        f"per configuration, {summary['total_score_time']:.1f} s / "
        f"{summary['total_fit_time']:.1f} s in all"
    )
    write_json(
        f"model_selection_hn{history_noise(args):g}",
        dict(
            args=vars(args),
            results=results,
            rows=rows,
            ar_baseline=ar_rows,
            summary=summary,
        ),
        args.output,
    )


if __name__ == "__main__":
    main()
