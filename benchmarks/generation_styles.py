"""Walking and jogging from one model: the paper's first demonstration (§4.1).

Protocol (Taylor, Hinton & Roweis 2006, §4.1, with the bar of issue 5):

- preprocess all 33 CMU subject 35 trials (23 walks, 10 jogs, 2813 frames):
  exponential maps, body-centred root, z-scores;
- train one ConditionalRBM, 200 hidden units, order 3, ``--n-iter`` epochs
  (1000), for every training seed in ``--seeds``;
- per training seed, draw 6 walk seeds and 6 jog seeds (``order``
  consecutive real frames from a random walk / jog trial) and generate 300
  frames from each with the original scheme (30 Gibbs iterations per frame,
  visible means, a final mean-field step);
- judge the last 100 frames of every generated sequence:
  * style: nearest training style (centroid of the 33 trials) on mean
    forward speed (``root_dforward`` in ASF units per frame) and gait
    frequency of the hip and knee channels;
  * dies out: leg amplitude (RMS of the per-channel standard deviation of
    the hip and knee exp-map channels, z-scored units) below half the mean
    amplitude of the training trials;
  * stalls: mean forward speed below half that of the training walks
    (standing or shuffling in place, whatever the legs do);
  * blows up: any generated value beyond |z| > 10 anywhere in the 300 frames;
  * keeps its style: the seed's style, and neither died out, stalled nor
    blew up;
- the bar, for every training seed: at least 5 of 6 sequences of each style
  keep their style, none blows up, at most one per style dies out.

Variants (``--variants``):

``faithful``
    The original code's schedule: CD-1, learning rate 1e-3, momentum 0.9
    after 5 epochs, weight decay 2e-4, minibatches of 100 frames.
``noisy-history``
    The same, trained with ``history_noise`` (``--history-noise``, default
    0.8): Gaussian noise on the past frames that feed the directed
    connections, so the model learns to pull a drifting history back to the
    data instead of extrapolating it (see the ConditionalRBM docstring).

Also reported: the spectral similarity (Bhattacharyya coefficient of
channel-by-frequency power spectra) of each generated sequence to the real
trials of its seed style.

Run from the repository root, e.g.::

    python benchmarks/generation_styles.py
    python benchmarks/generation_styles.py --seeds 0 --variants faithful

Trained models are cached with joblib in ``--cache-dir`` (keyed by the
estimator's parameters and the data, shared with the other generation
benchmarks).  Prints a table and
writes JSON to ``benchmarks/results/generation_styles.json``.
"""

import os

# One BLAS thread per process: the matrices are small, and threads only
# fight on a shared machine.  Must be set before numpy is imported.
for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import hashlib  # noqa: E402
import json  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import joblib  # noqa: E402
import numpy as np  # noqa: E402
import sklearn  # noqa: E402
from _splits import EARLIER_DEFAULTS  # noqa: E402

from sklearn_crbm import ConditionalRBM  # noqa: E402
from sklearn_crbm.datasets import bone_columns, load_cmu35  # noqa: E402
from sklearn_crbm.metrics import (  # noqa: E402
    forward_speed,
    gait_statistics,
    motion_amplitude,
    nearest_style,
    spectral_similarity,
)
from sklearn_crbm.preprocessing import make_motion_preprocessor  # noqa: E402
from sklearn_crbm.utils import check_sequence_ids, random_windows  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
RESULTS = REPO / "benchmarks" / "results"
DEFAULT_DATA_HOME = os.environ.get(
    "SKLEARN_CRBM_DATA", str(REPO.parent / "shared" / "data")
)
CMU_LEGS = ("lfemur", "rfemur", "ltibia", "rtibia")  # hips and knees
MIT_LEGS = ("lhip", "rhip", "lknee", "rknee")
BLOW_UP = 10.0
VARIANTS = {
    "faithful": {"history_noise": 0.0},
    "noisy-history": {"history_noise": None},  # filled from --history-noise
}


