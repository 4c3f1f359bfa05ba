"""Filling in missing mocap channels: the paper's experiment (§4.4) on CMU 35.

Protocol (Taylor, Hinton & Roweis 2006, §4.4):

- train on the 31 training trials of CMU subject 35 (23 walks and jogs minus
  the two test trials); preprocessing (exponential maps, body-centred root,
  z-scores) fitted on the training trials only;
- a 200-hidden-unit CRBM of order 3;
- test on walk 35_29 and jog 35_18; erase (a) the left leg (lfemur, ltibia,
  lfoot, ltoes) and (b) the upper body (lowerback and every bone above it)
  from half-way through each sequence to its end;
- fill in with CRBMImputer: single draws repeated ``--n-repeats`` times with
  the error averaged over them (what the paper reports), and the average of
  ``--n-draws`` draws (a posterior-mean fill); with NearestNeighborImputer
  (the paper's baseline), scikit-learn's KNNImputer and IterativeImputer, and
  per-channel linear interpolation (holding the last observed value, since
  the gap runs to the end of the sequence);
- repeat the CRBM for every training seed.

Errors: the paper's (per-frame mean squared error over the erased channels,
summed over the erased frames, in z-scored units) and the RMS error in
degrees of the erased bones' raw Euler channels after the inverse transform.
The paper reports, for the walk: left leg 8.78 (nearest neighbour 11.68),
upper body 20.52 (nearest neighbour 22.20).

Variants (``--variants``), each trained once per seed and cached:

``original``
    ``ConditionalRBM.paper_schedule()``, the original code's schedule
    (REFERENCE.md): CD-1, learning rate 1e-3 for all weights, momentum 0.9
    after 5 epochs, weight decay 2e-4, shuffled minibatches of 100 frames,
    clean histories, ``--n-iter`` epochs (the paper: 4000); the paper's
    single-chain fill-in.
``particles``
    The same models; fill-in with 10 particles per draw, resampled before
    every frame by how well each particle's past predicts the frame's
    observed channels (CRBMImputer's ``n_particles``).  Inference-only fix.
``noisy``
    Trained with noisy histories (ConditionalRBM's ``history_noise=0.4``:
    the past frames feeding the directed connections get N(0, 0.4^2) noise
    during training, so the model learns to pull a perturbed past back to
    the data); single-chain fill-in.  Training-only fix.
``robust``
    Both: noisy-history training and 10 particles.

Run from the repository root, e.g.::

    python benchmarks/paper_fillin.py                      # the full protocol
    python benchmarks/paper_fillin.py --seeds 0 --n-iter 200 --n-repeats 10

A full run trains ten models (two training schedules, five seeds) of 4000
epochs, several minutes each on one core (``--n-jobs`` trains seeds in
parallel); they are cached with joblib in ``--cache-dir``, so re-running the
fill-in (or another fill-in variant) does not retrain, and the fill-ins then
take a few minutes.  The output also shows, for the upper body, the error
when every erased frame is filled from the *true* past frames instead of the
model's own earlier fills: the gap between the two is the drift.  Prints a table and
writes JSON to ``benchmarks/results/paper_fillin.json``.
"""

import os

# One BLAS thread per process: the matrices are small, and threads only
# fight on a shared machine.  Must be set before numpy is imported.
for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import platform  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import joblib  # noqa: E402
import numpy as np  # noqa: E402
import sklearn  # noqa: E402
from sklearn.experimental import enable_iterative_imputer  # noqa: E402, F401
from sklearn.impute import IterativeImputer, KNNImputer  # noqa: E402

from sklearn_crbm import ConditionalRBM  # noqa: E402
from sklearn_crbm.datasets import load_cmu35  # noqa: E402
from sklearn_crbm.impute import CRBMImputer, NearestNeighborImputer  # noqa: E402
from sklearn_crbm.metrics import fillin_error  # noqa: E402
from sklearn_crbm.model_selection import make_fillin_cases  # noqa: E402
from sklearn_crbm.preprocessing import make_motion_preprocessor  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
PAPER = {("walk", "leg"): (8.78, 11.68), ("walk", "upper"): (20.52, 22.20)}
PARTS = {"left leg": "leg", "upper body": "upper"}  # short names in the JSON

