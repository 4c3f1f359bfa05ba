"""Why the score and the fill-in error of ``model_selection.py`` disagree.

Works on the models that ``model_selection.py`` fitted and cached (it must
have run first, for the same ``--history-noise``), and never refits them
unless asked (``--seeds``):

- ``breakdown``: the cached results per order, size and fold; Spearman
  correlations per fold and within every order;
- ``fillin``: ``--draws`` independent on-line fills (``CRBMImputer.sample``)
  of every held-out case, each draw's error and its spread, against the
  differences between configurations; also the error of their mean (what
  ``CRBMImputer(n_draws=k)`` returns);
- ``ais``: the score's estimate at the default annealing against a long
  run and its reverse (RAISE) companion, and exact enumeration where it is
  affordable;
- ``seeds``: the same grid retrained with other ``random_state`` values
  (cached like the main grid), for the spread of score and fill-in across
  training seeds;
- ``conditional``: ``log p(erased channels | observed ones, clean past)``,
  exactly as an RBM on the erased channels (or annealed);
- ``spread``: the model's distribution of a frame given its clean past, a
  mixture of unit-variance Gaussians: the error of its mean and the spread of
  its components, by Gibbs sampling;
- ``prediction``: the one-step prediction scorer beside the score;
- ``epochs``: score and fill-in error as training goes on (refits, with
  ``partial_fit``);
- ``training``: the grid retrained with the last ``--fraction`` of its
  epochs changed (``--variant``): ``clean-last`` on clean histories
  (``history_noise=0``), ``sampled-last`` / ``sampled`` (every epoch) with
  contrastive divergence whose reconstructions are drawn from ``p(v | h)``,
  unit-variance noise included, instead of set to their mean (the density
  the score measures); ``none`` is the main grid.  Score, fill-in error and
  the spread of ``spread``, per configuration.

``--paper-fillin`` uses the paper's single-chain fill-in, as in
``model_selection.py``.  The findings are in ``benchmarks/README.md``.

Run from the repository root, with one BLAS thread::

    OPENBLAS_NUM_THREADS=1 python benchmarks/model_selection_diagnostics.py breakdown
    OPENBLAS_NUM_THREADS=1 python benchmarks/model_selection_diagnostics.py fillin --draws 8

Results are written as JSON to ``benchmarks/results/``.
"""

import argparse
import contextlib
import copy
import json
import pickle
import time
from types import SimpleNamespace

import numpy as np
from _common import DEFAULT_DATA_HOME, RESULTS, print_table, write_json
from model_selection import (
    CACHE,
    _imputer_for,
    fill_key,
    fillin,
    fitted_model,
    imputer_parameters,
    load_fold,
    model_key,
    model_parameters,
    run_one,
)
from scipy.stats import spearmanr

import sklearn_crbm._crbm_math as crbm_math
from sklearn_crbm import ConditionalRBM
from sklearn_crbm._crbm_math import sequence_dynamic_biases
from sklearn_crbm._likelihood import FrameRBMs, log_partition
from sklearn_crbm.model_selection import erasure_mask, make_prediction_scorer
from sklearn_crbm.utils._sequences import check_sequence_ids

DIAGNOSTICS = RESULTS / "model_selection_diagnostics"


# Columns several tables share: the configuration and the fill-in errors.
CONFIG = ("config", "hidden x order", "s")
FILLIN_PARTS = [("leg", "fill-in leg", ".3f"), ("upper", "fill-in upper", ".3f")]
FILLIN = ("fillin", "fill-in", ".3f")


def _args_for(args, seed=None):
    return argparse.Namespace(
        **{
            **vars(args),
            "seed": args.seed if seed is None else seed,
            "no_cache": False,
        }
    )


def key_of(n_components, order, fold, args, seed=None):
    return model_key(n_components, order, fold, _args_for(args, seed))


def cached_model(n_components, order, fold, args, seed=None):
    path = CACHE / f"{key_of(n_components, order, fold, args, seed)}.pkl"
    return pickle.loads(path.read_bytes())


def cached_result(n_components, order, fold, args, seed=None):
    """The cached score and fill-in errors of a grid cell (``--paper-fillin`` or not)."""
    key = fill_key(n_components, order, fold, _args_for(args, seed))
    return json.loads((CACHE / f"{key}.json").read_text())


def fill(result):
    return 0.5 * (result["left leg"] + result["upper body"])


