"""Fuzzing the file readers with mutated real files: what escapes, what hangs.

The files of the development set (``external_dev``: BVH from pybvh, the CMU
BVH conversion and Bandai Namco; ASF/AMC from the CMU database) and a Bandai
Namco JSON label file with its ``style_label.txt`` are mutated at random:
truncated, bytes replaced, lines deleted, repeated or swapped, garbage words
inserted or substituted (numbers replaced by other numbers, one to three mutations per case).  Long files are
first cut to their first ``--frames`` frames, so that a case takes
milliseconds and the mutations fall on the parts that are parsed differently.

Every case is given to its reader: ``read_bvh``, ``Skeleton.from_asf``,
``read_amc`` (with the skeleton of the original ASF file) and, for labels,
``read_bvh_folder(folder, labels="style")`` on a folder of two small BVH
files whose first JSON file and label-name file are the mutated ones.  A
reader may refuse a case with a ValueError or TypeError (or an OSError for a
path it cannot open); a failure is

- ``other exception``: any other exception escapes;
- ``over 10 s``: the reader takes longer than ten seconds (it is stopped);
- ``non-finite``: the reader returns NaN or infinity (in the data, a bone, a
  frame rate, a label) without a warning.

The table gives, per reader, the cases tried, those read, those refused and
the failures by kind; the JSON also lists every failure with its message,
and ``--failures`` keeps the failing files.

Run from the repository root (one BLAS thread; 20,000 cases per reader took
about four minutes per reader on a shared 2-core machine; ``--seed`` gives
other cases, to run in chunks)::

    OMP_NUM_THREADS=1 python benchmarks/fuzz_readers.py --n-cases 20000
    python benchmarks/fuzz_readers.py --n-cases 500 --readers bvh labels
"""

import signal
import tempfile
import time
import traceback
import warnings
from pathlib import Path

import numpy as np
from _common import announce, parser, print_table, write_json

from sklearn_crbm.datasets import Skeleton, read_amc, read_bvh, read_bvh_folder

READERS = ("bvh", "asf", "amc", "labels")
TIME_LIMIT_S = 10.0

GARBAGE = [
    b"nan", b"inf", b"-inf", b"1e999", b"-1e999", b"1e-320", b"0", b"-0", b"-1",
    b"99999999999999999999", b"9" * 5000, b"1.5e308", b"\xc2\xb2", b"\xd9\xa6",
    b"\x00", b"\xff", b"\xe9", b"{", b"}", b"[", b"]", b"[" * 3000, b"(", b")",
    b"#", b":", b"::", b",", b'"', b"true", b"null", b"NaN", b"Infinity",
    b"ROOT", b"JOINT", b"End", b"Site", b"OFFSET", b"CHANNELS", b"CHANNELS 0",
    b"Xrotation", b"Wrotation", b"Xposition", b"MOTION", b"HIERARCHY", b"Frames:",
    b"Frame", b"Time:", b":root", b":bonedata", b":hierarchy", b":units",
    b":documentation", b":DEGREES", b":RADIANS", b"begin", b"end", b"name", b"dof",
    b"rx", b"rw", b"tx", b"axis", b"XYZ", b"XXZ", b"direction", b"length", b"order",
    b"position", b"orientation", b"angle", b"rad", b"root", b"lfemur", b"Hips",
    b"\t", b"\r", b"1", b"2", b"3", b"6", b"1000000000",
]  # fmt: skip
NUMBERS = [
    b"0", b"-0", b"1", b"-1", b"0.5", b"360", b"-720", b"1e5", b"-1e9", b"1e308",
    b"-1e308", b"1e-320", b"4.9e-324", b"123456789012345678901234567890",
]  # fmt: skip
MUTATIONS = (
    "truncate", "flip", "delete", "duplicate", "swap", "insert", "replace", "renumber"
)  # fmt: skip


class _TooSlow(Exception):
    pass