# The paper's training schedule, as ConditionalRBM names it (every parameter
# spelled out, so later changes of the defaults do not change it).
ORIGINAL_MODEL = {
    name: value
    for name, value in ConditionalRBM.paper_schedule().get_params().items()
    if name not in ("n_iter", "random_state", "verbose")
}
# The training-side fix: noisy histories (ConditionalRBM's ``history_noise``).
NOISY_MODEL = dict(ORIGINAL_MODEL, history_noise=0.4)
# The paper's on-line procedure (CRBMImputer's offset correction off).
PAPER_FILLIN = dict(n_gibbs=30, offset_shrinkage=None, observation_gain=1.0)
VARIANTS = {
    "original": dict(model=ORIGINAL_MODEL, imputer=dict(PAPER_FILLIN, n_particles=1)),
    "particles": dict(model=ORIGINAL_MODEL, imputer=dict(PAPER_FILLIN, n_particles=10)),
    "noisy": dict(model=NOISY_MODEL, imputer=dict(PAPER_FILLIN, n_particles=1)),
    "robust": dict(model=NOISY_MODEL, imputer=dict(PAPER_FILLIN, n_particles=10)),
    # ConditionalRBM's default noise level before history_noise_fraction
    # (on every channel, as paper_schedule's fraction of 1 keeps it)
    "noisy0.8": dict(
        model=dict(ORIGINAL_MODEL, history_noise=0.8),
        imputer=dict(PAPER_FILLIN, n_particles=1),
    ),
}


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data-home", default=str(REPO.parent / "shared" / "data"))
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3, 4])
    parser.add_argument("--n-iter", type=int, default=4000, help="training epochs")
    parser.add_argument("--n-repeats", type=int, default=100, help="single draws")
    parser.add_argument("--n-draws", type=int, default=100, help="draws averaged")
    parser.add_argument(
        "--variants", nargs="+", default=list(VARIANTS), choices=VARIANTS
    )
    parser.add_argument("--dtype", default="float32", choices=["float32", "float64"])
    parser.add_argument(
        "--n-jobs", type=int, default=1, help="seeds trained in parallel"
    )
    parser.add_argument(
        "--cache-dir",
        default=str(Path(tempfile.gettempdir()) / "sklearn_crbm_paper_fillin"),
        help="joblib cache of trained models ('' disables it)",
    )
    parser.add_argument(
        "--output", default=str(REPO / "benchmarks" / "results" / "paper_fillin.json")
    )
    return parser.parse_args()


def load(data_home):
    """Preprocessed training data and the paper's four fill-in cases."""
    train = load_cmu35(data_home, subset="train")
    test = load_cmu35(data_home, subset="test")
    with sklearn.config_context(enable_metadata_routing=True):
        # the paper's encoding: joint rotations from the rest pose, Taylor's roll
        pre = make_motion_preprocessor(train.skeleton, reference="rest", roll="taylor")
        Z_train = pre.fit_transform(train.data, sequence_ids=train.sequence_ids)
    cases = {
        (motion, PARTS[part]): case
        for (motion, part), case in make_fillin_cases(test, pre).items()
    }
    return Z_train, train.sequence_ids, cases


def linear_interpolation(X_missing):
    """Per-channel linear interpolation; the last observed value past the end."""
    X = X_missing.copy()
    t = np.arange(len(X))
    for j in range(X.shape[1]):
        missing = np.isnan(X[:, j])
        if missing.any():
            X[missing, j] = np.interp(t[missing], t[~missing], X[~missing, j])
    return X


def baselines(Z_train, cases):
    methods = {
        "nearest neighbour": NearestNeighborImputer(),
        "KNNImputer(5)": KNNImputer(n_neighbors=5),
        "IterativeImputer": IterativeImputer(max_iter=10, random_state=0),
    }
    results = {}
    for name, imputer in methods.items():
        imputer.fit(Z_train)
        for key, case in cases.items():
            results[(name, *key)] = case.errors(imputer.transform(case.X_missing))
    for key, case in cases.items():
        results[("linear interpolation", *key)] = case.errors(
            linear_interpolation(case.X_missing)
        )
    return results


# fmt: off
# (joblib keys its cache on this function's source text: keep it unchanged.)
def _train_imputer(model_params, seed, n_iter, Z_train, sequence_ids):
    """A CRBMImputer with its model trained (cached: fill-in settings do not retrain)."""
    model = ConditionalRBM(**model_params, n_iter=n_iter, random_state=seed)
    start = time.perf_counter()
    imputer = CRBMImputer(model, random_state=seed).fit(Z_train, sequence_ids=sequence_ids)
    return imputer, time.perf_counter() - start