def spearman(x, y):
    return float(spearmanr(x, y).statistic) if len(x) >= 3 else float("nan")


# ------------------------------------------------------------------ breakdown


def breakdown(args):
    rows = []
    for fold in args.folds:
        for order in args.orders:
            for size in args.sizes:
                r = cached_result(size, order, fold, args)
                rows.append(
                    dict(
                        fold=fold,
                        config=f"{size} x {order}",
                        size=size,
                        order=order,
                        score=r["score"],
                        leg=r["left leg"],
                        upper=r["upper body"],
                        fillin=fill(r),
                        generation=r["generation_error"],
                    )
                )
    print_table(
        rows,
        [
            ("fold", "fold", "d"),
            CONFIG,
            ("score", "score", ".3f"),
            *FILLIN_PARTS,
            ("fillin", "fill-in mean", ".3f"),
            ("generation", "generation", ".3f"),
        ],
        title=f"per fold, history_noise {args.history_noise:g}",
    )
    correlations = []
    for fold in [*args.folds, "mean"]:
        chosen = rows if fold == "mean" else [r for r in rows if r["fold"] == fold]
        table = _mean_over_folds(chosen)
        for label, pick in [
            ("order >= 1", lambda r: r["order"] >= 1),
            ("all", lambda r: True),
            *[
                (f"order {o}", lambda r, o=o: r["order"] == o)
                for o in args.orders
                if o >= 1
            ],
        ]:
            sub = [r for r in table if pick(r)]
            for target in ("fillin", "leg", "upper"):
                correlations.append(
                    dict(
                        fold=str(fold),
                        models=label,
                        target=target,
                        rho=spearman(
                            [r["score"] for r in sub], [-r[target] for r in sub]
                        ),
                    )
                )
    print_table(
        correlations,
        [
            ("fold", "fold", "s"),
            ("models", "models", "s"),
            ("target", "against -", "s"),
            ("rho", "Spearman", ".3f"),
        ],
        title="Spearman(score, -error)",
    )
    return dict(rows=rows, correlations=correlations)


def _print_fold_means(rows, columns, title):
    """Print the rows averaged over folds (one per configuration); return them."""
    table = _mean_over_folds(rows)
    print_table(table, columns, title=title)
    return table


def _mean_over_folds(rows):
    out = []
    for config in dict.fromkeys(r["config"] for r in rows):
        runs = [r for r in rows if r["config"] == config]
        out.append(
            {
                k: (np.mean([r[k] for r in runs]) if k not in ("config", "fold") else v)
                for k, v in runs[0].items()
            }
        )
    return out


# -------------------------------------------------------------------- fill-in


def fillin_draws(args):
    """Per-draw fill-in errors of every configuration and fold."""
    DIAGNOSTICS.mkdir(parents=True, exist_ok=True)
    results = []
    for fold in args.folds:
        data = None
        for order in args.orders:
            for size in args.sizes:
                name = (
                    f"fill_{key_of(size, order, fold, args)}_d{args.draws}"
                    f"_r{args.fill_seed}{'_paper' if args.paper_fillin else ''}.json"
                )
                path = DIAGNOSTICS / name
                if path.exists():
                    results.append(json.loads(path.read_text()))
                    continue
                data = load_fold(args.data_home, fold) if data is None else data
                model = cached_model(size, order, fold, args)
                imputer = _imputer_for(
                    model, data, args.fill_seed, imputer_parameters(args)
                )
                result = dict(n_components=size, order=order, fold=fold)
                start = time.process_time()
                for part, bones in data["parts"].items():
                    mask = erasure_mask(
                        data["Z_test"],
                        bones=bones,
                        feature_names=data["names"],
                        sequence_ids=data["test_ids"],
                        strict=False,
                    )
                    X_missing = np.where(mask, np.nan, data["Z_test"])
                    draws = imputer.sample(
                        X_missing,
                        args.draws,
                        sequence_ids=data["test_ids"],
                        random_state=args.fill_seed,
                    )
                    errors = np.square(draws - data["Z_test"])[:, mask]
                    result[f"{part} draws"] = errors.mean(axis=1).tolist()
                    mean_fill = draws.mean(axis=0)
                    result[f"{part} mean fill"] = float(
                        np.mean(np.square(mean_fill - data["Z_test"])[mask])
                    )
                result["time"] = time.process_time() - start
                path.write_text(json.dumps(result, indent=1))
                results.append(result)
                print(
                    f"fold {fold} {size} x {order}: per draw "
                    f"{np.mean(result['left leg draws']):.3f} / "
                    f"{np.mean(result['upper body draws']):.3f}, sd "
                    f"{np.std(result['left leg draws'], ddof=1):.3f} / "
                    f"{np.std(result['upper body draws'], ddof=1):.3f}; mean fill "
                    f"{result['left leg mean fill']:.3f} / "
                    f"{result['upper body mean fill']:.3f} "
                    f"({result['time']:.0f} s)",
                    flush=True,
                )
    return summarise_fillin(args, results)


