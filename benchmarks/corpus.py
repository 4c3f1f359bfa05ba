"""One model of a whole labelled corpus (issue 47): any content in any style.

Bandai dataset-2, takes 001-010 of every ``--contents`` x ``--styles`` cell
but a Latin square held out; per seed ``FactoredCRBM`` (``--n-iter``,
``--model``) with content and style as two label factors (``--factors 1``:
one label ``content/style``, none held out).  A ``StyleJudge`` per factor
(its accuracy on the real takes 011-012 beside every figure) judges, per
cell, 4 sequences of 600 frames from a normal walk over frames 300-599
(content, style, alive, ``corpora.py``'s statistics; raise-ups: action then
rest), and per content switches of content and of style at frame 300 (new
label within 60 frames, and after).  Takes 011-012: ``predict``
(``--recognise-frames``), log-likelihood per frame beside a
``ConditionalRBM`` per content (``--baseline``).  Fit time and memory,
frames/s with labels switching.  Means over seeds [95% bootstrap interval];
fits are cached::

    python benchmarks/corpus.py
    python benchmarks/corpus.py --contents walk run --styles normal elderly \\
        --seeds 0 --n-iter 5
"""

import json
from functools import partial
from pathlib import Path

import _common as common
import numpy as np
import sklearn
from corpora import CYCLIC, N_FRAMES, N_SEQUENCES, ONE_SHOT, Content, describe, generate
from sklearn.utils import Bunch

from sklearn_crbm import ConditionalRBM, FactoredCRBM
from sklearn_crbm.datasets import read_bvh_folder
from sklearn_crbm.metrics import StyleJudge
from sklearn_crbm.preprocessing import make_motion_preprocessor

STYLES = tuple("active elderly exhausted feminine masculine normal youthful".split())
TRAINING_TAKES, LAST_TAKE = 10, 12  # takes 011-012 held out; never 013 on
WINDOW, STRIDE, SWITCH, LATENCY = 60, 15, 300, 60


class Corpus:
    """Every frame's ``content``, ``style``, ``take``, ``ids`` (sequence) and
    ``Z`` (preprocessed as fitted on the ``train`` frames); ``unseen``: held out."""

    def __init__(self, data_home, contents, styles, held_out, factors):
        takes = read_bvh_folder(Path(data_home) / "bandai_dataset2")
        parts = np.array([name.split("_")[1:] for name in takes.sequence_names])
        content, style, take = parts[takes.sequence_ids].T
        keep = np.isin(content, contents) & np.isin(style, styles)
        if take.astype(int)[keep].max() > LAST_TAKE:
            raise ValueError("Takes 013 and later are kept for independent checks.")
        self.skeleton, self.factors = takes.skeleton, factors
        self.raw, self.ids = takes.data[keep], takes.sequence_ids[keep]
        self.content, self.style = content[keep], style[keep]
        self.take = take[keep].astype(int)
        pairs = zip(self.content, self.style, strict=True)
        self.unseen = np.array([cell in held_out for cell in pairs], dtype=bool)
        self.train = (self.take <= TRAINING_TAKES) & ~self.unseen
        self.test = self.take > TRAINING_TAKES
        self.preprocessor = make_motion_preprocessor(self.skeleton)
        with sklearn.config_context(enable_metadata_routing=True):
            self.preprocessor.fit(
                self.raw[self.train], sequence_ids=self.ids[self.train]
            )
            self.Z = self.preprocessor.transform(self.raw, sequence_ids=self.ids)
        self.cells = {}

    def labels(self, rows):
        """The model's labels: ``(content, style)`` rows, or ``content/style``."""
        labels = np.column_stack([self.content[rows], self.style[rows]])
        if self.factors == 2:
            return labels
        return np.char.add(np.char.add(labels[:, 0], "/"), labels[:, 1])

    def cell(self, content, style):
        """The real takes 001-010 of a cell and their statistics (``Content``)."""
        if (content, style) not in self.cells:
            rows = (self.content == content) & (self.style == style)
            rows &= self.take <= TRAINING_TAKES
            takes = Bunch(data=self.raw[rows], sequence_ids=self.ids[rows])
            takes.skeleton = self.skeleton
            cell = self.cells[content, style] = Content.__new__(Content)
            cell.describe(content, takes, self.preprocessor, self.Z[rows])
        return self.cells[content, style]

    def history(self, model, n_sequences=N_SEQUENCES):
        """The seed of every sequence: a window of a real normal walk."""
        width = max(model.history_length, 1)
        return self.cell("walk", "normal").seed(width)[:n_sequences]


