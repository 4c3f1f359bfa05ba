"""A CRBM trained on BVH walks: does its walking move every joint at the data's speed?

Protocol (issue 14): the 12 normal walks of the Bandai Namco Research Motion
dataset (``external_dev/bandai_walk_normal_train``: one actor, 27 joints with
position channels on every joint, a static ``joint_Root`` above the moving
``Hips``; 30 Hz, 224 to 285 frames each) go through the *default* pipeline,
``make_motion_preprocessor(skeleton)`` (exponential maps measured from each
joint's mean rotation, exact yaw-pitch-roll root, z-scores), and train a
``ConditionalRBM(200, order=3, history_noise=0.8, history_noise_fraction=1)``
(the CLI demo's model until the default noise changed) for
``--n-iter`` epochs.  The model generates ``--n-sequences`` sequences of
``--n-frames`` frames, seeded with windows of real training frames; the frames
go back through the exact ``inverse_transform`` to BVH channels and through
the skeleton's forward kinematics to joint positions.

Per joint, the *speed* is the mean distance a joint moves from one frame to
the next (cm per frame), averaged over all frames of all sequences:

- ``global``: in the world, as the joint walks;
- ``body``: relative to the hips (the joint's position minus the hips'),
  which is the limb's own motion without the walk's translation.

The pass mark of the issue: the generated speed within 25% of the data's for
every joint, in both.  The script also reports the frames whose joint maps
jump by more than 1 radian, and draws the generated walk next to the real
one (``--figure``).

Run from the repository root, e.g.::

    python benchmarks/generation_bandai.py
    python benchmarks/generation_bandai.py --n-iter 300 --seeds 0

``--encoding paper`` runs the same with the paper's encoding (joint rotations
from the rest pose), whose maps flip where a thigh sits near pi.

Prints a table and writes JSON to ``benchmarks/results/generation_bandai.json``
(``generation_bandai_paper.json``).
"""

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import sklearn  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import DEFAULT_DATA_HOME, print_table, write_json  # noqa: E402
from _splits import EARLIER_DEFAULTS  # noqa: E402

from sklearn_crbm import ConditionalRBM  # noqa: E402
from sklearn_crbm.datasets import read_bvh_folder  # noqa: E402
from sklearn_crbm.preprocessing import make_motion_preprocessor  # noqa: E402

FOLDER = Path("external_dev") / "bandai_walk_normal_train"
TOLERANCE = 0.25
ENCODINGS = {
    "default": {},
    # the paper's: exponential maps from the rest pose, Taylor's roll
    "paper": dict(reference="rest", roll="taylor"),
}


def load(data_home):
    walks = read_bvh_folder(Path(data_home) / FOLDER, frame_rate=30.0)
    return walks


def joint_speeds(skeleton, raw, sequence_ids, root):
    """Mean per-frame displacement of every joint, in the world and from the root.

    Returns two arrays of shape (n_bones,): global and body-relative speeds.
    """
    positions = skeleton.forward_kinematics(raw)
    body = positions - positions[:, [root]]
    same = np.diff(sequence_ids) == 0  # steps within a sequence
    step = np.linalg.norm(np.diff(positions, axis=0), axis=-1)[same]
    body_step = np.linalg.norm(np.diff(body, axis=0), axis=-1)[same]
    return step.mean(axis=0), body_step.mean(axis=0)


def map_jumps(pre, raw, sequence_ids):
    """Steps where a joint's exponential map moves by more than 1 radian (the
    root's global orientation, which the root encoder re-expresses, left out)."""
    Z = pre.named_steps["expmap"].transform(raw)
    names = pre.named_steps["expmap"].get_feature_names_out()
    root = pre.named_steps["root"].root_
    starts = [i for i, n in enumerate(names) if n.endswith("_ex") and n != f"{root}_ex"]
    maps = np.stack([Z[:, i : i + 3] for i in starts], axis=1)
    step = np.linalg.norm(np.diff(maps, axis=0), axis=-1)
    return int(np.sum(step[np.diff(sequence_ids) == 0] > 1.0))


def run(walks, *, n_iter, seed, n_sequences, n_frames, encoding):
    skeleton = walks.skeleton
    ids = walks.sequence_ids
    with sklearn.config_context(enable_metadata_routing=True):
        pre = make_motion_preprocessor(skeleton, **ENCODINGS[encoding])
        Z = pre.fit_transform(walks.data, sequence_ids=ids)
    model = ConditionalRBM(
        200, order=3, n_iter=n_iter, random_state=seed, **EARLIER_DEFAULTS
    )
    start = time.perf_counter()
    model.fit(Z.astype(np.float32), sequence_ids=ids)
    fit_seconds = time.perf_counter() - start
    generated = model.sample(n_frames, n_sequences=n_sequences, random_state=seed)
    gen_ids = np.repeat(np.arange(n_sequences), n_frames)
    with sklearn.config_context(enable_metadata_routing=True):
        raw = pre.inverse_transform(generated.astype(np.float64), sequence_ids=gen_ids)
    root = skeleton.bone_names.index(pre.named_steps["root"].root_)
    data_global, data_body = joint_speeds(skeleton, walks.data, ids, root)
    gen_global, gen_body = joint_speeds(skeleton, raw, gen_ids, root)
    return dict(
        pre=pre,
        raw=raw,
        gen_ids=gen_ids,
        root=root,
        n_features=Z.shape[1],
        fit_seconds=fit_seconds,
        data_global=data_global,
        data_body=data_body,
        gen_global=gen_global,
        gen_body=gen_body,
        data_jumps=map_jumps(pre, walks.data, ids),
        generated_jumps=map_jumps(pre, raw, gen_ids),
    )