def summarise_fillin(args, results):
    """Noise of one draw against the spread of configurations; correlations."""
    rows = []
    for order in args.orders:
        for size in args.sizes:
            runs = [
                r for r in results if r["n_components"] == size and r["order"] == order
            ]
            draws = np.mean(
                [
                    0.5
                    * (np.array(r["left leg draws"]) + np.array(r["upper body draws"]))
                    for r in runs
                ],
                axis=0,
            )  # per draw, averaged over folds
            score = np.mean(
                [cached_result(size, order, r["fold"], args)["score"] for r in runs]
            )
            single = np.mean(
                [fill(cached_result(size, order, r["fold"], args)) for r in runs]
            )
            rows.append(
                dict(
                    config=f"{size} x {order}",
                    order=order,
                    score=score,
                    single=single,
                    per_draw=float(draws.mean()),
                    draw_sd=float(draws.std(ddof=1)),
                    mean_fill=float(
                        np.mean(
                            [
                                0.5
                                * (r["left leg mean fill"] + r["upper body mean fill"])
                                for r in runs
                            ]
                        )
                    ),
                    draws=draws.tolist(),
                )
            )
    print_table(
        rows,
        [
            CONFIG,
            ("score", "score", ".3f"),
            ("single", "fill-in, benchmark's draw", ".3f"),
            ("per_draw", f"mean of {args.draws} draws' errors", ".3f"),
            ("draw_sd", "sd of one draw's error", ".3f"),
            ("mean_fill", f"error of the {args.draws}-draw mean fill", ".3f"),
        ],
        title=f"fill-in noise, folds {args.folds}, history_noise {args.history_noise:g}",
    )
    summary = {}
    for label, minimum in (("order >= 1", 1), ("all", 0)):
        sub = [r for r in rows if r["order"] >= minimum]
        scores = [r["score"] for r in sub]
        summary[label] = dict(
            single=spearman(scores, [-r["single"] for r in sub]),
            per_draw_mean=spearman(scores, [-r["per_draw"] for r in sub]),
            mean_fill=spearman(scores, [-r["mean_fill"] for r in sub]),
            one_draw=[
                spearman(scores, [-r["draws"][d] for r in sub])
                for d in range(args.draws)
            ],
        )
        s = summary[label]
        print(
            f"Spearman(score, -fill-in), {label}: benchmark's single draw "
            f"{s['single']:.3f}; mean of {args.draws} draws' errors "
            f"{s['per_draw_mean']:.3f}; {args.draws}-draw mean fill "
            f"{s['mean_fill']:.3f}; one draw each: "
            + ", ".join(f"{v:.2f}" for v in s["one_draw"])
        )
    return dict(rows=rows, summary=summary)


# ------------------------------------------------------------------------ AIS


