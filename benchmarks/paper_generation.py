"""The paper's generation experiments: styles (§4.1), stacks (§4.2, §5), transitions (§4.3).

``styles``: per model and seed, 300 frames from each of 6 real seed windows
per style, the last 100 judged (``metrics.judge_generated_motion``); a seed
passes when for every style at least 5 of 6 keep it, none blows up and at
most one dies out.  ``--models``: ``paper``
(``paper_schedule(n_iter=1000)``), ``defaults``, ``stacked``
(``StackedCRBM((200, 200), order=3, n_iter=500)``) and ``stacked-noisy``
(``history_noise=0.4``); ``--datasets``: ``cmu`` (CMU 35) and ``mit``.
``transitions``: 12 sequences of 1200 frames of the CMU ``defaults`` with
``hidden_noise``; switches between 60-frame windows counted per direction.

Run from the repository root::

    python benchmarks/paper_generation.py
    python benchmarks/paper_generation.py --parts transitions --noise 0 2 4
"""

import _common as common
import numpy as np

from sklearn_crbm import ConditionalRBM, StackedCRBM

STACKED = dict(n_components=(200, 200), order=3, n_iter=500)
MODELS = {
    "paper": lambda seed: ConditionalRBM.paper_schedule(n_iter=1000, random_state=seed),
    "defaults": lambda seed: ConditionalRBM(random_state=seed),
    "stacked": lambda seed: StackedCRBM(**STACKED, random_state=seed),
    "stacked-noisy": lambda seed: StackedCRBM(
        **STACKED, history_noise=0.4, random_state=seed
    ),
}
N_PER_STYLE, N_FRAMES = 6, 300
WINDOW, HOP = 60, 30
COUNTS = ("keeps", "dead", "stalled", "blown")  # sequences per style
LABELS = ("walk", "jog", "still", "blown")  # of windows
PARTS, DATASETS = ("styles", "transitions"), ("cmu", "mit")


def fitted(corpus, model_name, seed):
    model = MODELS[model_name](seed)
    return common.cached_fit(model, corpus.Z.astype(np.float32), corpus.ids)[0]


def styles_row(corpus, model, seed):
    """Counts per style over the last 100 of 300 generated frames."""
    history, expected = corpus.seed_windows(model, N_PER_STYLE, seed)
    generated = model.sample(N_FRAMES, history=history, random_state=seed)
    ids = np.repeat(np.arange(len(expected)), N_FRAMES)
    verdict = corpus.judge(generated, ids, expected, last_frames=100)
    row, passes = {}, True
    for style in corpus.style_names:
        mine = expected == style
        counts = {k: int(verdict[k][mine].sum()) for k in COUNTS}
        row.update({f"{style} {k}": v for k, v in counts.items()})
        row[f"{style} speed"] = float(np.mean(verdict.speed[mine]))
        row[f"{style} Hz"] = float(np.nanmean(verdict.frequency[mine]))
        passes &= counts["keeps"] >= N_PER_STYLE - 1
        passes &= counts["blown"] == 0 and counts["dead"] <= 1
    row["passes"] = "yes" if passes else "no"
    return row


def window_labels(corpus, generated, n_sequences, n_frames):
    """walk / jog / still / blown for every window of every sequence."""
    starts = np.arange(0, n_frames - WINDOW + 1, HOP)
    rows = (starts[:, None] + np.arange(WINDOW)).ravel()
    windows = generated.reshape(n_sequences, n_frames, -1)[:, rows]
    windows = windows.reshape(n_sequences * len(starts) * WINDOW, -1)
    verdict = corpus.judge(
        windows, np.repeat(np.arange(n_sequences * len(starts)), WINDOW)
    )
    labels = np.where(verdict.dead | verdict.stalled, "still", verdict.style)
    labels = np.where(verdict.blown, "blown", labels)
    return labels.reshape(n_sequences, len(starts))


def transitions_row(corpus, model, seed, noise, n_frames=1200):
    history, _ = corpus.seed_windows(model, N_PER_STYLE, seed)
    generated = model.sample(
        n_frames, history=history, hidden_noise=noise, random_state=seed
    )
    labels = window_labels(corpus, generated, len(history), n_frames)
    switches = {"walk to jog": 0, "jog to walk": 0}
    for row in labels:
        moving = [label for label in row if label in ("walk", "jog")]
        for a, b in zip(moving[:-1], moving[1:], strict=True):
            if a != b:
                switches[f"{a} to {b}"] += 1
    shares = {s: float(np.mean(labels == s)) for s in LABELS}
    return dict(hidden_noise=noise, seed=seed, **switches, **shares)


def main(argv=None):
    p = common.parser(__doc__, seeds=(0, 1, 2))
    p.add_argument("--parts", nargs="+", default=list(PARTS), choices=PARTS)
    p.add_argument("--datasets", nargs="+", default=list(DATASETS), choices=DATASETS)
    p.add_argument("--models", nargs="+", default=list(MODELS), choices=MODELS)
    p.add_argument("--noise", type=float, nargs="+", default=[0, 1, 2, 2.5, 3, 4])
    args = p.parse_args(argv)
    common.announce()
    corpora = {n: common.MotionCorpus(args.data_home, n) for n in args.datasets}
    results = {}
    if "styles" in args.parts:
        rows = []
        for name, corpus in corpora.items():
            for model_name in args.models:
                if name == "mit" and not model_name.startswith("stacked"):
                    continue  # the MIT data is the two-level model's
                for seed in args.seeds:
                    row = styles_row(corpus, fitted(corpus, model_name, seed), seed)
                    rows.append(dict(data=name, model=model_name, seed=seed, **row))
                    print(f"  {name} {model_name} seed {seed}: {row}", flush=True)
        columns = ["data", "model", "seed"]
        for style in ("walk", "jog"):
            columns += [(f"{style} {k}", f"{style}s {k}", "d") for k in COUNTS]
            columns += [
                (f"{style} {k}", f"{style} {k}", ".2f") for k in ("speed", "Hz")
            ]
        title = f"\n§4.1, §5: {N_PER_STYLE} sequences per style, last 100 of {N_FRAMES} frames"
        table = common.print_table(rows, [*columns, "passes"], title=title)
        results["styles"] = dict(rows=rows, table=table)
    if "transitions" in args.parts:
        corpus = corpora.get("cmu") or common.MotionCorpus(args.data_home, "cmu")
        rows = [
            transitions_row(corpus, fitted(corpus, "defaults", seed), seed, noise)
            for noise in args.noise
            for seed in args.seeds
        ]
        noise = ("hidden_noise", "hidden_noise", "g")
        shares = [(s, f"share {s}", ".2f") for s in LABELS]
        columns = [noise, "seed", "walk to jog", "jog to walk", *shares]
        title = (
            f"\n§4.3: {2 * N_PER_STYLE} sequences of 1200 frames, windows of {WINDOW}"
        )
        table = common.print_table(rows, columns, title=title)
        results["transitions"] = dict(rows=rows, table=table)
    common.write_json("paper_generation", args.output, args=vars(args), **results)


if __name__ == "__main__":
    main()