class Judge:
    """``StyleJudge``s of content and style on 2-s windows of every takes 001-010."""

    def __init__(self, corpus):
        ids, counts = np.unique(corpus.ids, return_counts=True)
        long = np.isin(corpus.ids, ids[counts >= WINDOW])
        rows = long & (corpus.take <= TRAINING_TAKES)
        self.judges = [
            StyleJudge(window=WINDOW, stride=STRIDE).fit(
                corpus.Z[rows], labels[rows], sequence_ids=corpus.ids[rows]
            )
            for labels in (corpus.content, corpus.style)
        ]
        rows = long & corpus.test
        windows = self.windows(corpus.Z[rows], corpus.ids[rows])
        first = np.searchsorted(corpus.ids, windows.sequence_ids)
        truth = corpus.content[first], corpus.style[first]
        self.real = {}  # cell: judged its content, judged its style, per window
        for c, s in set(zip(*truth, strict=True)):
            cell = (truth[0] == c) & (truth[1] == s)
            self.real[c, s] = (windows.content[cell] == c, windows.style[cell] == s)

    def windows(self, Z, ids=None):
        """Windows' sequence ids, starts, content and style (``ids``: N_FRAMES)."""
        if ids is None:
            ids = np.repeat(np.arange(len(Z) // N_FRAMES), N_FRAMES)
        Z = np.clip(np.nan_to_num(Z), -1e3, 1e3)  # what is left of a blow-up
        content, style = (judge.verdict(Z, sequence_ids=ids) for judge in self.judges)
        return Bunch(
            sequence_ids=content.sequence_ids,
            starts=content.starts,
            content=content.predicted,
            style=style.predicted,
        )

    def accuracy(self, cells):
        """Content / style accuracy on the cells' real windows of takes 011-012."""
        judged = [self.real[cell] for cell in cells if cell in self.real]
        if not judged:
            return "no window"
        content, style = (
            100 * np.mean(np.concatenate(k)) for k in zip(*judged, strict=True)
        )
        return f"{content:.0f}% / {style:.0f}%"


def sequences(corpus, model, rows, seed, n_sequences=N_SEQUENCES):
    """``(Z, warnings, seconds)``: sequences from a normal walk asked for
    labels ``rows`` (one ``(content, style)``, or one per frame)."""
    rows = np.atleast_2d(rows)
    if corpus.factors == 2:
        params = {"y": tuple(rows[0]) if len(rows) == 1 else rows}
    else:
        combined = np.array(["/".join(row) for row in rows])
        one_hot = (combined[:, None] == model.classes_).astype(float)
        params = {"style": combined[0] if len(rows) == 1 else one_hot}
    return generate(model, corpus.history(model, n_sequences), seed, params)


def judge_cell(corpus, judge, model, cell, seed):
    """``corpora.py``'s statistics of the sequences asked for ``cell``, the
    windows judged its content and style, alive, and a raise-up's action."""
    Z, caught, seconds = sequences(corpus, model, [cell], seed)
    real, windows = corpus.cell(*cell), judge.windows(Z)
    run = describe(real, Z, caught, seconds)
    judged = windows.starts >= SWITCH
    run["content"] = float(np.mean(windows.content[judged] == cell[0]))
    run["style"] = float(np.mean(windows.style[judged] == cell[1]))
    kept = np.asarray(run["blown"]) == 0  # a blow-up is neither alive nor acts
    run["alive"] = float(np.mean((np.asarray(run["liveliness"]) >= 0.5) & kept))
    if cell[0] in ONE_SHOT:
        moving = real.unscaled(np.clip(np.nan_to_num(Z), -1e3, 1e3))[:, real.channels]
        halves = moving.reshape(N_SEQUENCES, 2, N_FRAMES // 2, -1)
        ids = real.takes.sequence_ids
        real_range = np.median(
            [
                np.ptp(real.unscaled_real[ids == t][:, real.channels], 0).mean()
                for t in set(ids)
            ]
        )
        ranges = np.ptp(halves, axis=2).mean(axis=-1) / real_range
        run["action"] = float(np.mean((ranges[:, 0] >= 0.5) & kept))
        run["rest"] = float(np.mean(ranges[:, 1] <= 0.5))
    return run


def switches(corpus, judge, model, contents, styles, seed):
    """Per content a switch of content and one of style at frame ``SWITCH``:
    per switch the sequences judged the new label in time, and the windows
    from ``SWITCH + LATENCY`` judged it."""
    runs = []
    for i, content in enumerate(contents):
        old = (content, styles[(i + 1) % len(styles)])
        for factor, new in (
            ("content", (contents[(i + 1) % len(contents)], old[1])),
            ("style", (content, styles[(i + 2) % len(styles)])),
        ):
            rows = [old] * SWITCH + [new] * (N_FRAMES - SWITCH)
            windows = judge.windows(sequences(corpus, model, rows, seed)[0])
            is_new = windows[factor] == new[factor == "style"]
            early = (windows.starts >= SWITCH) & (windows.starts <= SWITCH + LATENCY)
            in_time = [
                any(is_new & early & (windows.sequence_ids == k))
                for k in range(N_SEQUENCES)
            ]
            held = np.mean(is_new[windows.starts > SWITCH + LATENCY])
            runs.append(
                dict(factor=factor, new=new, in_time=np.mean(in_time), held=held)
            )
    return runs


def switching_speed(corpus, model, contents, styles):
    """Frames/s of one sequence, content changed every 100 frames, style 150."""
    frames = np.arange(N_FRAMES)
    content = np.take(contents, frames // 100, mode="wrap")
    rows = np.column_stack([content, np.take(styles, frames // 150, mode="wrap")])
    with common.threadpool_limits(1):
        return N_FRAMES / sequences(corpus, model, rows, 0, n_sequences=1)[2]


def first_frames(ids, n_frames):
    """Frames among the first ``n_frames`` of their (contiguous) sequence."""
    return np.arange(len(ids)) - np.searchsorted(ids, ids) < n_frames


def recognition(corpus, model, n_frames):
    """``predict`` of the first ``n_frames`` of every take 011-012: takes
    recognised (held-out cells' too), wall and CPU seconds."""
    rows = corpus.test & first_frames(corpus.ids, n_frames)
    X, ids, result = corpus.Z[rows], corpus.ids[rows], {}
    predict = partial(model.predict, X, sequence_ids=ids)
    wall, cpu = common.time_both(lambda: result.update(y=predict()))
    first = np.r_[True, ids[1:] != ids[:-1]]
    predicted = result["y"][first]
    if corpus.factors == 1:
        predicted = np.char.partition(predicted.astype(str), "/")[:, ::2]
    correct = predicted == np.column_stack([corpus.content, corpus.style])[rows][first]
    run = {"predict, wall s": wall, "predict, CPU s": cpu}
    for name, takes in (("", ...), ("held-out cells' ", corpus.unseen[rows][first])):
        if np.any(takes):
            run[f"recognised: {name}content %"] = correct[takes, 0].mean()
            run[f"recognised: {name}style %"] = correct[takes, 1].mean()
    return run


def likelihood(corpus, model, seed, baseline_params):
    """Log-likelihood per frame of takes 011-012 (frames with the past of
    both) of the model and of a ``ConditionalRBM`` per content."""
    totals = {}  # group: frames, and the two models' sums over them
    for content in np.unique(corpus.content):
        base = ConditionalRBM(random_state=seed, **baseline_params)
        train = corpus.train & (corpus.content == content)
        base = common.cached_fit(base, corpus.Z[train], corpus.ids[train])[0]
        width = max(model.history_length, base.history_length)
        for unseen in (False, True):
            rows = corpus.test & (corpus.content == content) & (corpus.unseen == unseen)
            if rows.any():
                X, ids = corpus.Z[rows], corpus.ids[rows]
                kw = dict(sequence_ids=ids, sample_weight=~first_frames(ids, width))
                n = kw["sample_weight"].sum()
                scores = [
                    model.score(X, corpus.labels(rows), **kw),
                    base.score(X, **kw),
                ]
                for group in ("all", "held-out cells")[: 1 + unseen]:
                    totals[group] = totals.get(group, 0) + n * np.array([1, *scores])
    return {
        f"log-likelihood per frame, {group}: {name}": t[k] / t[0]
        for group, t in totals.items()
        for k, name in ((1, "FactoredCRBM"), (2, "ConditionalRBM per content"))
    }


def one_seed(corpus, judge, seed, args):
    """Every measurement of one training seed."""
    params = dict(random_state=seed, **json.loads(args.model))
    if args.n_iter is not None:
        params["n_iter"] = args.n_iter
    X, ids, y = (f[corpus.train] for f in (corpus.Z, corpus.ids, corpus.labels(...)))
    with common.threadpool_limits(args.threads):
        model = FactoredCRBM(**params)
        model, *fit = common.cached_fit(model, X, ids, y=y, memory=True)
    run = dict(seed=seed, n_iter=model.n_iter_, cells={})
    with common.threadpool_limits(1):
        for cell in [(c, s) for c in args.contents for s in args.styles]:
            run["cells"]["/".join(cell)] = judge_cell(corpus, judge, model, cell, seed)
            shown = {k: np.mean(v) for k, v in run["cells"]["/".join(cell)].items()}
            shown = ", ".join(
                f"{k} {shown[k]:.2f}" for k in PERCENT + NUMBERS if k in shown
            )
            print(f"  seed {seed} {'/'.join(cell)}: {shown}", flush=True)
        run["switches"] = switches(
            corpus, judge, model, args.contents, args.styles, seed
        )
        run["measures"] = measures = {}
        for factor in ("content", "style"):
            done = [s for s in run["switches"] if s["factor"] == factor]
            name = f"{factor} switches: new {factor}"
            measures[f"{name} within {LATENCY} frames %"] = np.mean(
                [s["in_time"] for s in done]
            )
            measures[f"{name}, windows after {LATENCY} %"] = np.mean(
                [s["held"] for s in done]
            )
        measures.update(recognition(corpus, model, args.recognise_frames))
        measures.update(likelihood(corpus, model, seed, json.loads(args.baseline)))
        measures["fit s"], measures["MB the fit added"] = fit
        fps = switching_speed(corpus, model, args.contents, args.styles)
        measures["frames/s, one sequence, labels switching, one thread"] = fps
    print(f"  seed {seed}: {measures}", flush=True)
    return run


def interval(per_seed, percent=False):
    """Mean over seeds [95% interval] as text; "-" where a seed has none."""
    if any(value is None or np.isnan(value) for value in per_seed):
        return "-"
    return common.interval_text(per_seed, percent)


PERCENT = ("content", "style", "alive", "action", "rest")
NUMBERS = ("liveliness", "divergence", "jitter")


def cell_row(name, runs, cells, judge):
    """Means over seeds (of each seed's mean over the cells' sequences)."""
    row = dict(cells=name, n=len(cells), judge=judge.accuracy(cells))
    for key in PERCENT + NUMBERS:
        per_cell = [[run["cells"]["/".join(c)].get(key) for c in cells] for run in runs]
        if per_cell[0][0] is not None:
            row[key] = interval([np.mean(v) for v in per_cell], key in PERCENT)
    blown = [run["cells"]["/".join(c)]["blown"] for run in runs for c in cells]
    row["blown"] = int(np.sum(blown))
    return row


def main(argv=None):
    p = common.parser(__doc__, seeds=(0, 1, 2))
    p.add_argument("--contents", nargs="+", default=list(CYCLIC + ONE_SHOT))
    p.add_argument("--styles", nargs="+", default=list(STYLES))
    p.add_argument("--factors", type=int, choices=(1, 2), default=2)
    p.add_argument("--n-iter", type=int, default=None, help="FactoredCRBM's n_iter")
    p.add_argument("--model", default="{}", help="FactoredCRBM parameters, JSON")
    p.add_argument("--baseline", default="{}", help="ConditionalRBM parameters, JSON")
    p.add_argument("--recognise-frames", type=int, default=60)
    p.add_argument("--threads", type=int, default=1, help="BLAS threads of the fit")
    args = p.parse_args(argv)
    if min(len(args.contents), len(args.styles)) < 2:
        p.error("give at least two contents and two styles")
    common.announce()
    cells = [(c, s) for c in args.contents for s in args.styles]
    styles = args.styles * len(args.contents)  # a Latin square, if two factors
    held_out = (
        list(zip(args.contents, styles, strict=False)) if args.factors == 2 else []
    )
    corpus = Corpus(args.data_home, args.contents, args.styles, held_out, args.factors)
    judge = Judge(corpus)
    real = judge.accuracy(cells)
    print(f"{corpus.train.sum()} training frames; held out {held_out}", flush=True)
    runs = [one_seed(corpus, judge, seed, args) for seed in args.seeds]
    groups = [
        cell_row(f"{name}, {kind}", runs, chosen, judge)
        for name, held in (("trained", False), ("held out", True))
        for kind, contents in (("cyclic", CYCLIC), ("raise-ups", ONE_SHOT))
        if (
            chosen := [c for c in cells if (c in held_out) == held and c[0] in contents]
        )
    ]
    per_cell = [
        cell_row(("held out: " * (c in held_out)) + "/".join(c), runs, [c], judge)
        for c in cells
    ]
    new = {s["factor"]: [] for s in runs[0]["switches"]}
    for switch in runs[0]["switches"]:
        new[switch["factor"]].append(tuple(switch["new"]))
    others = [
        dict(
            measure=key,
            value=interval([r["measures"][key] for r in runs], "%" in key),
            judge=judge.accuracy(new[key.split()[0]]) if "switches" in key else "",
        )
        for key in runs[0]["measures"]
    ]
    data = f"{corpus.Z[corpus.train].nbytes / 2**20:.0f} MB of training data"
    columns = ["cells", "n", *((k, k, "s") for k in PERCENT + NUMBERS), "blown"]
    columns.append(("judge", "judge on real", "s"))
    title = (
        f"\n{N_SEQUENCES} sequences of {N_FRAMES} frames per cell from a normal walk, "
        f"frames {SWITCH}-{N_FRAMES - 1}; seeds {args.seeds}: means [95% interval]; "
        "judge on real: its content / style accuracy on the cells' takes 011-012"
    )
    tables = [
        common.print_table(groups, columns, title=title),
        common.print_table(per_cell, columns, title="\nper cell"),
        common.print_table(
            others,
            ["measure", ("value", "mean [95%]", "s"), ("judge", "judge on real", "s")],
            title=f"\nthe judge on all real windows of takes 011-012: {real}; {data}",
        ),
    ]
    payload = dict(args=vars(args), runs=runs, tables=tables, held_out=held_out)
    payload.update(groups=groups, cells=per_cell, others=others)
    common.write_json("corpus", args.output, **payload)


if __name__ == "__main__":
    main()
