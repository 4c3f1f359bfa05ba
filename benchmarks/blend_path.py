"""Along the label path between two styles: what the factored CRBM's blends become.

Data, split, judge and models as in ``styles.py`` (Bandai walks, trained on
takes 001-005; ``--models`` reuses the models ``styles.py --models`` saved,
and saves those it trains).  For every pair of ``--pairs`` (default: all 21)
and every weight ``w`` of ``--weights``, ``--n-sequences`` sequences of
``--n-frames`` frames seeded with a normal walk follow the constant label
``(1 - w)`` first style + ``w`` second style; the windows from frame 100 on
are judged (``StyleJudge`` trained on all 42 real takes).

Prints, per pair and weight, the share of windows judged as the first style,
the second, the normal walk and any other style, and the share alive
against the style each window is judged as (means over ``--seeds``), and
writes JSON to ``benchmarks/results/blend_path.json``.

Run from the repository root, e.g.::

    python benchmarks/blend_path.py --seeds 0 2 --models models/ \\
        --pairs feminine/masculine exhausted/masculine --weights 0.25 0.5 0.75
"""

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import itertools  # noqa: E402
import json  # noqa: E402

import numpy as np  # noqa: E402
import sklearn  # noqa: E402
from _common import announce, parser, print_table, write_json  # noqa: E402
from styles import (  # noqa: E402
    NORMAL,
    Split,
    fitted_candidate,
    judged_blend,
    label_weights,
)

from sklearn_crbm.datasets import load_bandai_walks  # noqa: E402


def shares(verdict, first, second):
    """Shares of windows judged as each style of the pair, normal, other; alive."""
    judged = verdict.predicted
    named = {first: judged == first, second: judged == second}
    normal = judged == NORMAL
    return dict(
        first=float(named[first].mean()),
        second=float(named[second].mean()),
        normal=float(normal.mean()) if NORMAL not in named else 0.0,
        other=float(np.mean(~(named[first] | named[second] | normal))),
        alive=float(verdict.alive.mean()),
    )


def path_cells(candidate, split, pairs, weights, args, seed):
    rng = np.random.default_rng(seed)
    cells = {}
    for first, second in pairs:
        for weight in weights:
            labels = label_weights(
                split.styles, args.n_frames, first, second, blend=weight
            )
            verdict, _, _, _ = judged_blend(candidate, split, labels, args, rng)
            cells[f"{first}/{second}@{weight:g}"] = shares(verdict, first, second)
            print(f"  seed {seed} {first}/{second} at {weight:g}: done", flush=True)
    return cells


def _pairs(names, styles):
    if not names:
        return list(itertools.combinations(styles, 2))
    pairs = [tuple(name.split("/")) for name in names]
    for pair in pairs:
        if len(pair) != 2 or not set(pair) <= set(styles):
            raise SystemExit(f"--pairs: {'/'.join(pair)!r} is not two of {styles}")
    return pairs


def main(argv=None):
    p = parser(__doc__, seeds=(0,))
    p.add_argument("--pairs", nargs="+", metavar="FIRST/SECOND")
    p.add_argument("--weights", type=float, nargs="+", default=[0.25, 0.5, 0.75])
    p.add_argument("--n-frames", type=int, default=1000)
    p.add_argument("--n-sequences", type=int, default=6)
    p.add_argument("--n-iter", type=int, help="epochs (default: the package's)")
    p.add_argument("--params", type=json.loads, metavar="JSON")
    p.add_argument("--models", help="folder of models saved by styles.py --models")
    args = p.parse_args(argv)
    announce()
    sklearn.set_config(enable_metadata_routing=True)
    walks = load_bandai_walks(args.data_home)
    split = Split(walks, walks.takes[walks.sequence_ids] <= 5)
    pairs = _pairs(args.pairs, split.styles)
    results = {}
    for seed in args.seeds:
        candidate, _ = fitted_candidate("factored", split, args, seed)
        results[seed] = path_cells(candidate, split, pairs, args.weights, args, seed)
    rows = []
    for key in results[args.seeds[0]]:
        row = {"blend": key.replace("@", " at ")}
        for column in ("first", "second", "normal", "other", "alive"):
            row[column] = np.mean([results[s][key][column] for s in args.seeds])
        rows.append(row)
    print(
        f"\nFactoredCRBM, Bandai walks; label (1 - w) first + w second; "
        f"seeds {args.seeds}; {args.n_sequences} x {args.n_frames} frames\n"
    )
    columns = [("blend", "blend (first/second at w)", "s")]
    columns += [(c, f"judged {c}", ".0%") for c in ("first", "second", "normal")]
    columns += [("other", "other", ".0%"), ("alive", "alive", ".0%")]
    table = print_table(rows, columns)
    write_json("blend_path", args.output, args=vars(args), results=results, table=table)
    return results


if __name__ == "__main__":
    main()
