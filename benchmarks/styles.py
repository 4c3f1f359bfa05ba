"""Many styles from one model: the factored CRBM's criteria (issues 29, 35).

The Bandai walks in seven styles, preprocessed as fitted on takes 001-005;
the takes 006 held out.  ``FactoredCRBM`` with the defaults per seed
(``--n-iter`` shortens training).  Parts (``--parts``): ``style`` (per style,
``--n-sequences`` x ``--n-frames`` frames from a normal walk, windows from
frame 100 judged the style and alive, gait within 25%/15%, no blow-up),
``blends`` (the 21 pairs at 50/50), ``transitions`` (the 42 ordered pairs
switched half-way, judged 60 frames on), ``likelihood``, ``recognition`` and
``fillin`` (log ratio to the best of ``KNNImputer`` (5, 10) and
``AutoregressiveImputer``) on the takes 006, ``speed`` (s/epoch; the
products' share of generating 100 sequences together, at least 0.6).

Results are cached per seed, keyed by the code; ``--tabulate`` merges
earlier runs' JSON (seeds run apart)::

    python benchmarks/styles.py --seeds 0 --n-iter 50
    python benchmarks/styles.py --tabulate seed0.json seed1.json
"""

import os

# One BLAS thread per process: the matrices are small, and threads only
# fight on a shared machine.  Must be set before numpy is imported.
for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import hashlib  # noqa: E402
import itertools  # noqa: E402
import json  # noqa: E402
from functools import partial  # noqa: E402
from pathlib import Path  # noqa: E402

import _common as common  # noqa: E402
import numpy as np  # noqa: E402
import sklearn  # noqa: E402
from sklearn.impute import KNNImputer  # noqa: E402

from sklearn_crbm import FactoredCRBM  # noqa: E402
from sklearn_crbm.datasets import bone_columns, load_bandai_walks  # noqa: E402
from sklearn_crbm.impute import AutoregressiveImputer  # noqa: E402
from sklearn_crbm.metrics import StyleJudge, forward_speed, step_frequency  # noqa: E402
from sklearn_crbm.model_selection import make_fillin_cases, paper_body_parts  # noqa: E402
from sklearn_crbm.preprocessing import make_motion_preprocessor  # noqa: E402
from sklearn_crbm.utils import random_windows  # noqa: E402

FRAME_RATE = 30.0
NORMAL = "normal"
LEGS = ("UpperLeg_L", "UpperLeg_R", "LowerLeg_L", "LowerLeg_R")
BODY_PARTS = dict(left_leg="UpperLeg_L", upper_body="Spine")
JUDGED_FROM = 100  # first frame of the windows judged
AFTER_SWITCH = 60  # frames after a transition's switch before windows count
LAST_FRAMES = 100  # frames of the amplitude and frequency check
SCORED_FROM = 12  # frames of each held-out take not scored (full histories)
RECOGNITION_FRAMES = 300
BLOWN_UP = 2.0  # a channel beyond this times its largest real |z| has blown up
PARTS = tuple("style blends transitions likelihood recognition fillin speed".split())


