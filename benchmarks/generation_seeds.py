"""Generated walks and jogs that keep their style and their legs, every seed (issue 15).

Protocol:

- one ConditionalRBM per training seed on all 33 CMU subject 35 trials
  (200 hidden units, order 3, ``--n-iter`` 1000 epochs; ``default``: every
  other parameter at its default, ``paper``:
  ``ConditionalRBM.paper_schedule``; ``bare``: ``ConditionalRBM()``, every
  parameter but ``random_state`` at its default, ``--n-iter`` ignored;
  ``unaveraged``: ``default`` with ``average_fraction=0`` (the last
  epoch's parameters, the defaults before averaging); ``every-channel``:
  ``default`` with the noise of the defaults before
  ``history_noise_fraction``, ``history_noise=0.8`` on every channel, not
  averaged; ``centred``: that with ``centering=True``),
  cached with the other generation benchmarks;
- per training seed, 6 walk-seeded and 6 jog-seeded sequences of 1000
  frames (seeds of the model's ``history_length`` real frames, ``order``
  unless ``hidden_order`` is larger, drawn as in ``generation_styles.py``;
  ``sample`` with its defaults);
- judged over frames 200-299 (the last 100 of the first 300) and over
  frames 900-999 (the last 100 of 1000); a sequence *passes* a window when
  it keeps its seed's style (nearest style on forward speed and step
  frequency), never leaves |z| <= 10, its leg amplitude (RMS of the
  per-channel standard deviations of the femur and tibia channels) is
  within 25% of the real trials of its style, and its step frequency within
  15% of theirs.

Prints one row per model and seed, and writes JSON (every sequence's
statistics) to ``benchmarks/results/generation_seeds.json``::

    python benchmarks/generation_seeds.py
    python benchmarks/generation_seeds.py --models paper --seeds 0 1
    python benchmarks/generation_seeds.py --models bare
"""

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import tempfile  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from _splits import EARLIER_DEFAULTS, UNAVERAGED, cached_model  # noqa: E402
from generation_styles import Motion, draw_seeds, judge  # noqa: E402

from sklearn_crbm import ConditionalRBM  # noqa: E402
from sklearn_crbm.datasets import load_cmu35  # noqa: E402
from sklearn_crbm.preprocessing import make_motion_preprocessor  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
STYLES = ("walk", "jog")
AMPLITUDE_TOLERANCE = 0.25
FREQUENCY_TOLERANCE = 0.15
WINDOWS = {"frames 200-299": 300, "frames 900-999": 1000}  # window -> its end


def model(name, seed, n_iter, n_components=200):
    if name == "paper":
        return ConditionalRBM.paper_schedule(n_iter=n_iter, random_state=seed)
    if name == "bare":
        return ConditionalRBM(random_state=seed)
    default = ConditionalRBM(n_components, order=3, n_iter=n_iter, random_state=seed)
    if name in ("every-channel", "centred"):
        default.set_params(**EARLIER_DEFAULTS)  # the defaults of then
    if name == "unaveraged":
        default.set_params(**UNAVERAGED)
    return default.set_params(centering=name == "centred")


def real_statistics(motion):
    """Mean leg amplitude and step frequency of the real trials of each style."""
    stats = motion.train_stats
    return {
        style: dict(
            amplitude=float(np.mean(stats["amplitude"][motion.styles == style])),
            frequency=float(np.nanmean(stats["frequency"][motion.styles == style])),
        )
        for style in STYLES
    }


def verdicts(motion, generated, n_frames, end, seed_styles, real):
    """Per-sequence statistics over the 100 frames before ``end``, and the bar."""
    n_sequences = len(seed_styles)
    window = generated.reshape(n_sequences, n_frames, -1)[:, :end].reshape(
        n_sequences * end, -1
    )
    stats = judge(motion, window, end, seed_styles, last_frames=100)
    reference = {
        key: np.array([real[s][key] for s in seed_styles])
        for key in ("amplitude", "frequency")
    }
    stats["lively"] = (
        np.abs(stats["amplitude"] / reference["amplitude"] - 1) <= AMPLITUDE_TOLERANCE
    )
    stats["in_step"] = (
        np.abs(stats["frequency"] / reference["frequency"] - 1) <= FREQUENCY_TOLERANCE
    )
    stats["passes"] = (
        (stats["style"] == seed_styles)
        & ~stats["blown"]
        & stats["lively"]
        & stats["in_step"]
    )
    return stats