def ais_accuracy(args):
    rows = []
    for fold in args.folds:
        data = load_fold(args.data_home, fold)
        frames = data["Z_test"]
        for order in args.orders:
            for size in args.sizes:
                model = cached_model(size, order, fold, args)
                row = dict(fold=fold, config=f"{size} x {order}", order=order)
                start = time.process_time()
                row["score"] = model.score(frames, sequence_ids=data["test_ids"])
                row["score_time"] = time.process_time() - start
                valid = _valid(model, data)
                long = copy.deepcopy(model).set_params(
                    ais_steps=args.long_steps, ais_chains=args.long_chains
                )
                start = time.process_time()
                est = long.estimate_log_likelihood(
                    frames, sequence_ids=data["test_ids"], method="ais", reverse=True
                )
                row["long_time"] = time.process_time() - start
                row["long"] = float(est.log_likelihood[valid].mean())
                row["raise"] = float(est.lower[valid].mean())
                row["long_se"] = float(
                    np.sqrt(np.sum(est.standard_error[valid] ** 2)) / valid.sum()
                )
                default = model.estimate_log_likelihood(
                    frames, sequence_ids=data["test_ids"], method="ais", reverse=True
                )
                row["default_raise"] = float(default.lower[valid].mean())
                row["exact"] = float("nan")
                if size <= args.exact_max:
                    exact = model.estimate_log_likelihood(
                        frames, sequence_ids=data["test_ids"], method="exact"
                    )
                    row["exact"] = float(exact.log_likelihood[valid].mean())
                rows.append(row)
                print(
                    f"fold {fold} {size} x {order}: score {row['score']:.3f} "
                    f"[RAISE {row['default_raise']:.3f}], {args.long_steps} x "
                    f"{args.long_chains}: {row['long']:.3f} [RAISE {row['raise']:.3f}]"
                    f", exact {row['exact']:.3f} ({row['long_time']:.0f} s)",
                    flush=True,
                )
    print_table(
        rows,
        [
            ("fold", "fold", "d"),
            CONFIG,
            ("score", "score (default AIS)", ".3f"),
            ("default_raise", "its RAISE", ".3f"),
            ("long", f"AIS {args.long_steps} x {args.long_chains}", ".3f"),
            ("raise", "its RAISE", ".3f"),
            ("exact", "exact", ".3f"),
        ],
        title=f"score estimates, history_noise {args.history_noise:g}",
    )
    return dict(rows=rows)


def _valid(model, data):
    ids = data["test_ids"]
    valid = np.zeros(len(ids), dtype=bool)
    for i in np.unique(ids):
        rows = np.flatnonzero(ids == i)
        valid[rows[model.history_length :]] = True
    return valid


# ---------------------------------------------------------------------- seeds


def other_seeds(args):
    """The grid retrained with other seeds, through model_selection's cache."""
    results = []
    for fold in args.folds:
        data = load_fold(args.data_home, fold)
        for seed in args.seeds:
            run_args = _args_for(args, seed)
            for order in args.orders:
                for size in args.sizes:
                    r = run_one(data, size, order, fold, run_args)
                    results.append({**r, "seed": seed})
                    print(
                        f"fold {fold} seed {seed} {size} x {order}: score "
                        f"{r['score']:.3f}, fill-in {fill(r):.3f}",
                        flush=True,
                    )
    return dict(results=results)


# --------------------------------------------------------------------- epochs


def epochs(args):
    """Held-out score and fill-in error as training goes on (``partial_fit``)."""
    rows = []
    checkpoints = sorted(set(args.checkpoints))
    for fold in args.folds:
        data = load_fold(args.data_home, fold)
        for order in args.orders:
            for size in args.sizes:
                model = ConditionalRBM(
                    **dict(model_parameters(size, order, args), n_iter=checkpoints[0])
                )
                model.fit(data["Z_train"], sequence_ids=data["train_ids"])
                for epoch in checkpoints:
                    while model.n_iter_ < epoch:
                        model.partial_fit(
                            data["Z_train"], sequence_ids=data["train_ids"]
                        )
                    score = model.score(data["Z_test"], sequence_ids=data["test_ids"])
                    errors = fillin(model, data, args.seed, imputer_parameters(args))
                    row = dict(
                        fold=fold,
                        config=f"{size} x {order}",
                        n_components=size,
                        order=order,
                        epochs=epoch,
                        score=score,
                        leg=errors["left leg"],
                        upper=errors["upper body"],
                        fillin=0.5 * (errors["left leg"] + errors["upper body"]),
                    )
                    rows.append(row)
                    print(
                        f"fold {fold} {size} x {order}, {epoch} epochs: score "
                        f"{score:.3f}, fill-in {row['leg']:.3f} / {row['upper']:.3f}",
                        flush=True,
                    )
    for epoch in checkpoints:
        sub = [r for r in rows if r["epochs"] == epoch and r["order"] >= 1]
        table = _mean_over_folds(
            [{k: v for k, v in r.items() if k != "epochs"} for r in sub]
        )
        print(
            f"{epoch} epochs: Spearman(score, -fill-in), order >= 1: "
            f"{spearman([r['score'] for r in table], [-r['fillin'] for r in table]):.3f}"
        )
    return dict(rows=rows)


# ----------------------------------------------------------------- conditional