# ------------------------------------------------------------------- data
class Split:
    """``walks`` preprocessed (``Z``) as fitted on the ``train`` frames, with
    ``judge`` (2-s windows' style, alive), ``pace`` (100 frames' gait), ``limit``
    (|z| per channel beyond which motion blew up) and the real takes' mean
    speed and step frequency per style (``styles``: the label weights' order)."""

    def __init__(self, walks, train):
        self.walks, self.train, self.test = walks, train, ~train
        self.styles = styles = sorted(walks.target_names)
        ids = walks.sequence_ids
        with sklearn.config_context(enable_metadata_routing=True):
            self.pre = make_motion_preprocessor(walks.skeleton)
            self.pre.fit(walks.data[train], sequence_ids=ids[train])
            self.Z = Z = self.pre.transform(walks.data, sequence_ids=ids)
        names = self.pre.get_feature_names_out()
        self.legs = legs = bone_columns(names, LEGS)
        labels = walks.target_names[walks.target]
        self.judge = StyleJudge(legs=legs).fit(Z, labels, sequence_ids=ids)
        self.pace = StyleJudge(window=LAST_FRAMES, stride=10, legs=legs)
        self.pace.fit(Z, labels, sequence_ids=ids)
        self.limit = BLOWN_UP * np.abs(Z).max(axis=0)
        speed = forward_speed(Z, sequence_ids=ids, feature_names=names)
        frequency = step_frequency(
            Z, sequence_ids=ids, features=legs, frame_rate=FRAME_RATE
        )
        take_styles = labels[np.searchsorted(ids, np.arange(ids.max() + 1))]
        self.real_speed = {s: float(speed[take_styles == s].mean()) for s in styles}
        self.real_frequency = {
            s: float(frequency[take_styles == s].mean()) for s in styles
        }

    def frames(self, rows):
        """``(Z, styles, sequence_ids)`` of the given rows."""
        walks = self.walks
        styles = walks.target_names[walks.target[rows]]
        return self.Z[rows], styles, walks.sequence_ids[rows]

    def seed_windows(self, style, width, n_windows, rng):
        """``n_windows`` windows of ``width`` real training frames of ``style``."""
        Z, styles, ids = self.frames(self.train)
        return random_windows(
            Z,
            sequence_ids=ids,
            width=width,
            n_windows=n_windows,
            sequences=np.unique(ids[styles == style]),
            random_state=rng,
        )


def label_weights(styles, n_frames, first, second=None, switch=None, blend=None):
    """Per-frame label weights: one style, a 50/50 ``blend``, or a switch."""
    weights = np.zeros((n_frames, len(styles)))
    weights[:, styles.index(first)] = 1.0
    if blend is not None:
        weights[:, styles.index(first)] = 1.0 - blend
        weights[:, styles.index(second)] = blend
    if switch is not None:
        weights[switch:] = 0.0
        weights[switch:, styles.index(second)] = 1.0
    return weights


# ----------------------------------------------------------- measurements
def _draw_seed(rng):
    """An int seed from ``rng`` (the estimators take ints or RandomStates)."""
    return int(rng.integers(np.iinfo(np.int32).max))


def generated_ids(n_sequences, n_frames):
    return np.repeat(np.arange(n_sequences), n_frames)


def generate(model, split, weights, seed_style, n_sequences, rng):
    """Sequences following ``weights``, seeded with real frames of ``seed_style``."""
    history = split.seed_windows(seed_style, model.history_length, n_sequences, rng)
    return model.sample(
        len(weights), history=history, style=weights, random_state=_draw_seed(rng)
    )


def _blown_up(split, frames, n_sequences):
    """Sequences with a value beyond its channel's limit (or not finite)."""
    beyond = ~(np.abs(frames) <= split.limit)  # NaN counts as beyond
    return beyond.reshape(n_sequences, -1).any(axis=1)


def generate_judged(model, split, weights, seed_style, args, rng):
    """Generate, then judge: windows (kept, alive), last frames' pace, blow-ups."""
    n_sequences, n_frames = args.n_sequences, len(weights)
    frames = generate(model, split, weights, seed_style, n_sequences, rng)
    ids = generated_ids(n_sequences, n_frames)
    requested = np.asarray(split.styles, dtype=object)[np.argmax(weights, axis=1)]
    blown = _blown_up(split, frames, n_sequences)
    finite = np.where(np.isfinite(frames), frames, 0.0)
    verdict = split.judge.verdict(
        finite, np.tile(requested, n_sequences), sequence_ids=ids
    )
    last = np.arange(len(frames)).reshape(n_sequences, n_frames)[:, -LAST_FRAMES:]
    pace = split.pace.verdict(
        finite[last.ravel()],
        np.repeat(requested[-1], last.size),
        sequence_ids=generated_ids(n_sequences, LAST_FRAMES),
    )
    return verdict, pace, blown


