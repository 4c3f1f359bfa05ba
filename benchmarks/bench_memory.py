"""Memory that ConditionalRBM.fit adds on top of its data, whatever the order.

Per order (``--orders``), in a fresh process: one epoch of a 200-unit CRBM
on ``--frames`` (10^6) synthetic float32 frames of 62 dimensions; the peak
that ``fit`` adds (``tracemalloc``; RSS ``VmHWM``), at most 150 MB.

Run from the repository root (about a minute)::

    python benchmarks/bench_memory.py --orders 1 3 6 12 24
"""

from pathlib import Path

from _common import announce, child_json, parser, print_table, write_json

BUDGET_MB = 150.0

CHILD = r"""
import json, sys, tracemalloc
from pathlib import Path
sys.path.insert(0, {bench_dir!r})
import numpy as np
from threadpoolctl import threadpool_limits
from _common import synthetic_motion
from sklearn_crbm import ConditionalRBM

def status(key):
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(key + ":"):
            return int(line.split()[1]) / 1024  # MB
    return float("nan")

n, order, dtype = {n}, {order}, {dtype!r}
X, ids = synthetic_motion(n, 62, max(1, n // 100), dtype=dtype)
model = ConditionalRBM(200, order=order, n_iter=1, random_state=0)
try:
    Path("/proc/self/clear_refs").write_text("5")  # reset the peak RSS
except OSError:
    pass
rss_before, hwm_before = status("VmRSS"), status("VmHWM")
tracemalloc.start()
base, _ = tracemalloc.get_traced_memory()
with threadpool_limits(1):
    model.fit(X, sequence_ids=ids)
_, peak = tracemalloc.get_traced_memory()
tracemalloc.stop()
print(json.dumps({{
    "data_mb": X.nbytes / 2**20,
    "traced_mb": (peak - base) / 2**20,
    "rss_before_mb": rss_before,
    "peak_rss_added_mb": status("VmHWM") - rss_before,
}}))
"""


def main(argv=None):
    p = parser(__doc__, seeds=None)
    p.add_argument("--frames", type=int, default=1_000_000)
    p.add_argument("--orders", type=int, nargs="+", default=[1, 3, 6, 12])
    p.add_argument("--dtype", default="float32")
    args = p.parse_args(argv)
    announce()

    bench_dir = str(Path(__file__).resolve().parent)
    rows = []
    for order in args.orders:
        code = CHILD.format(
            bench_dir=bench_dir, n=args.frames, order=order, dtype=args.dtype
        )
        row = child_json(["-c", code])
        row.update(order=order, frames=args.frames, dtype=args.dtype)
        added = max(row["traced_mb"], row["peak_rss_added_mb"])
        row["within_budget"] = "yes" if added <= BUDGET_MB else "NO"
        rows.append(row)
        print(f"  order {order}: {row['traced_mb']:.1f} MB traced", flush=True)
    columns = [
        ("frames", "frames", ",d"),
        "dtype",
        "order",
        ("data_mb", "data MB", ".0f"),
        ("traced_mb", "fit adds, traced MB", ".1f"),
        ("peak_rss_added_mb", "fit adds, peak RSS MB", ".1f"),
        ("within_budget", f"<= {BUDGET_MB:.0f} MB", "s"),
    ]
    title = "Memory of fit, 62 dims, 200 hidden, 1 epoch"
    table = print_table(rows, columns, title=title)
    write_json("bench_memory", args.output, args=vars(args), rows=rows, table=table)


if __name__ == "__main__":
    main()