def conditional(args):
    """Log-likelihood of the erased channels given the observed ones and the past.

    With the channels ``O`` of frame ``t`` observed, the erased ones ``M``
    given ``O`` and the (clean) past are an RBM on ``M`` whose hidden bias
    is ``b_hat + W_O (x_O / s_O)``: ``log p(x_M | x_O, past)`` is its
    negative free energy minus its log partition function, exact or
    annealed like the score.  ``log p(x_O | past)`` is the rest of the
    joint ``log p(x_t | past)``.  Frames from half-way through every
    held-out trial (the erased ones), with their true past.
    """
    rows = []
    for fold in args.folds:
        data = load_fold(args.data_home, fold)
        X = data["Z_test"].astype(np.float64)
        sequences = check_sequence_ids(data["test_ids"], len(X))
        for order in args.orders:
            for size in args.sizes:
                model = cached_model(size, order, fold, args)
                params = model._parameters
                row = dict(fold=fold, config=f"{size} x {order}", order=order)
                for part, bones in data["parts"].items():
                    mask = erasure_mask(
                        X,
                        bones=bones,
                        feature_names=data["names"],
                        sequence_ids=data["test_ids"],
                        strict=False,
                    )
                    frames = np.flatnonzero(mask.any(axis=1))
                    missing = mask[frames[0]]
                    cond, joint = _conditional_log_likelihood(
                        params,
                        model._visible_scale(),
                        X,
                        sequences,
                        frames,
                        missing,
                        args,
                    )
                    row[f"{part} cond"] = float(cond.mean())
                    row[f"{part} joint"] = float(joint.mean())
                    row[f"{part} observed"] = float((joint - cond).mean())
                r = cached_result(size, order, fold, args)
                row.update(leg=r["left leg"], upper=r["upper body"], fillin=fill(r))
                rows.append(row)
                print(
                    f"fold {fold} {size} x {order}: log p(leg | rest, past) "
                    f"{row['left leg cond']:.3f}, log p(upper | rest, past) "
                    f"{row['upper body cond']:.3f}, joint {row['left leg joint']:.3f}",
                    flush=True,
                )
    table = _print_fold_means(
        rows,
        [
            CONFIG,
            ("left leg joint", "log p(x_t | past)", ".3f"),
            ("left leg cond", "log p(leg | rest, past)", ".3f"),
            ("upper body cond", "log p(upper | rest, past)", ".3f"),
            *FILLIN_PARTS,
        ],
        title="held-out log-likelihoods of the erased frames (nats/frame)",
    )
    for label, x, y in [
        ("joint vs -fill-in", "left leg joint", "fillin"),
        ("leg cond vs -leg fill-in", "left leg cond", "leg"),
        ("upper cond vs -upper fill-in", "upper body cond", "upper"),
        ("leg obs vs -leg fill-in", "left leg observed", "leg"),
    ]:
        print(
            f"Spearman {label}: "
            f"{spearman([r[x] for r in table], [-r[y] for r in table]):.3f}"
        )
    table_sum = [
        dict(r, both=0.5 * (r["left leg cond"] + r["upper body cond"])) for r in table
    ]
    print(
        "Spearman mean conditional vs -fill-in: "
        f"{spearman([r['both'] for r in table_sum], [-r['fillin'] for r in table_sum]):.3f}"
    )
    return dict(rows=rows)


def _conditional_log_likelihood(params, scale, X, sequences, frames, missing, args):
    scale = np.ones(X.shape[1]) if scale is None else np.asarray(scale, np.float64)
    weights = params.weights.astype(np.float64)
    sub = SimpleNamespace(weights=weights[:, missing], visible_type=params.visible_type)
    rng = np.random.default_rng(args.seed)
    cond, joint = [], []
    for rows, visible_bias, hidden_bias in sequence_dynamic_biases(
        params, X, sequences, frames
    ):
        x = X[rows]
        full = FrameRBMs(params, visible_bias, hidden_bias, scale)
        log_z, _, _ = log_partition(
            full,
            method="auto",
            n_steps=args.cond_steps,
            n_chains=args.cond_chains,
            rng=rng,
        )
        joint.append(full.negative_free_energy(x) - log_z)
        hidden = (
            hidden_bias + (x[:, ~missing] / scale[~missing]) @ weights[:, ~missing].T
        )
        rbms = FrameRBMs(sub, visible_bias[:, missing], hidden, scale[missing])
        log_z, _, _ = log_partition(
            rbms,
            method="auto",
            n_steps=args.cond_steps,
            n_chains=args.cond_chains,
            rng=rng,
        )
        cond.append(rbms.negative_free_energy(x[:, missing]) - log_z)
    return np.concatenate(cond), np.concatenate(joint)


