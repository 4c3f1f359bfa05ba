"""Memory (and time) of fit: synthetic frames per order, and a whole corpus.

``--orders``: one epoch of a 200-unit CRBM on ``--frames`` (10^6) synthetic
float32 frames of 62 dims; the peak ``fit`` adds (``tracemalloc``; RSS
``VmHWM``), at most 150 MB.  ``--corpus`` (``bandai_dataset2``): every take
read, then the default ``make_motion_preprocessor`` and ``fit`` (``factored``:
``FactoredCRBM``, one label per content-style pair; ``crbm``:
``ConditionalRBM``; default BLAS threads): seconds and peak RSS added, per
100,000 frames and for dataset-2's 384,931 (training in proportion to the
schedule's updates).  Budgets 15 min, data + 500 MB.  Fresh processes::

    python benchmarks/bench_memory.py --orders 1 3 6 12 24    # a minute
    python benchmarks/bench_memory.py --orders --corpus ../shared/data/bandai_dataset2
"""

import math
import re
import time
import tracemalloc
from contextlib import suppress
from pathlib import Path

import numpy as np
import sklearn
from _common import announce, child_json, parser, print_table, write_json

from sklearn_crbm import ConditionalRBM, FactoredCRBM
from sklearn_crbm._engines._training import UpdateBudget
from sklearn_crbm.datasets import read_bvh_folder
from sklearn_crbm.models._factored import balanced_frames
from sklearn_crbm.preprocessing import make_motion_preprocessor
from sklearn_crbm.utils._sequences import check_sequence_ids

DATASET2, TAKE = 384_931, re.compile(r"^[^_]+_(.+)_\d+$")  # dataset-2_{pair}_{take}


def rss_mb(key="VmRSS", reset=False):
    """/proc/self/status's ``key`` in MB (``reset``: the peak RSS set to the RSS)."""
    with suppress(OSError):
        reset and Path("/proc/self/clear_refs").write_text("5")
    lines = Path("/proc/self/status").read_text().splitlines()
    return next(int(s.split()[1]) / 1024 for s in lines if s.startswith(key + ":"))


def in_child(call):
    """``bench_memory.<call>`` in a fresh process: the dict it returns."""
    code = f"import sys; sys.path.insert(0, {str(Path(__file__).parent)!r}); "
    code += f"import json, bench_memory as b; print(json.dumps(b.{call}))"
    return child_json(["-c", code])