def style_kept(model, split, args, rng):
    """Per style: windows kept (and alive) from JUDGED_FROM on, the last
    frames' pace and blow-ups, seeded with a normal walk."""
    cells = {}
    for style in split.styles:
        weights = label_weights(split.styles, args.n_frames, style)
        verdict, pace, blown = generate_judged(model, split, weights, NORMAL, args, rng)
        judged = verdict.starts >= JUDGED_FROM
        cells[style] = dict(
            kept=float(verdict.correct[judged].mean()),
            kept_alive=float(verdict.accepted[judged].mean()),
            amplitude_ratio=pace.amplitude_ratio.tolist(),
            frequency_ratio=pace.frequency_ratio.tolist(),
            pace_ok=int(np.sum(pace.alive)),
            blown_up=int(blown.sum()),
        )
    return cells


def blends(model, split, args, rng):
    names = split.pre.get_feature_names_out()
    cells = {}
    for first, second in itertools.combinations(split.styles, 2):
        weights = label_weights(split.styles, args.n_frames, first, second, blend=0.5)
        frames = generate(model, split, weights, NORMAL, args.n_sequences, rng)
        blown = _blown_up(split, frames, args.n_sequences)
        frames = np.where(np.isfinite(frames), frames, 0.0)
        ids = generated_ids(args.n_sequences, args.n_frames)
        verdict = split.judge.verdict(frames, sequence_ids=ids)
        judged = verdict.starts >= JUDGED_FROM
        later = np.tile(np.arange(args.n_frames) >= JUDGED_FROM, args.n_sequences)
        frames, ids = frames[later], ids[later]
        speed = forward_speed(frames, sequence_ids=ids, feature_names=names)
        frequency = step_frequency(
            frames, sequence_ids=ids, features=split.legs, frame_rate=FRAME_RATE
        )
        one_of_two = np.isin(verdict.predicted[judged], [first, second]).mean()
        cells[f"{first}/{second}"] = dict(
            one_of_two=float(one_of_two),
            speed_between=_between(np.mean(speed), split.real_speed, first, second),
            frequency_between=_between(
                np.mean(frequency), split.real_frequency, first, second
            ),
            blown_up=int(blown.sum()),
        )
    return cells


def _between(value, real, first, second, margin=0.1):
    """Whether ``value`` lies between the real values of two styles (or near)."""
    low, high = sorted((real[first], real[second]))
    return bool(low - margin * (high - low) <= value <= high + margin * (high - low))


def transitions(model, split, args, rng):
    cells = {}
    switch = args.n_frames // 2
    for first, second in itertools.permutations(split.styles, 2):
        weights = label_weights(
            split.styles, args.n_frames, first, second, switch=switch
        )
        verdict, _, blown = generate_judged(model, split, weights, first, args, rng)
        judged = verdict.starts >= switch + AFTER_SWITCH
        cells[f"{first}->{second}"] = dict(
            new_style=float(verdict.correct[judged].mean()),
            alive=float(verdict.alive[judged].mean()),
            new_alive=float(verdict.accepted[judged].mean()),
            blown_up=int(blown.sum()),
        )
    return cells


def likelihood(model, split, seed):
    Z, styles, ids = split.frames(split.test)
    result = model.estimate_log_likelihood(
        Z, sequence_ids=ids, style=styles, reverse=True, random_state=seed
    )
    scored = common.frames_with_history(ids, SCORED_FROM)
    estimate, error = result.log_likelihood[scored], result.standard_error[scored]
    return dict(
        mean=float(estimate.mean()),
        standard_error=float(np.sqrt(np.sum(error**2)) / len(scored)),
        reverse_gap=float(np.mean(estimate - result.lower[scored])),
        n_frames=len(scored),
    )