# ---------------------------------------------------------------------- spread


def spread(args):
    """The model's distribution of ``x_t`` given the clean past: its mean and spread.

    Given its past, a frame of a CRBM with unit-variance visibles is a
    mixture over hidden configurations ``h`` of ``N(mu(h), I)``, ``mu(h) =
    c_hat + W.T h``.  A block-Gibbs chain per held-out frame (started at the
    frame, ``--burn-in`` steps, then ``--gibbs`` steps collected) gives the
    mixture's mean ``m`` and the spread of its components ``E||mu(h) -
    m||^2``; with the squared error ``||x - m||^2`` of the mean, both per
    frame, summed over channels.  Frames from half-way through every held-out
    trial (the erased ones), with their true past.
    """
    rows = []
    for fold in args.folds:
        data = load_fold(args.data_home, fold)
        X, sequences, frames = _erased_frames(data)
        for order in args.orders:
            for size in args.sizes:
                model = cached_model(size, order, fold, args)
                error, mix, ar = _mixture_moments(
                    model._parameters, X, sequences, frames, args
                )
                r = cached_result(size, order, fold, args)
                row = dict(
                    fold=fold,
                    config=f"{size} x {order}",
                    order=order,
                    score=r["score"],
                    error=error,
                    spread=mix,
                    ar_error=ar,
                    leg=r["left leg"],
                    upper=r["upper body"],
                    fillin=fill(r),
                )
                rows.append(row)
                print(
                    f"fold {fold} {size} x {order}: score {row['score']:.3f}, "
                    f"||x - m||^2 {error:.2f}, spread {mix:.2f}, ||x - c_hat||^2 {ar:.2f}",
                    flush=True,
                )
    table = _print_fold_means(
        rows,
        [
            CONFIG,
            ("score", "score", ".3f"),
            ("error", "||x - E[x|past]||^2", ".2f"),
            ("spread", "E||mu(h) - E[x|past]||^2", ".2f"),
            ("ar_error", "||x - c_hat||^2", ".2f"),
            FILLIN,
        ],
        title="the model's frame given the clean past (sums over 62 channels)",
    )
    for name in ("error", "spread", "ar_error"):
        print(
            f"Spearman(score, -{name}) {spearman([r['score'] for r in table], [-r[name] for r in table]):.3f}; "
            f"Spearman(-{name}, -fill-in) "
            f"{spearman([-r[name] for r in table], [-r['fillin'] for r in table]):.3f}"
        )
    return dict(rows=rows)


def _mixture_moments(params, X, sequences, frames, args):
    rng = np.random.default_rng(args.seed)
    weights = params.weights.astype(np.float64)
    error, mix, ar = [], [], []
    for rows, visible_bias, hidden_bias in sequence_dynamic_biases(
        params, X, sequences, frames
    ):
        visible = X[rows].copy()
        total = np.zeros_like(visible)
        square = np.zeros(len(rows))
        for step in range(args.burn_in + args.gibbs):
            hidden = rng.random(hidden_bias.shape) < 1 / (
                1 + np.exp(-(hidden_bias + visible @ weights.T))
            )
            mean = visible_bias + hidden @ weights
            visible = mean + rng.standard_normal(mean.shape)
            if step >= args.burn_in:
                total += mean
                square += np.einsum("ij,ij->i", mean, mean)
        m = total / args.gibbs
        mix.append(square / args.gibbs - np.einsum("ij,ij->i", m, m))
        error.append(np.sum((X[rows] - m) ** 2, axis=1))
        ar.append(np.sum((X[rows] - visible_bias) ** 2, axis=1))
    return (float(np.concatenate(v).mean()) for v in (error, mix, ar))


def _erased_frames(data):
    """Frames from half-way through every held-out trial (the erased ones)."""
    X = data["Z_test"].astype(np.float64)
    mask = erasure_mask(
        X,
        bones=data["parts"]["left leg"],
        feature_names=data["names"],
        sequence_ids=data["test_ids"],
        strict=False,
    )
    return (
        X,
        check_sequence_ids(data["test_ids"], len(X)),
        np.flatnonzero(mask.any(axis=1)),
    )


# -------------------------------------------------------------------- training