def summary(stats, seed_styles):
    row = {}
    for style in STYLES:
        mine = seed_styles == style
        row[style] = dict(
            passes=int(stats["passes"][mine].sum()),
            keeps_style=int((stats["style"][mine] == style).sum()),
            blown=int(stats["blown"][mine].sum()),
            lively=int(stats["lively"][mine].sum()),
            in_step=int(stats["in_step"][mine].sum()),
            amplitude=[round(float(a), 3) for a in stats["amplitude"][mine]],
            frequency=[round(float(f), 3) for f in stats["frequency"][mine]],
            speed=[round(float(v), 3) for v in stats["speed"][mine]],
        )
    return row


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data-home", default=str(REPO.parent / "shared" / "data"))
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3, 4])
    parser.add_argument(
        "--models",
        nargs="+",
        default=["default", "paper"],
        choices=["default", "paper", "bare", "unaveraged", "centred", "every-channel"],
    )
    parser.add_argument("--n-iter", type=int, default=1000)
    parser.add_argument(
        "--n-components", type=int, default=200, help="hidden units of 'default'"
    )
    parser.add_argument(
        "--encoding",
        default="paper",
        choices=["paper", "default"],
        help="joint encoding: the paper's (rest pose, Taylor's roll) or the "
        "package's default (each joint's mean rotation)",
    )
    parser.add_argument("--n-per-style", type=int, default=6)
    parser.add_argument(
        "--cache-dir", default=str(Path(tempfile.gettempdir()) / "sklearn_crbm_issue15")
    )
    parser.add_argument(
        "--output",
        default=str(REPO / "benchmarks" / "results" / "generation_seeds.json"),
    )
    args = parser.parse_args(argv)

    cmu = load_cmu35(args.data_home)
    # the paper's encoding, in which the tables of the README were measured,
    # or the package's default one
    paper = dict(reference="rest", roll="taylor") if args.encoding == "paper" else {}
    preprocessor = make_motion_preprocessor(cmu.skeleton, **paper)
    motion = Motion(
        cmu.data, cmu.sequence_ids, cmu.motion, preprocessor, cmu.frame_rate
    )
    real = real_statistics(motion)
    print(
        "real trials: "
        + "; ".join(
            f"{s} leg amplitude {real[s]['amplitude']:.2f}, step frequency "
            f"{real[s]['frequency']:.2f} Hz"
            for s in STYLES
        )
    )
    n_frames = max(WINDOWS.values())
    rows = []
    for name in args.models:
        for seed in args.seeds:
            crbm, seconds = cached_model(
                args.cache_dir,
                model(name, seed, args.n_iter, args.n_components),
                motion.Z.astype(np.float32),
                motion.ids,
            )
            seeds, seed_styles = draw_seeds(
                motion,
                args.n_per_style,
                crbm.history_length,
                np.random.default_rng(seed),
            )
            generated = crbm.sample(n_frames, history=seeds, random_state=seed)
            row = dict(model=name, seed=seed, train_seconds=seconds)
            for window, end in WINDOWS.items():
                stats = verdicts(motion, generated, n_frames, end, seed_styles, real)
                row[window] = summary(stats, seed_styles)
            rows.append(row)
            report_row(row, args.n_per_style)
    print(markdown_table(rows, args.n_per_style))
    output = Path(args.output)
    output.parent.mkdir(parents=True, exist_ok=True)
    output.write_text(json.dumps(dict(args=vars(args), real=real, rows=rows), indent=2))
    print(f"\nwrote {output}")
    return rows


def report_row(row, n):
    cells = []
    for window in WINDOWS:
        for style in STYLES:
            r = row[window][style]
            cells.append(
                f"{window} {style}: {r['passes']}/{n} pass (style {r['keeps_style']}, "
                f"lively {r['lively']}, in step {r['in_step']}, blown {r['blown']}; "
                f"amplitude {min(r['amplitude']):.2f}-{max(r['amplitude']):.2f})"
            )
    print(
        f"{row['model']} seed {row['seed']}:\n    " + "\n    ".join(cells), flush=True
    )


def markdown_table(rows, n):
    """One line per model and seed: passes, leg amplitude and step frequency."""

    def spread(values):
        return f"{min(values):.2f}-{max(values):.2f}"

    lines = [
        "",
        "| model | seed | fit s | window | walks pass | jogs pass "
        "| leg amplitude walk / jog | step frequency walk / jog (Hz) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        for window in WINDOWS:
            walk, jog = (row[window][style] for style in STYLES)
            lines.append(
                f"| {row['model']} | {row['seed']} | {row['train_seconds']:.1f} "
                f"| {window} | {walk['passes']}/{n} | {jog['passes']}/{n} "
                f"| {spread(walk['amplitude'])} / {spread(jog['amplitude'])} "
                f"| {spread(walk['frequency'])} / {spread(jog['frequency'])} |"
            )
    return "\n".join(lines)


if __name__ == "__main__":
    main()