def recognition(model, split, seed):
    Z, styles, ids = split.frames(split.test)
    takes = np.unique(ids)
    first = np.concatenate(
        [np.flatnonzero(ids == k)[:RECOGNITION_FRAMES] for k in takes]
    )
    named = model.set_params(random_state=seed).predict(
        Z[first], sequence_ids=ids[first]
    )
    named = [named[ids[first] == k][0] for k in takes]
    truth = [styles[ids == k][0] for k in takes]
    return dict(
        correct=int(np.sum(np.asarray(named) == np.asarray(truth))), of=len(truth)
    )


def fillin(model, split, seed):
    """Log ratio of the model's fill-in error to the best simple baseline's."""
    Z, train_styles, ids = split.frames(split.train)
    baselines = [
        KNNImputer(n_neighbors=5).fit(Z),
        KNNImputer(n_neighbors=10).fit(Z),
        AutoregressiveImputer().fit(Z, sequence_ids=ids),
    ]
    walks = split.walks
    takes = np.unique(walks.sequence_ids[split.test])
    styles = walks.target_names[
        walks.target[np.searchsorted(walks.sequence_ids, takes)]
    ]
    held_out = {s: walks.sequence_names[k] for s, k in zip(styles, takes, strict=True)}
    cases = make_fillin_cases(
        walks,
        split.pre,
        trials=held_out,
        body_parts=paper_body_parts(walks.skeleton, **BODY_PARTS),
    )
    ratios, imputers = {}, {}
    for (style, part), case in cases.items():
        best = min(case.errors(b.transform(case.X_missing))[0] for b in baselines)
        if style not in imputers:
            imputers[style] = common.frozen_imputer(model, Z, ids, seed, train_styles)
        filled = imputers[style].transform(case.X_missing, style=style)
        ratios[f"{style}/{part}"] = float(np.log(case.errors(filled)[0] / best))
    return ratios


def speed(model, split, fit_seconds, rng, n_sequences=100, n_frames=30):
    """Seconds per epoch; frames/s of ``n_sequences`` generated together over
    the bound of their matrix products alone (criterion: at least 0.6)."""
    weights = label_weights(split.styles, n_frames, NORMAL)
    history = split.seed_windows(NORMAL, model.history_length, n_sequences, rng)
    run = partial(
        model.sample, n_frames, history=history, style=weights, random_state=0
    )
    shapes = _recorded_products(run)
    generation, alone = common.seconds(run), common.seconds(_products_alone(shapes))
    return dict(
        seconds_per_epoch=fit_seconds / model.n_iter_,
        generation_seconds=generation,
        generation_products_seconds=alone,
        generation_of_products_bound=alone / generation,
    )


def _recorded_products(run):
    """The operand shapes and dtypes of every ``numpy.matmul`` that ``run()`` calls."""
    shapes, matmul = [], np.matmul

    def recording(a, b, *rest, **kwargs):
        shapes.append((a.shape, b.shape, np.result_type(a, b)))
        return matmul(a, b, *rest, **kwargs)

    np.matmul = recording
    try:
        run()
    finally:
        np.matmul = matmul
    return shapes


def _products_alone(shapes):
    """A function running products of ``shapes`` (random operands) alone."""
    rng = np.random.default_rng(0)
    operands = [
        (rng.random(a).astype(dtype), rng.random(b).astype(dtype))
        for a, b, dtype in shapes
    ]

    def products():
        for a, b in operands:
            np.matmul(a, b)

    return products


# ----------------------------------------------------------------- report
# The "Done when" in one table, each column a measure over the
# training seeds.  A part's result per seed is one cell (ONE_CELL_PARTS) or
# a dict of cells: per style (style), per pair (blends, transitions), per
# case (fill-in log ratios).
ONE_CELL_PARTS = ("likelihood", "recognition", "speed")


def _per_seed(results, part):
    """``part``'s cells of every seed that has it: a list (one per seed) of lists."""
    found = [r[part] for r in results.values() if r.get(part) is not None]
    return [[f] if part in ONE_CELL_PARTS else list(f.values()) for f in found]