@contextlib.contextmanager
def sampled_reconstructions(seed):
    """Contrastive divergence with reconstructions drawn from ``p(v | h)``.

    The package's CD sets every reconstruction to its mean (paper, Section
    2.2), so training never sees the unit-variance noise of the Gaussian
    visibles that the likelihood integrates over.  Inside this context the
    reconstructions of ``cd_gradients`` get that noise (a diagnostic: the
    visible means it patches are those of training only).
    """
    mean_of = crbm_math.visible_means
    rng = np.random.default_rng(seed)

    def drawn(params, hidden, visible_bias, out=None):
        assert not params.learned_variance and params.visible_type != "binary"
        mean = mean_of(params, hidden, visible_bias, out=out)
        mean += rng.standard_normal(mean.shape)
        return mean

    crbm_math.visible_means = drawn
    try:
        yield
    finally:
        crbm_math.visible_means = mean_of


def _variant_model(data, size, order, fold, args):
    """The model of ``_train_variant``, pickled in the diagnostics' cache."""
    path = (
        DIAGNOSTICS
        / "training_cache"
        / f"{args.variant}_fr{args.fraction:g}_{model_key(size, order, fold, args)}.pkl"
    )
    if path.exists():
        return pickle.loads(path.read_bytes())
    model = _train_variant(data, size, order, fold, args)
    path.write_bytes(pickle.dumps(model))
    return model


def _train_variant(data, size, order, fold, args):
    """A grid cell trained with the last ``--fraction`` of its epochs changed."""
    if args.variant == "none":
        return fitted_model(data, size, order, fold, _args_for(args))[0]
    n_last = (
        args.n_iter if args.variant == "sampled" else round(args.fraction * args.n_iter)
    )
    model = ConditionalRBM(
        **dict(model_parameters(size, order, args), n_iter=args.n_iter - n_last)
    )
    X, ids = data["Z_train"], data["train_ids"]
    changed = (
        sampled_reconstructions(args.seed + 1000 * fold + size + order)
        if args.variant.startswith("sampled")
        else contextlib.nullcontext()
    )
    if n_last == args.n_iter:
        with changed:
            return model.set_params(n_iter=args.n_iter).fit(X, sequence_ids=ids)
    model.fit(X, sequence_ids=ids)
    if args.variant == "clean-last":
        model.set_params(history_noise=0.0)
    with changed:
        while model.n_iter_ < args.n_iter:
            model.partial_fit(X, sequence_ids=ids)
    return model


def training(args):
    """Score, fill-in error and spread after changing the end of training."""
    cache = DIAGNOSTICS / "training_cache"
    cache.mkdir(parents=True, exist_ok=True)
    rows = []
    for fold in args.folds:
        data = load_fold(args.data_home, fold)
        X, sequences, frames = _erased_frames(data)
        for order in args.orders:
            for size in args.sizes:
                key = (
                    f"{args.variant}_fr{args.fraction:g}_"
                    f"{fill_key(size, order, fold, args)}"
                )
                path = cache / f"{key}.json"
                if path.exists():
                    row = json.loads(path.read_text())
                else:
                    model = _variant_model(data, size, order, fold, args)
                    errors = fillin(model, data, args.seed, imputer_parameters(args))
                    error, mix, _ = _mixture_moments(
                        model._parameters, X, sequences, frames, args
                    )
                    row = dict(
                        fold=fold,
                        config=f"{size} x {order}",
                        order=order,
                        score=model.score(
                            data["Z_test"], sequence_ids=data["test_ids"]
                        ),
                        error=error,
                        spread=mix,
                        leg=errors["left leg"],
                        upper=errors["upper body"],
                        fillin=0.5 * (errors["left leg"] + errors["upper body"]),
                    )
                    path.write_text(json.dumps(row))
                rows.append(row)
                print(
                    f"{args.variant} fold {fold} {size} x {order}: score "
                    f"{row['score']:.3f}, spread {row['spread']:.2f}, fill-in "
                    f"{row['leg']:.3f} / {row['upper']:.3f}",
                    flush=True,
                )
    table = _print_fold_means(
        rows,
        [
            CONFIG,
            ("score", "score", ".3f"),
            ("error", "||x - E[x|past]||^2", ".2f"),
            ("spread", "E||mu(h) - E[x|past]||^2", ".2f"),
            *FILLIN_PARTS,
            FILLIN,
        ],
        title=f"training variant {args.variant!r}, last {args.fraction:g} of "
        f"{args.n_iter} epochs, history_noise {args.history_noise:g}",
    )
    sub = [r for r in table if r["order"] >= 1]
    summary = dict(
        spearman_order_ge_1=spearman(
            [r["score"] for r in sub], [-r["fillin"] for r in sub]
        ),
        mean_fillin=float(np.mean([r["fillin"] for r in sub])),
        best_fillin=float(min(r["fillin"] for r in sub)),
    )
    print(
        f"order >= 1: Spearman(score, -fill-in) {summary['spearman_order_ge_1']:.3f}; "
        f"fill-in mean {summary['mean_fillin']:.3f}, best {summary['best_fillin']:.3f}"
    )
    return dict(rows=rows, summary=summary)