def table(walks, result):
    skeleton = walks.skeleton
    rows = []
    body = skeleton.descendants(skeleton.bone_names[result["root"]])
    for name in body:
        j = skeleton.bone_names.index(name)
        row = dict(
            joint=name,
            data_global=result["data_global"][j],
            gen_global=result["gen_global"][j],
            ratio_global=result["gen_global"][j] / result["data_global"][j],
        )
        if j != result["root"]:
            row.update(
                data_body=result["data_body"][j],
                gen_body=result["gen_body"][j],
                ratio_body=result["gen_body"][j] / result["data_body"][j],
            )
        rows.append(row)
    return rows


def passes(rows):
    ratios = [r[k] for r in rows for k in ("ratio_global", "ratio_body") if k in r]
    return bool(all(abs(r - 1.0) <= TOLERANCE for r in ratios)), ratios


def draw(walks, result, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from sklearn_crbm.plotting import plot_motion_strip

    first = walks.sequence_ids == 0
    generated = result["raw"][result["gen_ids"] == 0]
    fig, axes = plt.subplots(2, 1, figsize=(14, 5.5))
    plot_motion_strip(walks.skeleton, walks.data[first][:120], step=6, ax=axes[0])
    axes[0].set_title("real walk (Bandai Namco, 30 Hz), every 6th frame")
    plot_motion_strip(walks.skeleton, generated[:120], step=6, ax=axes[1])
    axes[1].set_title("generated by the CRBM, every 6th frame")
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    print(f"wrote {path}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data-home", default=str(DEFAULT_DATA_HOME))
    parser.add_argument("--n-iter", type=int, default=1000)
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    parser.add_argument("--n-sequences", type=int, default=10)
    parser.add_argument("--n-frames", type=int, default=300)
    parser.add_argument(
        "--encoding",
        choices=list(ENCODINGS),
        default="default",
        help="preprocessing: the default, or the paper's (joint rotations from "
        "the rest pose, whose maps flip near pi)",
    )
    parser.add_argument("--figure", default=None, help="PNG of real and generated")
    parser.add_argument("--output", default=None, help="JSON file to write")
    args = parser.parse_args(argv)

    walks = load(args.data_home)
    print(
        f"{len(walks.sequence_names)} walks, {len(walks.data)} frames at "
        f"{walks.frame_rate:g} Hz, {walks.data.shape[1]} raw channels"
    )
    runs = []
    for seed in args.seeds:
        result = run(
            walks,
            n_iter=args.n_iter,
            seed=seed,
            n_sequences=args.n_sequences,
            n_frames=args.n_frames,
            encoding=args.encoding,
        )
        rows = table(walks, result)
        ok, ratios = passes(rows)
        print_table(
            rows,
            [
                ("joint", "joint", "s"),
                ("data_global", "data cm/frame", ".2f"),
                ("gen_global", "generated", ".2f"),
                ("ratio_global", "ratio", ".2f"),
                ("data_body", "data, from hips", ".2f"),
                ("gen_body", "generated", ".2f"),
                ("ratio_body", "ratio", ".2f"),
            ],
            title=(
                f"seed {seed}, {args.encoding} encoding: {result['n_features']} "
                "channels, "
                f"{args.n_iter} epochs in {result['fit_seconds']:.0f} s; map jumps "
                f"> 1 rad: data {result['data_jumps']}, generated "
                f"{result['generated_jumps']}"
            ),
        )
        print(
            f"seed {seed}: every joint within {TOLERANCE:.0%}: {ok} "
            f"(ratios {min(ratios):.2f} to {max(ratios):.2f})"
        )
        if args.figure and seed == args.seeds[0]:
            draw(walks, result, args.figure)
        runs.append(
            dict(
                seed=seed,
                passes=ok,
                min_ratio=min(ratios),
                max_ratio=max(ratios),
                fit_seconds=result["fit_seconds"],
                n_features=result["n_features"],
                data_map_jumps=result["data_jumps"],
                generated_map_jumps=result["generated_jumps"],
                joints=rows,
            )
        )
    write_json(
        "generation_bandai"
        if args.encoding == "default"
        else "generation_bandai_paper",
        dict(
            encoding=args.encoding,
            n_iter=args.n_iter,
            n_sequences=args.n_sequences,
            n_frames=args.n_frames,
            tolerance=TOLERANCE,
            runs=runs,
        ),
        args.output,
    )


if __name__ == "__main__":
    main()