# fmt: on


def _with_new_parameters(imputer):
    """Give a cached imputer (and its model) the parameters added since it was saved."""
    for obj in (imputer, imputer.estimator, imputer.estimator_):
        for name, value in type(obj)().get_params(deep=False).items():
            if not hasattr(obj, name):
                setattr(obj, name, value)
    return imputer


def crbm_results(imputer, imputer_params, seed, cases, n_repeats, n_draws):
    """Single draws (mean error over them) and the average of ``n_draws`` draws.

    ``transform`` with ``n_draws=k`` returns the mean of ``sample(k)`` drawn
    with the same seed, so both numbers come from one set of draws.
    """
    # Only fill-in parameters change: the fitted model stays.
    imputer = imputer.set_params(**imputer_params, n_draws=1, random_state=seed)
    out = {}
    for key, case in cases.items():
        draws = imputer.sample(
            case.X_missing, n_samples=max(n_repeats, n_draws), random_state=seed
        )
        single = np.array([case.errors(filled) for filled in draws[:n_repeats]])
        averaged = case.errors(draws[:n_draws].mean(axis=0))
        out[key] = dict(
            single=single[:, 0].mean(),
            single_std=single[:, 0].std(),
            single_min=single[:, 0].min(),
            single_max=single[:, 0].max(),
            single_degrees=single[:, 1].mean(),
            averaged=averaged[0],
            averaged_degrees=averaged[1],
            true_past=true_past_error(imputer, case, n_repeats, seed),
        )
    return out


def true_past_error(imputer, case, n_draws, seed):
    """The error when every erased frame is filled from the *true* past frames.

    Each erased frame becomes its own short sequence: its ``n_lags`` true past
    frames (complete, so copied as they are) followed by the frame with its
    channels erased.  Compared with the on-line error, where the past holds
    the model's own earlier fills, it measures how much of the error comes
    from fills feeding back through the directed connections (the drift).
    """
    n_lags = imputer.estimator_.history_length
    Z, mask = case.X, case.missing_mask
    rows = np.flatnonzero(mask.any(axis=1))
    windows = rows[:, None] + np.arange(-n_lags, 1)
    X = Z[windows]
    X[:, -1][mask[rows]] = np.nan
    X = X.reshape(-1, Z.shape[1])
    ids = np.repeat(np.arange(len(rows)), n_lags + 1)
    draws = imputer.sample(X, n_samples=n_draws, sequence_ids=ids, random_state=seed)
    filled = draws.reshape(n_draws, len(rows), n_lags + 1, -1)[:, :, -1]
    return float(
        np.mean([fillin_error(Z[rows], f, missing_mask=mask[rows]) for f in filled])
    )


