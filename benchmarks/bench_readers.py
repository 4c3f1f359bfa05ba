"""Time of the file readers per megabyte, on huge skeletons and on real files.

Readers must take time linear in a file's size, whatever its shape.  Timed
(best of ``--repeats``, wall and process CPU seconds, judged on CPU seconds
per MB): ``read_bvh`` on ``--joints`` (5,000) joints under one parent,
``Skeleton.from_asf`` on ``--bones`` (15,000) bones in a binary tree, and
``read_bvh``/``read_amc`` on the largest real files of ``external_dev``.

Run from the repository root::

    python benchmarks/bench_readers.py                 # about ten seconds
    python benchmarks/bench_readers.py --joints 20000 --bones 60000
"""

import tempfile
from pathlib import Path

from _common import announce, parser, print_table, time_both, write_json

from sklearn_crbm.datasets import Skeleton, read_amc, read_bvh

# A second per megabyte is the ceiling; the readers should be far below it.
BUDGET_S_PER_MB = 1.0


def wide_bvh(path, n_joints):
    """A BVH file with ``n_joints`` joints under its root, two frames."""
    joint = (
        "  JOINT j{k}\n  {{\n    OFFSET {x} 1 0\n"
        "    CHANNELS 3 Zrotation Xrotation Yrotation\n"
        "    End Site\n    {{\n      OFFSET 0 1 0\n    }}\n  }}\n"
    )
    lines = [
        "HIERARCHY\nROOT hips\n{\n  OFFSET 0 0 0\n"
        "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
    ]
    lines += [joint.format(k=k, x=k % 7 - 3) for k in range(n_joints)]
    frame = " ".join(["0"] * (6 + 3 * n_joints))
    lines.append(f"}}\nMOTION\nFrames: 2\nFrame Time: 0.0333333\n{frame}\n{frame}\n")
    path.write_text("".join(lines))
    return path


def tree_asf(path, n_bones):
    """An ASF file with ``n_bones`` bones in a binary tree under the root."""
    lines = [
        ":units\n  length 1\n  angle deg\n:root\n  order TX TY TZ RX RY RZ\n"
        "  axis XYZ\n  position 0 0 0\n  orientation 0 0 0\n:bonedata\n"
    ]
    lines += [
        f"  begin\n    name b{k}\n    direction 0 1 0\n    length 1\n"
        "    dof rx\n  end\n"
        for k in range(n_bones)
    ]
    lines.append(":hierarchy\n  begin\n    root b0\n")
    lines += [
        f"    b{k} "
        + " ".join(f"b{c}" for c in (2 * k + 1, 2 * k + 2) if c < n_bones)
        + "\n"
        for k in range((n_bones - 1) // 2 + 1)
        if 2 * k + 1 < n_bones
    ]
    lines.append("  end\n")
    path.write_text("".join(lines))
    return path


def main():
    p = parser(__doc__, seeds=None)
    p.add_argument("--joints", type=int, default=5000)
    p.add_argument("--bones", type=int, default=15000)
    p.add_argument("--repeats", type=int, default=3)
    args = p.parse_args()
    announce()
    real = Path(args.data_home) / "external_dev"
    cmu_bvh = real / "cmu_bvh_bvh11" / "131_03.bvh"
    dance = real / "cmu_asfamc_gsimchoni"
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        cases = [
            (f"read_bvh, {args.joints} joints under one parent",
             wide_bvh(folder / "wide.bvh", args.joints), read_bvh),
            (f"Skeleton.from_asf, {args.bones} bones",
             tree_asf(folder / "tree.asf", args.bones), Skeleton.from_asf),
            ("read_bvh, real: CMU 131_03.bvh", cmu_bvh, read_bvh),
            ("read_amc, real: charleston1.amc", dance / "charleston1.amc",
             lambda path: read_amc(path, dance / "charleston.asf")),
        ]  # fmt: skip
        rows = []
        for name, path, read in cases:
            megabytes = path.stat().st_size / 1e6
            times = [
                time_both(lambda read=read, path=path: read(path))
                for _ in range(args.repeats)
            ]
            wall, cpu = min(t[0] for t in times), min(t[1] for t in times)
            within = "yes" if cpu / megabytes < BUDGET_S_PER_MB else "NO"
            rows.append({"case": name, "MB": megabytes, "wall_s": wall,
                         "cpu_s": cpu, "cpu_s_per_MB": cpu / megabytes,
                         "within": within})  # fmt: skip
    columns = ["case", ("MB", "MB", ".2f"), ("wall_s", "wall s", ".3f"),
               ("cpu_s", "CPU s", ".3f"), ("cpu_s_per_MB", "CPU s per MB", ".3f"),
               ("within", f"under {BUDGET_S_PER_MB:g} s/MB", "")]  # fmt: skip
    print_table(rows, columns, title=f"Readers, best of {args.repeats} calls")
    write_json("bench_readers", args.output, rows=rows, joints=args.joints,
               bones=args.bones, repeats=args.repeats,
               budget_s_per_mb=BUDGET_S_PER_MB)  # fmt: skip


if __name__ == "__main__":
    main()
