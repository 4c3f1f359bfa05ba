"""Walk/jog transitions from hidden-unit noise: the paper's third demonstration (§4.3).

Protocol (Taylor, Hinton & Roweis 2006, §4.3): the model of §4.1 (one
ConditionalRBM, 200 hidden units, order 3, trained on the 23 walks and 10
jogs of CMU subject 35, which contain no transition between the styles)
generates long sequences with Gaussian noise of standard deviation
``hidden_noise`` added to the hidden biases each time hidden states are
chosen.  For each noise level and training seed, ``--n-sequences`` sequences
of ``--n-frames`` frames are generated (half seeded with walk frames, half
with jog frames).  Each sequence is cut into windows of ``--window`` frames
(hop ``--hop``); every window is labelled with the nearest training style
(mean forward speed and gait frequency, as in ``generation_styles.py``), or
``still`` when its forward speed is below half the walking speed or its legs
stop moving.  Reported per noise level: switches between walk and jog per
1000 frames, the share of sequences with at least one switch, the share of
windows in each state, and how many sequences blew up (|z| > 10); switches
are counted per direction (walk to jog, jog to walk).

Models come from the same cache as ``generation_styles.py`` (the
``noisy-history`` variant by default; ``--variant faithful`` for the paper's
schedule).  Run from the repository root, e.g.::

    python benchmarks/generation_transitions.py
    python benchmarks/generation_transitions.py --noise 0 1 2 --seeds 0

Prints a table and writes JSON to
``benchmarks/results/generation_transitions.json``.
"""

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))

import generation_styles as styles  # noqa: E402

from sklearn_crbm.metrics import nearest_style  # noqa: E402


def window_labels(motion, generated, n_frames, window, hop):
    """Label every window of every sequence: walk, jog, still or blown."""
    n_sequences = generated.shape[0] // n_frames
    sequences = generated.reshape(n_sequences, n_frames, -1)
    starts = np.arange(0, n_frames - window + 1, hop)
    rows = (starts[:, None] + np.arange(window)).ravel()
    windows = sequences[:, rows].reshape(n_sequences * len(starts) * window, -1)
    ids = np.repeat(np.arange(n_sequences * len(starts)), window)
    stats = motion.statistics(windows, ids)
    train = motion.train_stats
    labels = nearest_style(stats["gait"], train["gait"], motion.styles)
    walk_speed = train["speed"][motion.styles == "walk"].mean()
    # the amplitude of a short window is smaller than a trial's: compare
    # with the training trials' windows of the same length
    still = (stats["speed"] < 0.5 * walk_speed) | (
        stats["amplitude"] < 0.5 * motion.window_amplitude(window)
    )
    labels = np.where(still, "still", labels).astype(object)
    labels = np.where(stats["max_abs_z"] > styles.BLOW_UP, "blown", labels).astype(
        object
    )
    return labels.reshape(n_sequences, len(starts))


def count_switches(labels):
    """Walk->jog and jog->walk changes per sequence, ignoring still windows."""
    to_jog, to_walk = [], []
    for row in labels:
        moving = [label for label in row if label in ("walk", "jog")]
        pairs = list(zip(moving[:-1], moving[1:], strict=True))
        to_jog.append(sum(pair == ("walk", "jog") for pair in pairs))
        to_walk.append(sum(pair == ("jog", "walk") for pair in pairs))
    return np.asarray(to_jog), np.asarray(to_walk)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data-home", default=styles.DEFAULT_DATA_HOME)
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument(
        "--variant", default="noisy-history", choices=list(styles.VARIANTS)
    )
    parser.add_argument("--history-noise", type=float, default=0.8)
    parser.add_argument("--n-iter", type=int, default=1000)
    parser.add_argument(
        "--noise",
        type=float,
        nargs="+",
        default=[0.0, 1.0, 2.0, 2.5, 3.0, 4.0, 6.0, 8.0],
    )
    parser.add_argument("--n-sequences", type=int, default=12)
    parser.add_argument("--n-frames", type=int, default=1200)
    parser.add_argument("--window", type=int, default=60)
    parser.add_argument("--hop", type=int, default=30)
    parser.add_argument(
        "--cache-dir",
        default=str(Path(tempfile.gettempdir()) / "sklearn_crbm_generation"),
    )
    parser.add_argument(
        "--output", default=str(styles.RESULTS / "generation_transitions.json")
    )
    args = parser.parse_args(argv)

    motion, _ = styles.load_cmu_motion(args.data_home)
    params = styles.variant_params(args.variant, args.history_noise)
    rows = []
    for seed in args.seeds:
        model, _ = styles.train_crbm(
            args.cache_dir, motion.Z, motion.ids, seed, args.n_iter, params
        )
        rng = np.random.default_rng(seed)
        seeds, seed_styles = styles.draw_seeds(
            motion, args.n_sequences // 2, model.history_length, rng
        )
        for noise in args.noise:
            start = time.perf_counter()
            generated = model.sample(
                args.n_frames, history=seeds, hidden_noise=noise, random_state=seed
            )
            seconds = time.perf_counter() - start
            labels = window_labels(
                motion, generated, args.n_frames, args.window, args.hop
            )
            to_jog, to_walk = count_switches(labels)
            switches = to_jog + to_walk
            shares = {
                s: float(np.mean(labels == s))
                for s in ("walk", "jog", "still", "blown")
            }
            rows.append(
                {
                    "seed": seed,
                    "hidden_noise": noise,
                    "switches_per_1000_frames": float(
                        switches.mean() * 1000 / args.n_frames
                    ),
                    "sequences_with_switch": float(np.mean(switches > 0)),
                    "walk_to_jog": int(to_jog.sum()),
                    "jog_to_walk": int(to_walk.sum()),
                    "blown_sequences": int(np.any(labels == "blown", axis=1).sum()),
                    "shares": shares,
                    "generation_seconds": seconds,
                    "labels": [list(map(str, row)) for row in labels],
                    "seed_styles": list(map(str, seed_styles)),
                }
            )
            print(
                f"  seed {seed} noise {noise}: {switches.sum()} switches, "
                f"{seconds:.1f}s",
                flush=True,
            )

    print(
        f"\n§4.3 transitions: {args.n_sequences} sequences of {args.n_frames} frames per "
        f"training seed and noise level ({args.variant} model, {args.n_iter} epochs)"
    )
    header = (
        f"{'noise':>5} {'seed':>4} | {'switches/1000f':>14} {'seq. w/ switch':>14} "
        f"{'w->j':>4} {'j->w':>4} | {'walk':>5} {'jog':>5} {'still':>5} {'blown':>5}"
    )
    print(header)
    print("-" * len(header))
    for r in sorted(rows, key=lambda r: (r["hidden_noise"], r["seed"])):
        s = r["shares"]
        print(
            f"{r['hidden_noise']:>5.2f} {r['seed']:>4} | {r['switches_per_1000_frames']:>14.2f} "
            f"{r['sequences_with_switch']:>14.2f} {r['walk_to_jog']:>4} {r['jog_to_walk']:>4} | "
            f"{s['walk']:>5.2f} {s['jog']:>5.2f} "
            f"{s['still']:>5.2f} {s['blown']:>5.2f}"
        )
    output = Path(args.output)
    output.parent.mkdir(parents=True, exist_ok=True)
    output.write_text(json.dumps({"args": vars(args), "rows": rows}, indent=2))
    print(f"\nwrote {output}")
    return rows


if __name__ == "__main__":
    main()