def _cells(rows, key):
    return [cell[key] for row in rows for cell in row]


def _interval(rows, rng, key=None, percent=True):
    """Mean of ``key`` of the cells (None: the cells) over the seeds [95%]."""
    values = [[cell if key is None else cell[key] for cell in row] for row in rows]
    return common.interval_text(values, percent, "+.3f", rng)


def _fillin(rows, rng):
    """Mean log ratio over styles, parts and seeds, its interval over the
    seed-cells (each a row of the bootstrap: one seed gives an interval too)."""
    return _interval([[ratio] for row in rows for ratio in row], rng, percent=False)


def _pace(rows, rng):
    total = sum(map(len, _cells(rows, "amplitude_ratio")))
    return f"{sum(_cells(rows, 'pace_ok'))}/{total}"


def _blends(rows, rng):
    """Pairs (mean over seeds) with the speed between the two styles', pairs
    with at least 80% of windows judged one of the two (and the mean share of
    windows with its interval), pairs with the step frequency between."""
    n = len(rows[0])

    def pairs(passes):
        return f"{np.mean([sum(passes(c) for c in row) for row in rows]):.1f}/{n}"

    one_of_two = _interval(rows, rng, "one_of_two")
    return (
        f"{pairs(lambda c: c['speed_between'])}; "
        f"{pairs(lambda c: c['one_of_two'] >= 0.8)} ({one_of_two}); "
        f"freq {pairs(lambda c: c['frequency_between'])}"
    )


def _likelihood(rows, rng):
    means = _cells(rows, "mean")
    error, gap = max(_cells(rows, "standard_error")), max(_cells(rows, "reverse_gap"))
    span = f" ({min(means):.2f} to {max(means):.2f})" if len(means) > 1 else ""
    return f"{np.mean(means):.2f}{span}; SE {error:.1e}, gap {gap:.2f}"


def _recognition(rows, rng):
    correct = _cells(rows, "correct")
    return f"{min(correct)}-{max(correct)}/{rows[0][0]['of']}"


def _mean(rows, rng, key):
    return f"{np.mean(_cells(rows, key)):.2f}"


# (column, part, formatter of the per-seed rows of cells and ``rng``, for the
# bootstrap), for the table's columns in the order of the issue.
COLUMNS = [
    ("kept & alive [95%]", "style", partial(_interval, key="kept_alive")),
    ("kept", "style", lambda r, g: f"{100 * np.mean(_cells(r, 'kept')):.0f}%"),
    ("in pace", "style", _pace),
    ("blown up", "style", lambda r, g: str(sum(_cells(r, "blown_up")))),
    (
        "transitions: new & alive [95%]",
        "transitions",
        partial(_interval, key="new_alive"),
    ),
    ("blends: speed between; 1 of 2 >= 80% (windows [95%]); freq", "blends", _blends),
    ("held-out LL/frame", "likelihood", _likelihood),
    ("recognised", "recognition", _recognition),
    ("fill-in log ratio [95%]", "fillin", _fillin),
    (
        "100 together / products",
        "speed",
        partial(_mean, key="generation_of_products_bound"),
    ),
    ("s/epoch", "speed", partial(_mean, key="seconds_per_epoch")),
]


def table(results, seed=0):
    """The measures over the seeds (``seed``: the bootstrap's), then per style."""
    row = {"seeds": ",".join(str(s) for s in results)}
    styles = [r["style"] for r in results.values() if r.get("style")]
    first = styles[0] if styles else ()
    means = {s: np.mean([r[s]["kept_alive"] for r in styles]) for s in first}
    lowest = min(means, key=means.get) if means else None
    row["lowest style"] = f"{lowest} {100 * means[lowest]:.0f}%" if means else "-"
    for column, part, formatter in COLUMNS:
        cells = _per_seed(results, part)
        # each column its own stream, whatever the columns before it drew
        row[column] = formatter(cells, np.random.default_rng(seed)) if cells else "-"
    common.print_table([row], list(row))
    if means:
        print()
        percents = {s: f"{100 * m:.0f}%" for s, m in means.items()}
        common.print_table([percents], list(means))