def mutate(data, rng):
    """``data`` after one to three random mutations."""
    for _ in range(rng.integers(1, 4)):
        kind = MUTATIONS[rng.integers(len(MUTATIONS))]
        lines = data.split(b"\n")
        if kind == "truncate":
            data = data[: rng.integers(0, max(len(data), 1))]
        elif kind == "flip" and data:
            buffer = bytearray(data)
            for i in rng.integers(0, len(buffer), rng.integers(1, 5)):
                buffer[i] = rng.integers(0, 256)
            data = bytes(buffer)
        elif kind == "delete":
            for _ in range(rng.integers(1, 6)):
                if lines:
                    del lines[rng.integers(len(lines))]
            data = b"\n".join(lines)
        elif kind == "duplicate":
            lines.insert(rng.integers(len(lines) + 1), lines[rng.integers(len(lines))])
            data = b"\n".join(lines)
        elif kind == "swap":
            i, j = rng.integers(len(lines), size=2)
            lines[i], lines[j] = lines[j], lines[i]
            data = b"\n".join(lines)
        elif kind == "renumber":
            for _ in range(rng.integers(1, 4)):
                i = rng.integers(len(lines))
                words = lines[i].split()
                numbers = [k for k, w in enumerate(words) if _is_number(w)]
                if numbers:
                    words[numbers[rng.integers(len(numbers))]] = NUMBERS[
                        rng.integers(len(NUMBERS))
                    ]
                    lines[i] = b" ".join(words)
            data = b"\n".join(lines)
        elif kind in ("insert", "replace"):
            for _ in range(rng.integers(1, 5)):
                i = rng.integers(len(lines))
                words = lines[i].split()
                token = GARBAGE[rng.integers(len(GARBAGE))]
                if kind == "replace" and words:
                    words[rng.integers(len(words))] = token
                else:
                    words.insert(rng.integers(len(words) + 1), token)
                lines[i] = b" ".join(words)
            data = b"\n".join(lines)
    return data


def _is_number(word):
    try:
        float(word)
    except ValueError:
        return False
    return True


# ------------------------------------------------------------------ originals
def first_bvh_frames(data, n_frames):
    """A BVH file's bytes with only its first ``n_frames`` frames."""
    head, _, motion = data.partition(b"MOTION")
    lines = motion.strip().split(b"\n")
    frames = [line for line in lines[2:] if line.strip()][:n_frames]
    return b"\n".join(
        [head + b"MOTION", f"Frames: {len(frames)}".encode(), lines[1], *frames, b""]
    )


def first_amc_frames(data, n_frames):
    """An AMC file's bytes with only its first ``n_frames`` frames."""
    lines, kept, seen = data.split(b"\n"), [], 0
    for line in lines:
        if line.strip().isdigit():
            seen += 1
            if seen > n_frames:
                break
        kept.append(line)
    return b"\n".join(kept) + b"\n"


def originals(dev, n_frames):
    """``{reader: [(name, bytes, context)]}``: the files each reader's cases
    are mutated from, with what the reader needs beside them."""
    bvh = [
        (p.name, first_bvh_frames(p.read_bytes(), n_frames), None)
        for p in sorted(dev.glob("*/*.bvh"))
    ]
    asf = [(p.name, p.read_bytes(), None) for p in sorted(dev.glob("*/*.asf"))]
    amc = []
    for p in sorted(dev.glob("*/*.amc")):
        asf_path = max(p.parent.glob("*.asf"), key=lambda a: p.stem.startswith(a.stem))
        amc.append(
            (
                p.name,
                first_amc_frames(p.read_bytes(), n_frames),
                Skeleton.from_asf(asf_path),
            )
        )
    labels = [
        ("walk.json", b'{"content": 0, "style": 2}\n', "json"),
        ("style_label.txt", b"dataset-2_active\ndataset-2_elderly\ndataset-2_normal\n",
         "names"),
    ]  # fmt: skip
    return {"bvh": bvh, "asf": asf, "amc": amc, "labels": labels}


# ------------------------------------------------------------------ reading
def _finite(*arrays):
    return all(np.all(np.isfinite(np.asarray(a, dtype=np.float64))) for a in arrays)


def _skeleton_finite(skeleton):
    return _finite(
        [bone.direction for bone in skeleton.bones],
        [bone.length for bone in skeleton.bones],
        [bone.axis for bone in skeleton.bones],
    )


def read_case(reader, content, context, folder):
    """Give ``content`` to the reader; True if what it returned is finite."""
    if reader == "bvh":
        path = folder / "case.bvh"
        path.write_bytes(content)
        skeleton, data, _, rate = read_bvh(path)
        return _finite(data, rate) and _skeleton_finite(skeleton)
    if reader == "asf":
        path = folder / "case.asf"
        path.write_bytes(content)
        return _skeleton_finite(Skeleton.from_asf(path))
    if reader == "amc":
        path = folder / "case.amc"
        path.write_bytes(content)
        return _finite(read_amc(path, context)[0])
    labelled = folder / "labelled"
    (
        labelled / ("walk_a.json" if context == "json" else "style_label.txt")
    ).write_bytes(content)
    walks = read_bvh_folder(labelled, labels="style")
    names = [n for n in walks.target_names if isinstance(n, float)]
    return _finite(walks.data, names)