# ------------------------------------------------------------------ data
class Motion:
    """Preprocessed motion and the statistics of its trials."""

    def __init__(
        self, data, sequence_ids, styles, preprocessor, frame_rate, legs=CMU_LEGS
    ):
        self.preprocessor = preprocessor
        self.ids = sequence_ids
        self.styles = np.asarray(styles, dtype=object)
        self.frame_rate = frame_rate
        with sklearn.config_context(enable_metadata_routing=True):
            self.Z = preprocessor.fit_transform(data, sequence_ids=sequence_ids)
        self.names = np.asarray(preprocessor.get_feature_names_out(), dtype=object)
        self.root_names = np.asarray(
            preprocessor[:-1].get_feature_names_out(), dtype=object
        )
        self.leg_bones = legs
        self.legs = list(self.names[bone_columns(self.names, legs)])
        self.train_stats = self.statistics(self.Z, self.ids)

    def statistics(self, Z, ids, last_frames=None):
        """Per-sequence gait statistics, speed, leg amplitude and max |z|.

        ``gait`` (z-scored speed and gait frequency) is what styles are
        classified on; ``speed`` is the same speed in the encoder's units
        (ASF units per frame), for the table and the stall criterion.
        """
        Z = np.asarray(Z, dtype=np.float64)
        finite = np.clip(np.nan_to_num(Z, nan=0.0), -1e3, 1e3)
        unscaled = self.preprocessor[-1].inverse_transform(finite)
        gait = gait_statistics(
            finite,
            sequence_ids=ids,
            feature_names=self.names,
            legs=self.leg_bones,
            frame_rate=self.frame_rate,
            last_frames=last_frames,
        )
        stats = {
            "gait": gait,
            "speed": forward_speed(
                unscaled,
                sequence_ids=ids,
                feature_names=self.root_names,
                last_frames=last_frames,
            ),
            "frequency": gait[:, 1],
            "amplitude": motion_amplitude(
                finite,
                sequence_ids=ids,
                feature_names=self.names,
                features=self.legs,
                last_frames=last_frames,
            ),
        }
        sequences = check_sequence_ids(ids, len(Z))
        stats["max_abs_z"] = np.array(
            [
                np.max(np.abs(np.nan_to_num(Z[a:b], nan=np.inf)))
                for a, b in zip(sequences.starts, sequences.stops, strict=True)
            ]
        )
        return stats

    def window_amplitude(self, window):
        """Mean leg amplitude of the real trials over windows of ``window`` frames."""
        sequences = check_sequence_ids(self.ids, len(self.Z))
        rows = [
            np.arange(s, s + window)
            for a, b in zip(sequences.starts, sequences.stops, strict=True)
            for s in range(a, b - window + 1, max(window // 2, 1))
        ]
        if not rows:
            return float(self.train_stats["amplitude"].mean())
        windows = self.Z[np.concatenate(rows)]
        ids = np.repeat(np.arange(len(rows)), window)
        return float(
            motion_amplitude(
                windows, sequence_ids=ids, feature_names=self.names, features=self.legs
            ).mean()
        )


def load_cmu_motion(data_home):
    cmu = load_cmu35(data_home)
    pre = make_motion_preprocessor(cmu.skeleton)
    return Motion(cmu.data, cmu.sequence_ids, cmu.motion, pre, cmu.frame_rate), cmu


def draw_seeds(motion, n_per_style, width, rng, styles=("walk", "jog")):
    """``width`` consecutive real frames from random trials of each style."""
    seeds = [
        random_windows(
            motion.Z,
            sequence_ids=motion.ids,
            width=width,
            n_windows=n_per_style,
            sequences=np.flatnonzero(motion.styles == style),
            random_state=rng,
        )
        for style in styles
    ]
    seed_styles = np.repeat(np.asarray(styles, dtype=object), n_per_style)
    return np.concatenate(seeds), seed_styles


def judge(motion, generated, n_frames, seed_styles, last_frames=100):
    """Statistics and verdicts of every generated sequence."""
    n_sequences = len(seed_styles)
    ids = np.repeat(np.arange(n_sequences), n_frames)
    stats = motion.statistics(generated, ids, last_frames=last_frames)
    stats["max_abs_z"] = np.abs(
        np.nan_to_num(generated, nan=np.inf).reshape(n_sequences, n_frames, -1)
    ).max(axis=(1, 2))
    train = motion.train_stats
    stats["style"] = nearest_style(stats["gait"], train["gait"], motion.styles)
    walk_speed = train["speed"][motion.styles == "walk"].mean()
    stats["dead"] = stats["amplitude"] < 0.5 * train["amplitude"].mean()
    stats["stalled"] = stats["speed"] < 0.5 * walk_speed
    stats["blown"] = stats["max_abs_z"] > BLOW_UP
    stats["keeps"] = (
        (stats["style"] == seed_styles)
        & ~stats["dead"]
        & ~stats["stalled"]
        & ~stats["blown"]
    )
    similarity = np.full(n_sequences, np.nan)
    finite = (
        np.isfinite(generated).all(axis=1).reshape(n_sequences, n_frames).all(axis=1)
    )
    for style in np.unique(seed_styles):
        real = np.isin(motion.ids, np.flatnonzero(motion.styles == style))
        chosen = np.flatnonzero((seed_styles == style) & finite & ~stats["blown"])
        if len(chosen) == 0:
            continue
        rows = (chosen[:, None] * n_frames + np.arange(n_frames)).ravel()
        similarity[chosen] = spectral_similarity(
            generated[rows],
            motion.Z[real],
            sequence_ids=np.repeat(np.arange(len(chosen)), n_frames),
            reference_sequence_ids=motion.ids[real],
            last_frames=last_frames,
        )
    stats["similarity"] = similarity
    return stats


def summarise(stats, seed_styles, styles=("walk", "jog")):
    row = {}
    for style in styles:
        mine = seed_styles == style
        row[style] = {
            "n": int(mine.sum()),
            "keeps": int(stats["keeps"][mine].sum()),
            "other_style": int((stats["style"][mine] != style).sum()),
            "dead": int(stats["dead"][mine].sum()),
            "stalled": int(stats["stalled"][mine].sum()),
            "blown": int(stats["blown"][mine].sum()),
            "speed": float(np.nanmean(stats["speed"][mine])),
            "frequency": float(np.nanmean(stats["frequency"][mine])),
            "amplitude": float(np.nanmean(stats["amplitude"][mine])),
            "similarity": float(np.nanmean(stats["similarity"][mine]))
            if np.isfinite(stats["similarity"][mine]).any()
            else float("nan"),
        }
    row["passes"] = bool(
        all(
            row[s]["keeps"] >= row[s]["n"] - 1
            and row[s]["blown"] == 0
            and row[s]["dead"] <= 1
            for s in styles
        )
    )
    return row


def per_sequence(stats, seed_styles):
    keys = ("speed", "frequency", "amplitude", "max_abs_z", "similarity")
    out = []
    for i, style in enumerate(seed_styles):
        item = {
            "seed_style": str(style),
            "style": None if stats["style"][i] is None else str(stats["style"][i]),
        }
        item.update({k: float(stats[k][i]) for k in keys})
        item.update(
            {k: bool(stats[k][i]) for k in ("dead", "stalled", "blown", "keeps")}
        )
        out.append(item)
    return out


# -------------------------------------------------------------- training
def cached_fit(cache_dir, estimator, X, ids):
    """Fit ``estimator`` on ``X``, or load the same fit from ``cache_dir``.

    The key is the estimator's class and parameters and a hash of the data,
    so any script asking for the same model gets the same file.
    """
    digest = hashlib.sha1()
    digest.update(type(estimator).__name__.encode())
    digest.update(repr(sorted(estimator.get_params().items())).encode())
    digest.update(np.ascontiguousarray(X).tobytes())
    digest.update(np.ascontiguousarray(ids).tobytes())
    path = (
        Path(cache_dir) / f"{type(estimator).__name__}_{digest.hexdigest()[:20]}.joblib"
    )
    if path.exists():
        return joblib.load(path)
    start = time.perf_counter()
    estimator.fit(X, sequence_ids=ids)
    result = (estimator, time.perf_counter() - start)
    path.parent.mkdir(parents=True, exist_ok=True)
    joblib.dump(result, path)
    return result


def train_crbm(cache_dir, Z, ids, seed, n_iter, params):
    model = ConditionalRBM(200, order=3, n_iter=n_iter, random_state=seed, **params)
    return cached_fit(cache_dir, model, Z.astype(np.float32), ids)


def variant_params(name, history_noise):
    # the defaults of when these were measured, with the variant's noise
    params = {**EARLIER_DEFAULTS, **VARIANTS[name]}
    if params["history_noise"] is None:
        params["history_noise"] = history_noise
    return params


def print_table(rows, title):
    print(f"\n{title}")
    header = (
        f"{'variant':<14} {'seed':>4} | {'walk keep':>9} {'->jog':>5} {'dead':>4} {'stall':>5} "
        f"{'blown':>5} {'speed':>5} {'freq':>5} {'sim':>5} | {'jog keep':>8} {'->walk':>6} "
        f"{'dead':>4} {'stall':>5} {'blown':>5} {'speed':>5} {'freq':>5} {'sim':>5} | pass"
    )
    print(header)
    print("-" * len(header))
    for r in rows:
        w, j = r["walk"], r["jog"]
        print(
            f"{r['variant']:<14} {r['seed']:>4} | {w['keeps']:>7}/6 {w['other_style']:>5} {w['dead']:>4} "
            f"{w['stalled']:>5} {w['blown']:>5} {w['speed']:>5.2f} {w['frequency']:>5.2f} "
            f"{w['similarity']:>5.2f} | {j['keeps']:>6}/6 {j['other_style']:>6} {j['dead']:>4} "
            f"{j['stalled']:>5} {j['blown']:>5} {j['speed']:>5.2f} {j['frequency']:>5.2f} "
            f"{j['similarity']:>5.2f} | {'yes' if r['passes'] else 'NO'}"
        )


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data-home", default=DEFAULT_DATA_HOME)
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument(
        "--variants", nargs="+", default=list(VARIANTS), choices=list(VARIANTS)
    )
    parser.add_argument("--n-iter", type=int, default=1000)
    parser.add_argument("--history-noise", type=float, default=0.8)
    parser.add_argument("--n-per-style", type=int, default=6)
    parser.add_argument("--n-frames", type=int, default=300)
    parser.add_argument("--n-gibbs", type=int, default=30)
    parser.add_argument(
        "--cache-dir",
        default=str(Path(tempfile.gettempdir()) / "sklearn_crbm_generation"),
    )
    parser.add_argument("--output", default=str(RESULTS / "generation_styles.json"))
    args = parser.parse_args(argv)

    motion, _ = load_cmu_motion(args.data_home)
    train = motion.train_stats
    print(
        "training trials: mean speed walk {:.2f} jog {:.2f}; gait frequency walk {:.2f} Hz "
        "jog {:.2f} Hz; leg amplitude {:.2f}".format(
            train["speed"][motion.styles == "walk"].mean(),
            train["speed"][motion.styles == "jog"].mean(),
            np.nanmean(train["frequency"][motion.styles == "walk"]),
            np.nanmean(train["frequency"][motion.styles == "jog"]),
            train["amplitude"].mean(),
        )
    )
    rows, details = [], []
    for variant in args.variants:
        params = variant_params(variant, args.history_noise)
        for seed in args.seeds:
            model, seconds = train_crbm(
                args.cache_dir, motion.Z, motion.ids, seed, args.n_iter, params
            )
            rng = np.random.default_rng(seed)
            seeds, seed_styles = draw_seeds(
                motion, args.n_per_style, model.history_length, rng
            )
            start = time.perf_counter()
            generated = model.sample(
                args.n_frames, history=seeds, n_gibbs=args.n_gibbs, random_state=seed
            )
            generation_seconds = time.perf_counter() - start
            stats = judge(motion, generated, args.n_frames, seed_styles)
            row = {
                "variant": variant,
                "seed": seed,
                "params": params,
                "train_seconds": seconds,
                "generation_seconds": generation_seconds,
            }
            row.update(summarise(stats, seed_styles))
            rows.append(row)
            details.append(
                {
                    "variant": variant,
                    "seed": seed,
                    "sequences": per_sequence(stats, seed_styles),
                }
            )
            print(
                f"  {variant} seed {seed}: trained in {seconds:.1f}s, generated in "
                f"{generation_seconds:.1f}s, passes: {row['passes']}",
                flush=True,
            )
    print_table(
        rows,
        f"§4.1 styles: {args.n_per_style} walk- and jog-seeded sequences of "
        f"{args.n_frames} frames per training seed ({args.n_iter} epochs)",
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