# ------------------------------------------------------------------- main
def run_seed(split, args, seed):
    Z, styles, ids = split.frames(split.train)
    rng = np.random.default_rng(seed)
    model = FactoredCRBM(random_state=seed)
    if args.n_iter is not None:
        model.set_params(n_iter=args.n_iter)
    fit_seconds = common.seconds(partial(model.fit, Z, styles, sequence_ids=ids))
    print(f"  seed {seed}: trained in {fit_seconds:.0f} s", flush=True)
    measures = {  # in this order: they draw from one random stream
        "style": lambda: style_kept(model, split, args, rng),
        "blends": lambda: blends(model, split, args, rng),
        "transitions": lambda: transitions(model, split, args, rng),
        "likelihood": lambda: likelihood(model, split, seed),
        "recognition": lambda: recognition(model, split, seed),
        "fillin": lambda: fillin(model, split, seed),
        "speed": lambda: speed(model, split, fit_seconds, rng),
    }
    out = {"fit_seconds": fit_seconds}
    for part, measure in measures.items():
        if part in args.parts:
            out[part] = measure()
    return out


def cached_seed(split, args, seed):
    """``run_seed``'s result, cached by seed, options and the code of the
    package and this script (processes of disjoint seeds share the work)."""
    key = hashlib.sha1()
    for path in sorted([*common.PACKAGE.rglob("*.py"), Path(__file__)]):
        key.update(path.read_bytes())
    options = (seed, args.n_iter, args.parts, args.n_frames, args.n_sequences)
    key.update(repr(options).encode())
    path = common.CACHE / "styles" / f"seed{seed}_{key.hexdigest()[:16]}.json"
    if path.exists():
        return json.loads(path.read_text())
    result = run_seed(split, args, seed)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(result))
    return result


def tabulate(paths):
    """Print the tables of earlier runs' JSON (seeds, parts), merged."""
    results = {}
    for path in paths:
        for seed, parts in json.loads(Path(path).read_text())["results"].items():
            results.setdefault(seed, {}).update(parts)
    print(f"\nBandai walks, 7 styles; from {', '.join(paths)}\n")
    table(results)
    return results


def main(argv=None):
    p = common.parser(__doc__)
    p.add_argument("--n-iter", type=int, help="epochs (default: the package's)")
    p.add_argument("--parts", nargs="+", default=list(PARTS), choices=PARTS)
    p.add_argument("--n-frames", type=int, default=1000)
    p.add_argument("--n-sequences", type=int, default=6)
    merge_help = "print the tables of earlier runs' JSON (merged) instead of running"
    p.add_argument("--tabulate", nargs="+", metavar="JSON", help=merge_help)
    p.set_defaults(output=str(common.RESULTS / "styles.json"))
    args = p.parse_args(argv)
    if args.tabulate:
        return tabulate(args.tabulate)

    sklearn.set_config(enable_metadata_routing=True)
    walks = load_bandai_walks(args.data_home)
    split = Split(walks, walks.takes[walks.sequence_ids] <= 5)
    results = {seed: cached_seed(split, args, seed) for seed in args.seeds}
    print(
        f"\nBandai walks, 7 styles; trained on takes 001-005, judged over "
        f"{args.n_sequences} x {args.n_frames} frames per style; seeds {args.seeds}, "
        f"n_iter {args.n_iter or 'default'}\n"
    )
    table(results)
    output = Path(args.output)
    output.parent.mkdir(parents=True, exist_ok=True)
    output.write_text(json.dumps({"args": vars(args), "results": results}, indent=1))
    print(f"\nwrote {output}")
    return results


if __name__ == "__main__":
    main()