def order_child(n, order, dtype):
    from _common import synthetic_motion, threadpool_limits

    X, ids = synthetic_motion(n, 62, max(1, n // 100), dtype=dtype)
    model = ConditionalRBM(200, order=order, n_iter=1, random_state=0)
    before = rss_mb(reset=True)
    tracemalloc.start()
    with threadpool_limits(1):
        model.fit(X, sequence_ids=ids)
    traced = tracemalloc.get_traced_memory()[1] / 2**20
    tracemalloc.stop()
    rss = rss_mb("VmHWM") - before
    return dict(data_mb=X.nbytes / 2**20, traced_mb=traced, peak_rss_added_mb=rss,
                within_budget="yes" if max(traced, rss) <= 150 else "NO")  # fmt: skip


def corpus_child(folder, name, max_updates=None):
    """Read, preprocess and fit on ``folder``; ``max_updates``: FactoredCRBM
    trains the epochs of ``UpdateBudget(200, max_updates=max_updates)``."""
    bunch = read_bvh_folder(folder, labels=TAKE)
    X, ids, y = bunch.data, bunch.sequence_ids, bunch.target
    model = (FactoredCRBM if name == "factored" else ConditionalRBM)(random_state=0)
    frames = check_sequence_ids(ids, len(ids)).valid_frames(model.history_length)
    if name == "factored" and model.balance_styles:  # repeated as fit repeats them
        frames = balanced_frames(frames, y[:, None] == np.unique(y))
    budget = model._update_budget if model.n_iter == "auto" else None
    if max_updates:  # the schedule FactoredCRBM's n_iter="auto" would have
        budget = UpdateBudget(200, max_updates=max_updates)
        model.set_params(n_iter=budget.n_epochs(len(frames), model.batch_size))
    before, start = rss_mb(reset=True), time.perf_counter()
    with sklearn.config_context(enable_metadata_routing=True):
        pre = make_motion_preprocessor(bunch.skeleton)
        Z = pre.fit_transform(X, sequence_ids=ids)
    middle = time.perf_counter()
    model.fit(Z, y if name == "factored" else None, sequence_ids=ids)
    fit_s, added = time.perf_counter() - middle, rss_mb("VmHWM") - before
    pre_s, ratio, size = middle - start, DATASET2 / len(ids), model.batch_size
    updates, more = model.n_iter_ * math.ceil(len(frames) / size), len(frames) * ratio
    epochs = budget.n_epochs(more, size) if budget else model.n_iter_
    more_s = fit_s * epochs * math.ceil(more / size) / updates
    per, within = 100_000 / len(ids), pre_s + fit_s <= 900 and added <= 500
    load = " ".join(Path("/proc/loadavg").read_text().split()[:3])
    return dict(model=name, frames=len(ids), data_mb=X.nbytes / 2**20,
                epochs=model.n_iter_, updates=updates, preprocess_s=pre_s,
                seconds=pre_s + fit_s, peak_rss_added_mb=added,
                s_per_100k=(pre_s + fit_s) * per, mb_per_100k=added * per,
                dataset2_s=pre_s * ratio + more_s, dataset2_mb=added * ratio,
                within_budget="yes" if within else "NO", load=load)  # fmt: skip


def main(argv=None):
    p = parser(__doc__, seeds=None)
    p.add_argument("--frames", type=int, default=1_000_000)
    p.add_argument("--orders", type=int, nargs="*", default=[1, 3, 6, 12])
    p.add_argument("--dtype", default="float32")
    p.add_argument("--corpus", default=None, help="a folder of BVH takes")
    p.add_argument("--models", nargs="+", default=["factored", "crbm"])
    p.add_argument("--factored-updates", type=int, help="UpdateBudget(200, this)")
    args = p.parse_args(argv)
    announce()
    rows, tables = [], []
    for order in args.orders:
        rows.append(in_child(f"order_child({args.frames}, {order}, {args.dtype!r})"))
        rows[-1].update(order=order, frames=args.frames, dtype=args.dtype)
    columns = [("frames", "frames", ",d"), "dtype", "order",
               ("data_mb", "data MB", ".0f"), ("traced_mb", "traced MB", ".1f"),
               ("peak_rss_added_mb", "peak RSS MB", ".1f"),
               ("within_budget", "<= 150 MB", "s")]  # fmt: skip
    if rows:
        title = "Memory fit adds, 62 dims, 200 hidden, 1 epoch"
        tables.append(print_table(rows, columns, title=title))
    for name in args.models if args.corpus else []:
        updates = args.factored_updates if name == "factored" else None
        rows.append(in_child(f"corpus_child({args.corpus!r}, {name!r}, {updates!r})"))
    columns = ["model", ("frames", "frames", ",d"), ("data_mb", "data MB", ".0f"),
               "epochs", ("updates", "updates", ",d"), ("preprocess_s", "pre s", ".0f"),
               ("seconds", "pre+fit s", ".0f"), ("peak_rss_added_mb", "adds MB", ".0f"),
               ("s_per_100k", "s/100k", ".0f"), ("mb_per_100k", "MB/100k", ".0f"),
               ("dataset2_s", "385k: s", ".0f"), ("dataset2_mb", "385k: MB", ".0f"),
               ("within_budget", "15 min, +500 MB", "s"), "load"]  # fmt: skip
    if args.corpus:
        title = f"Default preprocessing and fit of {args.corpus}"
        tables.append(print_table(rows[len(args.orders) :], columns, title=title))
    write_json("bench_memory", args.output, args=vars(args), rows=rows, tables=tables)


if __name__ == "__main__":
    main()