def main():
    args = parse_args()
    dtype = np.dtype(args.dtype)
    Z_train, sequence_ids, cases = load(args.data_home)
    print(
        f"training frames {Z_train.shape}, upper body: "
        f"{', '.join(cases['walk', 'upper'].bones)}"
    )
    for key, case in cases.items():
        print(
            f"  {case.trial} {key[0]:4s} {key[1]:5s}: {len(case.X)} frames, "
            f"erased frames {case.first_missing}..{len(case.X) - 1}, "
            f"{case.missing_mask.any(axis=0).sum()} channels"
        )
    base = baselines(Z_train, cases)
    memory = joblib.Memory(args.cache_dir or None, verbose=0)
    train = memory.cache(_train_imputer)
    Z_fit = Z_train.astype(dtype)
    results = {"baselines": {}, "crbm": {}}
    for (name, motion, part), (err, deg) in base.items():
        results["baselines"].setdefault(name, {})[f"{motion}/{part}"] = dict(
            error=err, degrees=deg
        )
    model_keys = {}
    for variant in args.variants:
        params = VARIANTS[variant]["model"]
        model_keys.setdefault(tuple(sorted(params.items())), params)
    trained = {}
    jobs = [(key, seed) for key in model_keys for seed in args.seeds]
    fitted = joblib.Parallel(n_jobs=args.n_jobs)(
        joblib.delayed(train)(model_keys[key], seed, args.n_iter, Z_fit, sequence_ids)
        for key, seed in jobs
    )
    for (key, seed), (imputer, seconds) in zip(jobs, fitted, strict=True):
        trained[(key, seed)] = _with_new_parameters(imputer)
        model = imputer.estimator_
        print(
            f"  model history_noise={model.history_noise} seed {seed}: trained "
            f"{model.n_iter_} epochs in {seconds:.0f} s, "
            f"reconstruction error {model.reconstruction_error_:.3f}"
        )
    for variant in args.variants:
        spec = VARIANTS[variant]
        key = tuple(sorted(spec["model"].items()))
        for seed in args.seeds:
            start = time.perf_counter()
            res = crbm_results(
                trained[(key, seed)],
                spec["imputer"],
                seed,
                cases,
                args.n_repeats,
                args.n_draws,
            )
            results["crbm"].setdefault(variant, {})[str(seed)] = {
                f"{m}/{p}": v for (m, p), v in res.items()
            }
            print(
                f"  {variant} seed {seed}: filled in {time.perf_counter() - start:.1f} s"
            )
    report(results, args)
    output = Path(args.output)
    output.parent.mkdir(parents=True, exist_ok=True)
    results["config"] = dict(
        vars(args),
        variants_spec={v: VARIANTS[v] for v in args.variants},
        python=platform.python_version(),
        numpy=np.__version__,
        sklearn=sklearn.__version__,
    )
    results["paper"] = {
        f"{m}/{p}": dict(crbm=c, nn=n) for (m, p), (c, n) in PAPER.items()
    }
    output.write_text(json.dumps(results, indent=2, default=float))
    print(f"\nwrote {output}")


def report(results, args):
    cells = [f"{m}/{p}" for m in ("walk", "jog") for p in ("leg", "upper")]
    nn = results["baselines"]["nearest neighbour"]
    print("\nBaselines: paper error (degrees RMS)")
    print(f"{'method':24s}" + "".join(f"{c:>20s}" for c in cells))
    for name, row in results["baselines"].items():
        print(
            f"{name:24s}"
            + "".join(
                f"{row[c]['error']:>11.2f} ({row[c]['degrees']:5.1f}°)" for c in cells
            )
        )
    print(
        "paper (walk)            " + f"{'CRBM 8.78 / NN 11.68':>20s}"
        f"{'CRBM 20.52 / NN 22.20':>22s}"
    )
    for variant, per_seed in results["crbm"].items():
        print(
            f"\nCRBM '{variant}': mean of {args.n_repeats} single draws "
            f"[ratio to NN] (degrees) | average of {args.n_draws} draws [ratio]"
        )
        print(f"{'seed':6s}" + "".join(f"{c:>40s}" for c in cells))
        ratios = {c: [] for c in cells}
        wins = {c: 0 for c in cells}
        for seed, row in per_seed.items():
            line = f"{seed:6s}"
            for c in cells:
                r = row[c]["single"] / nn[c]["error"]
                ratios[c].append(r)
                wins[c] += r < 1
                line += (
                    f"{row[c]['single']:>9.2f} [{r:4.2f}] ({row[c]['single_degrees']:4.1f}°)"
                    f" | {row[c]['averaged']:6.2f} "
                    f"[{row[c]['averaged'] / nn[c]['error']:4.2f}]"
                )
            print(line)
        print(
            f"{'median':6s}"
            + "".join(
                f"{'ratio ' + format(np.median(ratios[c]), '.3f'):>40s}" for c in cells
            )
        )
        print(
            f"{'wins':6s}"
            + "".join(
                f"{f'{wins[c]}/{len(per_seed)} seeds beat NN':>40s}" for c in cells
            )
        )
        print(
            f"{'':6s}drift check, error with the model's own past (on-line) vs the "
            "true past: "
            + "; ".join(
                f"{c} "
                + " ".join(
                    f"{row[c]['single']:.1f}/{row[c]['true_past']:.1f}"
                    for row in per_seed.values()
                )
                for c in cells
                if "upper" in c
            )
        )
        results["crbm"][variant]["summary"] = {
            c: dict(
                median_ratio=float(np.median(ratios[c])),
                wins=int(wins[c]),
                ratios=[float(r) for r in ratios[c]],
            )
            for c in cells
        }


if __name__ == "__main__":
    main()