# ------------------------------------------------------------------ prediction


def prediction(args):
    """The one-step prediction scorer beside the score, against the fill-in error."""
    scorer = make_prediction_scorer()
    rows = []
    for fold in args.folds:
        data = load_fold(args.data_home, fold)
        for order in args.orders:
            for size in args.sizes:
                model = cached_model(size, order, fold, args)
                r = cached_result(size, order, fold, args)
                rows.append(
                    dict(
                        fold=fold,
                        config=f"{size} x {order}",
                        order=order,
                        score=r["score"],
                        prediction=scorer(
                            model, data["Z_test"], sequence_ids=data["test_ids"]
                        ),
                        fillin=fill(r),
                    )
                )
    table = _print_fold_means(
        rows,
        [
            CONFIG,
            ("score", "score", ".3f"),
            ("prediction", "-one-step MSE", ".4f"),
            FILLIN,
        ],
        title=f"one-step prediction, history_noise {args.history_noise:g}",
    )
    for label, minimum in (("order >= 1", 1), ("all", 0)):
        sub = [r for r in table if r["order"] >= minimum]
        print(
            f"{label}: Spearman(score, -fill-in) "
            f"{spearman([r['score'] for r in sub], [-r['fillin'] for r in sub]):.3f}, "
            f"Spearman(-one-step MSE, -fill-in) "
            f"{spearman([r['prediction'] for r in sub], [-r['fillin'] for r in sub]):.3f}"
        )
    return dict(rows=rows)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "what",
        choices=[
            "breakdown",
            "fillin",
            "ais",
            "seeds",
            "epochs",
            "conditional",
            "spread",
            "prediction",
            "training",
        ],
    )
    parser.add_argument("--data-home", default=str(DEFAULT_DATA_HOME))
    parser.add_argument("--sizes", type=int, nargs="+", default=[10, 50, 200, 400])
    parser.add_argument("--orders", type=int, nargs="+", default=[0, 1, 3, 6])
    parser.add_argument("--folds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--n-iter", type=int, default=500)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--history-noise", type=float, default=0.8)
    # the measurements of benchmarks/README.md: noise on every channel, the
    # last epoch's parameters
    parser.add_argument("--history-noise-fraction", type=float, default=1.0)
    parser.add_argument("--average-fraction", type=float, default=0.0)
    parser.add_argument("--paper-fillin", action="store_true")
    parser.add_argument("--draws", type=int, default=8)
    parser.add_argument("--fill-seed", type=int, default=1)
    parser.add_argument("--long-steps", type=int, default=500)
    parser.add_argument("--long-chains", type=int, default=16)
    parser.add_argument("--burn-in", type=int, default=100)
    parser.add_argument("--gibbs", type=int, default=200)
    parser.add_argument("--cond-steps", type=int, default=100)
    parser.add_argument("--cond-chains", type=int, default=4)
    parser.add_argument("--exact-max", type=int, default=20)
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2])
    parser.add_argument(
        "--variant",
        choices=["none", "clean-last", "sampled-last", "sampled"],
        default="sampled-last",
    )
    parser.add_argument("--fraction", type=float, default=0.2)
    parser.add_argument(
        "--checkpoints", type=int, nargs="+", default=[100, 250, 500, 1000, 2000]
    )
    args = parser.parse_args(argv)
    run = dict(
        breakdown=breakdown,
        fillin=fillin_draws,
        ais=ais_accuracy,
        seeds=other_seeds,
        epochs=epochs,
        conditional=conditional,
        spread=spread,
        prediction=prediction,
        training=training,
    )[args.what]
    out = run(args)
    variant = f"_{args.variant}_fr{args.fraction:g}" if args.what == "training" else ""
    write_json(
        f"model_selection_{args.what}{variant}_hn{args.history_noise:g}"
        + ("_paper_fillin" if args.paper_fillin else ""),
        dict(args=vars(args), **out),
        None,
    )


if __name__ == "__main__":
    main()