def labelled_folder(folder, label_files):
    """Two small BVH files with their JSON labels and the label names."""
    labelled = folder / "labelled"
    labelled.mkdir()
    bvh = (
        "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition "
        "Zposition Zrotation Xrotation Yrotation\n  End Site\n  {\n    OFFSET 0 1 0"
        "\n  }\n}\nMOTION\nFrames: 2\nFrame Time: 0.0333333\n0 1 0 0 0 0\n0 1 1 0 0 0\n"
    )
    for name in ("walk_a", "walk_b"):
        (labelled / f"{name}.bvh").write_text(bvh)
    for _, content, role in label_files:
        name = "walk_a.json" if role == "json" else "style_label.txt"
        (labelled / name).write_bytes(content)
    (labelled / "walk_b.json").write_bytes(label_files[0][1])


def _raise_too_slow(signum, frame):
    raise _TooSlow


def run_case(reader, content, context, folder, restore):
    """``(outcome, message)``: "read", "refused" or a kind of failure."""
    signal.signal(signal.SIGALRM, _raise_too_slow)
    signal.setitimer(signal.ITIMER_REAL, TIME_LIMIT_S)
    start = time.perf_counter()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            finite = read_case(reader, content, context, folder)
    except _TooSlow:
        return "over 10 s", f"stopped after {time.perf_counter() - start:.1f} s"
    except (ValueError, TypeError, OSError) as exc:
        outcome = ("refused", str(exc)[:300])
    except Exception as exc:
        outcome = (
            "other exception",
            f"{type(exc).__name__}: {str(exc)[:300]}\n{traceback.format_exc()[-1500:]}",
        )
    else:
        if not finite and not caught:
            outcome = ("non-finite", "NaN or infinity returned without a warning")
        else:
            outcome = ("read", "")
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        restore()
    if time.perf_counter() - start > TIME_LIMIT_S:
        return "over 10 s", f"took {time.perf_counter() - start:.1f} s"
    return outcome


def main():
    p = parser(__doc__, seeds=None)
    p.add_argument("--n-cases", type=int, default=20000, help="cases per reader")
    p.add_argument("--readers", nargs="+", default=list(READERS), choices=READERS)
    p.add_argument("--frames", type=int, default=20, help="frames kept per file")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--failures", default=None, help="folder to keep failing files")
    args = p.parse_args()
    announce()
    sources = originals(Path(args.data_home) / "external_dev", args.frames)
    rng = np.random.default_rng(args.seed)
    rows, failures = [], []
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        labelled_folder(folder, sources["labels"])

        def restore():
            for _, content, role in sources["labels"]:
                name = "walk_a.json" if role == "json" else "style_label.txt"
                (folder / "labelled" / name).write_bytes(content)

        for reader in args.readers:
            counts = dict.fromkeys(
                ["read", "refused", "other exception", "over 10 s", "non-finite"], 0
            )
            start = time.perf_counter()
            for case in range(args.n_cases):
                name, original, context = sources[reader][
                    rng.integers(len(sources[reader]))
                ]
                content = mutate(original, rng)
                outcome, message = run_case(reader, content, context, folder, restore)
                counts[outcome] += 1
                if outcome not in ("read", "refused"):
                    failures.append(
                        dict(reader=reader, case=case, source=name, kind=outcome,
                             message=message)
                    )  # fmt: skip
                    if args.failures:
                        kept = Path(args.failures) / f"{reader}_{args.seed}_{case}"
                        kept.parent.mkdir(parents=True, exist_ok=True)
                        kept.write_bytes(content)
            rows.append(
                dict(reader=reader, cases=args.n_cases, **counts,
                     seconds=time.perf_counter() - start)
            )  # fmt: skip
            print(f"{reader}: {counts}", flush=True)
    print_table(
        rows,
        ["reader", "cases", "read", "refused", "other exception", "over 10 s",
         "non-finite", ("seconds", "seconds", ".0f")],
        title=f"Mutated files per reader (seed {args.seed}, {args.frames} frames kept)",
    )  # fmt: skip
    for failure in failures[:20]:
        print(f"{failure['reader']} case {failure['case']} ({failure['source']}): "
              f"{failure['kind']}: {failure['message'][:500]}")  # fmt: skip
    write_json(
        "fuzz_readers",
        args.output,
        rows=rows,
        failures=failures,
        seed=args.seed,
        frames=args.frames,
    )


if __name__ == "__main__":
    main()
