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

Every fitted model (pickle), its score and every (configuration, fold)
result are cached under ``benchmarks/results/model_selection_cache/``, keyed
on every parameter of the ConditionalRBM and of the CRBMImputer, defaults
included, and on the code they run (a model on the training and scoring
code, a result on the whole package's): a subset (``--sizes 10 50 --orders
1 --folds 0``) can run first and the full grid later reuses it, a changed
default or changed code fits or fills again, and
``--paper-fillin`` (the paper's single chain, ``n_particles=1,
offset_shrinkage=None, observation_gain=1``) fills the same models without refitting them.
``model_selection_diagnostics.py`` reads the cached models.  Run from the
repository root, with one BLAS thread::

    OPENBLAS_NUM_THREADS=1 python benchmarks/model_selection.py
    OPENBLAS_NUM_THREADS=1 python benchmarks/model_selection.py --sizes 10 50 --orders 0 1

Prints a table and writes ``benchmarks/results/model_selection_hn{noise}.json``
(``--history-noise``, default the estimator's; ``_paper_fillin`` appended
with ``--paper-fillin``).
"""

import argparse
import hashlib
import json
import pickle
import time

import numpy as np
import sklearn
from _common import DEFAULT_DATA_HOME, RESULTS, print_table, write_json
from _splits import PACKAGE, PACKAGE_CODE, TRAINING_CODE, code_digest
from scipy.stats import spearmanr
from sklearn.frozen import FrozenEstimator
from sklearn.model_selection import GridSearchCV
from sklearn.pipeline import Pipeline

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


def fillin(model, data, seed, imputer_params=None):
    """Mean squared error per erased entry (z-scores), left leg and upper body."""
    imputer = _imputer_for(model, data, seed, imputer_params or {})
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


def _imputer_for(model, data, seed, params):
    """CRBMImputer on the fitted model, without training it again."""
    imputer = CRBMImputer(FrozenEstimator(model), random_state=seed, **params)
    return imputer.fit(data["Z_train"], sequence_ids=data["train_ids"])


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


def option_or_default(args, name):
    """A ConditionalRBM parameter of the grid: the option if given, else its default."""
    value = getattr(args, name, None)
    return getattr(ConditionalRBM(), name) if value is None else value


def history_noise(args):
    return option_or_default(args, "history_noise")


def model_parameters(n_components, order, args):
    """The ConditionalRBM of a grid cell: the options given, defaults otherwise."""
    return dict(
        n_components=n_components,
        order=order,
        n_iter=args.n_iter,
        history_noise=history_noise(args),
        history_noise_fraction=option_or_default(args, "history_noise_fraction"),
        average_fraction=option_or_default(args, "average_fraction"),
        centering=getattr(args, "centering", False),
        random_state=args.seed,
    )


def imputer_parameters(args):
    """The fill-in procedure: CRBMImputer's defaults, or the paper's single chain."""
    paper = dict(n_particles=1, offset_shrinkage=None, observation_gain=1.0)
    return paper if args.paper_fillin else {}


# Parameters added after fits were cached, with the value those fits had
# (the estimator's record of them): left out of the key at that value, so
# the earlier fits stay valid.
_LATER_PARAMETERS = ConditionalRBM._added_parameters


def _digest(estimator, leave_out=()):
    """Eight hex digits naming every parameter of ``estimator``, defaults included.

    Part of every cache key, so that a changed default is a new key.
    """
    params = {
        k: v
        for k, v in estimator.get_params(deep=False).items()
        if k not in leave_out
        and not (k in _LATER_PARAMETERS and v == _LATER_PARAMETERS[k])
    }
    return hashlib.sha1(repr(sorted(params.items())).encode()).hexdigest()[:8]


# What a fit and the score cached with it run: changed code is a new key.
_MODEL_CODE = [*TRAINING_CODE, PACKAGE / "_likelihood.py"]


def model_key(n_components, order, fold, args):
    params = model_parameters(n_components, order, args)
    return (
        f"h{n_components}_o{order}_f{fold}_it{args.n_iter}_s{args.seed}"
        f"_hn{params['history_noise']:g}_{_digest(ConditionalRBM(**params))}"
        f"_c{code_digest(_MODEL_CODE)}"
    )


def fill_key(n_components, order, fold, args):
    """Cache key of a grid cell's fill-in and generation results.

    Names the model, the imputer's parameters and all of the package's code.
    """
    imputer = CRBMImputer(**imputer_parameters(args))
    digest = _digest(imputer, ("estimator", "random_state", "n_jobs"))
    return (
        f"{model_key(n_components, order, fold, args)}_fill{digest}"
        f"_c{code_digest(PACKAGE_CODE)}"
    )


def fitted_model(data, n_components, order, fold, args):
    """The fitted model of a grid cell and its score, cached (pickle and JSON)."""
    key = model_key(n_components, order, fold, args)
    model_path, result_path = CACHE / f"{key}.pkl", CACHE / f"{key}.fit.json"
    if model_path.exists() and result_path.exists() and not args.no_cache:
        return pickle.loads(model_path.read_bytes()), json.loads(
            result_path.read_text()
        )
    model = ConditionalRBM(**model_parameters(n_components, order, args))
    start = time.process_time()
    model.fit(data["Z_train"], sequence_ids=data["train_ids"])
    fit_time = time.process_time() - start
    start = time.process_time()
    score = model.score(data["Z_test"], sequence_ids=data["test_ids"])
    score_time = time.process_time() - start
    result = dict(score=score, fit_time=fit_time, score_time=score_time)
    CACHE.mkdir(parents=True, exist_ok=True)
    model_path.write_bytes(pickle.dumps(model))
    result_path.write_text(json.dumps(result, indent=1))
    return model, result


def run_one(data, n_components, order, fold, args):
    path = CACHE / f"{fill_key(n_components, order, fold, args)}.json"
    if path.exists() and not args.no_cache:
        return json.loads(path.read_text())
    model, fitted = fitted_model(data, n_components, order, fold, args)
    result = dict(
        n_components=n_components,
        order=order,
        fold=fold,
        **fitted,
        n_test_frames=len(data["Z_test"]),
        **fillin(model, data, args.seed, imputer_parameters(args)),
        generation_error=generation_error(model, data, args.seed),
    )
    path.write_text(json.dumps(result, indent=1))
    return result


def verify_search(args, results):
    """Run the real GridSearchCV(scoring=None) on the grid; compare with the cache.

    Same folds, same pipeline (preprocessing fitted on each training part),
    same ``random_state``: its per-fold test scores must be the cached ones.
    """
    cmu = load_cmu35(args.data_home, subset="all")
    fold_of_frame = trial_folds(np.asarray(cmu.motion))[cmu.sequence_ids]
    cv = [
        (np.flatnonzero(fold_of_frame != k), np.flatnonzero(fold_of_frame == k))
        for k in args.folds
    ]
    grid_cell = model_parameters(None, None, args)
    del grid_cell["n_components"], grid_cell["order"]  # the search's parameters
    model = ConditionalRBM(**grid_cell)
    pipeline = Pipeline(
        make_motion_preprocessor(cmu.skeleton).steps + [("crbm", model)]
    )
    grid = {"crbm__n_components": args.sizes, "crbm__order": args.orders}
    with sklearn.config_context(enable_metadata_routing=True):
        search = GridSearchCV(pipeline, grid, cv=cv, refit=False)
        search.fit(cmu.data, sequence_ids=cmu.sequence_ids)
    cached = {(r["n_components"], r["order"], r["fold"]): r["score"] for r in results}
    largest = 0.0
    for i, params in enumerate(search.cv_results_["params"]):
        for split, fold in enumerate(args.folds):
            key = (params["crbm__n_components"], params["crbm__order"], fold)
            got = search.cv_results_[f"split{split}_test_score"][i]
            largest = max(largest, abs(got - cached[key]))
    best = search.cv_results_["params"][search.best_index_]
    picked = f"{best['crbm__n_components']} x {best['crbm__order']}"
    print(
        f"GridSearchCV(scoring=None) run for real: picks {picked}; its per-fold "
        f"scores differ from the cached ones by at most {largest:.2e} nats/frame"
    )
    return dict(picked=picked, largest_difference=largest)


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
    parser.add_argument(
        "--history-noise-fraction",
        type=float,
        default=None,
        help="ConditionalRBM's history_noise_fraction (default: the estimator's)",
    )
    parser.add_argument(
        "--average-fraction",
        type=float,
        default=None,
        help="ConditionalRBM's average_fraction (default: the estimator's)",
    )
    parser.add_argument(
        "--centering", action="store_true", help="ConditionalRBM(centering=True)"
    )
    parser.add_argument(
        "--paper-fillin",
        action="store_true",
        help="fill in with the paper's single chain (n_particles=1, "
        "offset_shrinkage=None, observation_gain=1) instead of CRBMImputer's "
        "defaults",
    )
    parser.add_argument("--no-cache", action="store_true", help="refit everything")
    parser.add_argument(
        "--verify-search",
        action="store_true",
        help="also run GridSearchCV(scoring=None) on the grid (refits every model)",
    )
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
            f"history_noise {history_noise(args):g}, fill-in "
            f"{'paper (one chain)' if args.paper_fillin else 'CRBMImputer defaults'}"
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
    if args.verify_search:
        summary["search"] = verify_search(args, results)
    write_json(
        f"model_selection_hn{history_noise(args):g}"
        + ("_paper_fillin" if args.paper_fillin else ""),
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
