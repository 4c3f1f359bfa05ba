"""The two-level model: stable generated motion on MIT walking and CMU 35 (§4.2, §5).

Protocol (Taylor, Hinton & Roweis 2006, §4.2 and §5): a StackedCRBM of two
200-hidden-unit layers of order 3 (the first Gaussian on the preprocessed
motion, the second binary on the first layer's hidden probabilities) is
trained greedily, ``--n-iter`` epochs per layer (500), on

- ``mit``: Taylor's MIT walking data (3 sequences, 3826 frames, 49 dims),
  the data of the original two-level demo (the paper's §4.2 used Hsu's
  walk/jog file ``Jog1_M``, which is not public);
- ``cmu``: the 33 walks and jogs of CMU subject 35 (2813 frames, 62 dims).

Each model generates top-down, as Taylor's ``gen2.m`` did, 300 frames from
each of ``--n-per-style`` seeds per style (``2 * order`` real frames), and
the last 100 frames are judged with the statistics of
``generation_styles.py``: style (CMU only: nearest training style on speed
and gait frequency), dies out, stalls, blows up (|z| > 10), speed, gait
frequency, leg amplitude, and the spectral similarity to the real motion of
the seed's style.  "Stable" means neither died out, stalled nor blew up; on
CMU, "keeps" also asks for the seed's style.

Variants: ``faithful`` (the paper's schedule for both layers) and
``noisy-history`` (both layers trained with ``history_noise``,
``--history-noise``, default 0.4).

Run from the repository root, e.g.::

    python benchmarks/generation_stacked.py
    python benchmarks/generation_stacked.py --datasets mit --n-iter 500

Prints a table and writes JSON to ``benchmarks/results/generation_stacked.json``.
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

from sklearn_crbm._stacked import StackedCRBM  # noqa: E402
from sklearn_crbm.datasets import load_mit_walk  # noqa: E402
from sklearn_crbm.preprocessing import make_motion_preprocessor  # noqa: E402


def load_motion(name, data_home):
    if name == "cmu":
        motion, _ = styles.load_cmu_motion(data_home)
        return motion, ("walk", "jog")
    mit = load_mit_walk(data_home)
    pre = make_motion_preprocessor(mit.skeleton)
    motion = styles.Motion(
        mit.data, mit.sequence_ids, mit.motion, pre, mit.frame_rate, styles.MIT_LEGS
    )
    return motion, ("walk",)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data-home", default=styles.DEFAULT_DATA_HOME)
    parser.add_argument(
        "--datasets", nargs="+", default=["mit", "cmu"], choices=["mit", "cmu"]
    )
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    parser.add_argument(
        "--variants",
        nargs="+",
        default=list(styles.VARIANTS),
        choices=list(styles.VARIANTS),
    )
    parser.add_argument("--history-noise", type=float, default=0.4)
    parser.add_argument("--n-iter", type=int, default=500)
    parser.add_argument("--n-per-style", type=int, default=6)
    parser.add_argument("--n-frames", type=int, default=300)
    parser.add_argument(
        "--cache-dir",
        default=str(Path(tempfile.gettempdir()) / "sklearn_crbm_generation"),
    )
    parser.add_argument(
        "--output", default=str(styles.RESULTS / "generation_stacked.json")
    )
    args = parser.parse_args(argv)

    rows, details = [], []
    for dataset in args.datasets:
        motion, style_names = load_motion(dataset, args.data_home)
        print(
            f"{dataset}: {motion.Z.shape[0]} frames, {motion.Z.shape[1]} dims; legs: "
            f"{', '.join(motion.legs)}",
            flush=True,
        )
        train = motion.train_stats
        for style in style_names:
            mine = motion.styles == style
            print(
                f"  real {style}: speed {train['speed'][mine].mean():.2f}, gait "
                f"frequency {np.nanmean(train['frequency'][mine]):.2f} Hz, leg "
                f"amplitude {train['amplitude'][mine].mean():.2f}",
                flush=True,
            )
        for variant in args.variants:
            params = styles.variant_params(variant, args.history_noise)
            for seed in args.seeds:
                stack = StackedCRBM(
                    (200, 200), order=3, n_iter=args.n_iter, random_state=seed, **params
                )
                stack, seconds = styles.cached_fit(
                    args.cache_dir, stack, motion.Z.astype(np.float32), motion.ids
                )
                rng = np.random.default_rng(seed)
                seeds, seed_styles = styles.draw_seeds(
                    motion,
                    args.n_per_style,
                    stack.history_length,
                    rng,
                    styles=style_names,
                )
                start = time.perf_counter()
                generated = stack.sample(
                    args.n_frames, history=seeds, random_state=seed
                )
                generation_seconds = time.perf_counter() - start
                stats = styles.judge(motion, generated, args.n_frames, seed_styles)
                row = {
                    "dataset": dataset,
                    "variant": variant,
                    "seed": seed,
                    "train_seconds": seconds,
                    "generation_seconds": generation_seconds,
                }
                for style in style_names:
                    summary = styles.summarise(stats, seed_styles, styles=(style,))[
                        style
                    ]
                    mine = seed_styles == style
                    summary["stable"] = int(
                        (~stats["dead"] & ~stats["stalled"] & ~stats["blown"])[
                            mine
                        ].sum()
                    )
                    row[style] = summary
                rows.append(row)
                details.append(
                    {
                        "dataset": dataset,
                        "variant": variant,
                        "seed": seed,
                        "sequences": styles.per_sequence(stats, seed_styles),
                    }
                )
                print(
                    f"  {dataset} {variant} seed {seed}: trained in {seconds:.0f}s, "
                    f"generated in {generation_seconds:.1f}s",
                    flush=True,
                )

    print(
        f"\n§4.2/§5 two-level model: {args.n_per_style} sequences of {args.n_frames} "
        f"frames per style ({args.n_iter} epochs per layer); last 100 frames judged"
    )
    header = (
        f"{'data':<4} {'variant':<14} {'seed':>4} {'style':<5} | {'stable':>6} "
        f"{'keeps':>5} {'dead':>4} {'stall':>5} {'blown':>5} | {'speed':>5} "
        f"{'freq':>5} {'amp':>5} {'sim':>5}"
    )
    print(header)
    print("-" * len(header))
    for r in rows:
        for style in ("walk", "jog"):
            if style not in r:
                continue
            s = r[style]
            print(
                f"{r['dataset']:<4} {r['variant']:<14} {r['seed']:>4} {style:<5} | "
                f"{s['stable']:>4}/{s['n']} {s['keeps']:>5} {s['dead']:>4} {s['stalled']:>5} "
                f"{s['blown']:>5} | {s['speed']:>5.2f} {s['frequency']:>5.2f} "
                f"{s['amplitude']:>5.2f} {s['similarity']:>5.2f}"
            )
    output = Path(args.output)
    output.parent.mkdir(parents=True, exist_ok=True)
    output.write_text(
        json.dumps({"args": vars(args), "rows": rows, "sequences": details}, indent=2)
    )
    print(f"\nwrote {output}")
    return rows


if __name__ == "__main__":
    main()
