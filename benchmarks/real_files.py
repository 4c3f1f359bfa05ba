"""Other people's mocap files through the whole pipeline, checked by other tools.

Every BVH file and ASF/AMC pair of ``../shared/data/external_dev`` and of
the folders given on the command line goes through

1. reading (:func:`read_bvh`, or :meth:`Skeleton.from_asf` + :func:`read_amc`),
   and forward kinematics compared with independent readers of the same
   file: pybvh, bvhio and bvhtoolbox for BVH, CalciferZh's AMCParser for
   ASF/AMC (``--amcparser``);
2. the default preprocessing, ``make_motion_preprocessor(skeleton)``, and its
   ``inverse_transform``: the largest joint-rotation error (degrees) and
   joint-position error (file units) after aligning the first frame's root
   pose, which the encoder documents as not kept (it starts every sequence
   at heading 0 and ground position 0);
3. :func:`write_bvh` of what came back (of the file's own data when the
   preprocessing failed; at most ``--max-frames`` frames), read by pybvh,
   bvhio, bvhtoolbox and Blender's importer (``--blender-python``): the
   largest distance between their joint positions and the package's forward
   kinematics (Blender: with its default Euler rotation mode and with
   quaternions).  A joint other than the root whose position channels move
   (Bandai Namco's Hips, below a ground-marker root) is written as the ROOT
   (``write_bvh(..., root=...)``), as pybvh and bvhtoolbox read position
   channels on the root only; the marker joint is then not compared.

Prints one row per file and writes ``benchmarks/results/real_files.json``.
Numbers are maximum absolute errors over all frames and joints (bvhio and
AMCParser: over at most ``--tool-frames`` frames spread over the file,
bvhio and Blender compute in float32); a cell that is not a number says why
the tool gave nothing.  Not a test: the test suite runs
``tests/datasets/test_real_files.py`` on external_dev with a small
independent reader.

Needs ``pip install pybvh bvhio bvhtoolbox`` (not dependencies of the
package); Blender's importer needs a Python with ``bpy`` (``pip install
bpy`` in a separate environment) and ``benchmarks/blender_bvh_positions.py``.

Run::

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=. python benchmarks/real_files.py \\
        /work/collected_mocap --blender-python /path/to/bpy/python \\
        --amcparser /path/to/AMCParser/amc_parser.py
"""

import argparse
import contextlib
import importlib.util
import io
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path
from unittest import mock

import numpy as np
from _common import DEFAULT_DATA_HOME, print_table, write_json

from sklearn_crbm.datasets import (
    read_amc_folder,
    read_bvh,
    write_bvh,
)
from sklearn_crbm.preprocessing import make_motion_preprocessor

HERE = Path(__file__).resolve().parent
READER_STEPS = ("read", "round_trip") + tuple(
    f"{step}_{tool}"
    for step in ("fk", "w")
    for tool in ("pybvh", "bvhio", "bvhtoolbox", "amcparser", "blender", "blender_quat")
)


# ------------------------------------------------------------ the files
def motion_files(folders):
    """``(name, kind, path, skeleton, data, frame_rate, asf)`` for every file."""
    for folder in folders:
        for path in sorted(folder.rglob("*.bvh")):
            name = f"{folder.name}/{path.relative_to(folder)}"
            try:
                skeleton, data, _, rate = read_bvh(path)
            except ValueError as exc:
                yield name, "bvh", path, None, str(exc), None, None
                continue
            yield name, "bvh", path, skeleton, data, rate, None
        for sub in sorted({p.parent for p in folder.rglob("*.amc")}):
            motions = read_amc_folder(sub)
            for k, filename in enumerate(motions.filenames):
                path = Path(filename)
                skeleton = motions.skeletons[k]
                data = motions.data[motions.sequence_ids == k]
                name = f"{folder.name}/{path.relative_to(folder)}"
                asf = path.parent / f"{skeleton.name}.asf"
                yield name, "amc", path, skeleton, data, motions.frame_rate, asf


# --------------------------------------------- where the package puts joints
def written_points(skeleton, positions):
    """``{joint or "{joint}_end": (n_frames, 3)}``: where the package's forward
    kinematics puts every joint and end site of the BVH file that
    :func:`write_bvh` writes for ``skeleton``."""
    index = {name: i for i, name in enumerate(skeleton.bone_names)}
    if skeleton.convention == "bvh":
        return {name: positions[:, i] for name, i in index.items()}
    # ASF: a joint at the start of every bone (its parent's end), an end site
    # at the end of every leaf bone
    points = {}
    for name, i in index.items():
        parent = skeleton.bone(name).parent
        points[name] = positions[:, index[parent] if parent else i]
        if not skeleton.children(name):
            points[f"{name}_end"] = positions[:, i]
    return points


def moving_joint(skeleton, data):
    """The joint other than the root whose position channels move, when there
    is one (Bandai Namco's Hips): written as the ROOT, since pybvh and
    bvhtoolbox read position channels on the root only."""
    if skeleton.convention != "bvh":
        return None
    offsets = skeleton.local_offsets(data)
    moving = [
        bone.name
        for i, bone in enumerate(skeleton.bones)
        if bone.parent is not None and np.ptp(offsets[:, i], axis=0).max() > 1e-9
    ]
    return moving[0] if len(moving) == 1 else None


def max_error(points, other, frames=None):
    """Largest distance between the shared points; ``(error, n_points)``."""
    shared = [name for name in other if name in points]
    if not shared:
        return "no shared joints", 0
    error = 0.0
    for name in shared:
        mine = points[name] if frames is None else points[name][frames]
        n = min(len(mine), len(other[name]))
        error = max(error, float(np.max(np.abs(mine[:n] - other[name][:n]))))
    return error, len(shared)


def spread(n_frames, count):
    return np.unique(np.linspace(0, n_frames - 1, min(count, n_frames)).astype(int))


# ----------------------------------------------------- independent readers
def pybvh_points(path):
    import pybvh

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mocap = pybvh.read_bvh_file(path, world_up="+y")
    positions = mocap.node_positions()
    return {
        (f"{node.parent.name}_end" if node.is_end_site() else node.name): positions[
            :, i
        ]
        for i, node in enumerate(mocap.nodes)
    }


def bvhio_points(path, frames):
    import bvhio

    root = bvhio.readAsHierarchy(str(path))
    joints = [joint for joint, _, _ in root.layout()]
    out = {joint.Name: np.empty((len(frames), 3)) for joint in joints}
    for k, frame in enumerate(frames):
        root.loadPose(int(frame))
        for joint in joints:
            out[joint.Name][k] = joint.PositionWorld
    return out


def bvhtoolbox_points(path):
    from bvhtoolbox import BvhTree

    bvh2csv = importlib.import_module("bvhtoolbox.convert.bvh2csv")
    tree = BvhTree(Path(path).read_text())
    captured = {}

    def keep(filepath, data, header, **kwargs):
        captured["data"], captured["header"] = data, header

    with mock.patch.object(bvh2csv.np, "savetxt", keep):
        bvh2csv.write_joint_positions(tree, "unused.csv", end_sites=True)
    names, points, joint = captured["header"].split(",")[1:], {}, None
    for k in range(0, len(names), 3):
        name = names[k][: -len(".x")]
        # an end site is written right after its joint, and named "Site"
        joint, key = (joint, f"{joint}_end") if name == "Site" else (name, name)
        points[key] = captured["data"][:, 1 + k : 4 + k]
    return points


def amcparser_points(module, asf, amc, frames):
    joints = module.parse_asf(str(asf))
    motions = module.parse_amc(str(amc))
    out = {name: np.empty((len(frames), 3)) for name in joints}
    for k, frame in enumerate(frames):
        joints["root"].set_motion(motions[int(frame)])
        for name, joint in joints.items():
            out[name][k] = joint.coordinate.ravel()
    return out


def tool(function, *args):
    """A reader's points, or the first line of its error."""
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            return function(*args)
    except Exception as exc:  # the tool refused the file: say what it said
        return f"{type(exc).__name__}: {str(exc).splitlines()[0][:80]}"


def compare(points, other, frames=None):
    if isinstance(other, str):
        return other
    return max_error(points, other, frames)[0]


# --------------------------------------------------------- preprocessing
def rotation_angle_deg(A, B):
    """Angle of ``A^T B`` in degrees, element-wise over leading axes.

    From ``|A - B|_F = 2 sqrt(2) sin(angle / 2)``, exact for small angles
    (the arccos of the trace cannot resolve less than about 1e-6 degrees).
    """
    distance = np.linalg.norm(A - B, axis=(-2, -1))
    return np.rad2deg(2 * np.arcsin(np.clip(distance / np.sqrt(8), 0.0, 1.0)))


def round_trip(skeleton, data):
    """``(X_back, rotation error deg, position error)``, or an error string."""
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            pre = make_motion_preprocessor(skeleton)
            back = pre.inverse_transform(pre.fit_transform(data))
    except Exception as exc:
        return f"{type(exc).__name__}: {str(exc).splitlines()[0][:100]}"
    local, local_back = skeleton.local_rotations(data), skeleton.local_rotations(back)
    glob, glob_back = skeleton.global_rotations(data), skeleton.global_rotations(back)
    positions = skeleton.forward_kinematics(data)
    positions_back = skeleton.forward_kinematics(back)
    # the start pose of the encoder's root (Bandai: Hips, below a static
    # marker) is not kept: align it, and the bones below it, at frame 0
    root_name = pre.named_steps["root"].root_
    i = skeleton.bone_names.index(root_name)
    below = [skeleton.bone_names.index(n) for n in skeleton.descendants(root_name)]
    turn = glob[0, i] @ glob_back[0, i].T
    aligned = positions_back.copy()
    aligned[:, below] = (positions_back[:, below] - positions_back[0, i]) @ turn.T
    aligned[:, below] += positions[0, i]
    others = [k for k in range(len(skeleton.bones)) if k != i]
    rotation_error = max(
        float(
            np.max(
                rotation_angle_deg(local[:, others], local_back[:, others]), initial=0
            )
        ),
        float(np.max(rotation_angle_deg(glob[:, i], turn @ glob_back[:, i]))),
    )
    warned = sorted({str(w.message).splitlines()[0][:80] for w in caught})
    return back, rotation_error, float(np.max(np.abs(aligned - positions))), warned


# ----------------------------------------------------------------- main
def check_file(item, args, out_dir, amcparser):
    name, kind, path, skeleton, data, rate, asf = item
    row = {"file": name, "kind": kind}
    if skeleton is None:
        row["read"] = data
        return row, None
    positions = skeleton.forward_kinematics(data)
    points = written_points(skeleton, positions) if kind == "bvh" else None
    frames = spread(len(data), args.tool_frames)
    row.update(
        scale=float(np.max(np.abs(positions))),
        frames=len(data),
        channels=data.shape[1],
        root=skeleton.bone_names[0],
        frame_rate=round(rate, 3),
        read="ok",
    )
    if kind == "bvh":
        row["fk_pybvh"] = compare(points, tool(pybvh_points, path))
        row["fk_bvhio"] = compare(points, tool(bvhio_points, path, frames), frames)
        row["fk_bvhtoolbox"] = compare(points, tool(bvhtoolbox_points, path))
    elif amcparser is not None:
        mine = dict(zip(skeleton.bone_names, positions.transpose(1, 0, 2), strict=True))
        other = tool(amcparser_points, amcparser, asf, path, frames)
        row["fk_amcparser"] = compare(mine, other, frames)
    result = round_trip(skeleton, data)
    if isinstance(result, str):
        row["round_trip"], written = result, data
    else:
        written, row["rt_rot_deg"], row["rt_pos"], row["rt_warnings"] = result
        row["round_trip"] = "ok"
    written = written[: args.max_frames]
    out = out_dir / f"{len(list(out_dir.glob('*.bvh'))):03d}.bvh"
    row["written_root"] = moving_joint(skeleton, written)
    write_bvh(out, written, skeleton, rate, root=row["written_root"])
    row["written_as"] = out.name
    points = written_points(skeleton, skeleton.forward_kinematics(written))
    frames = spread(len(written), args.tool_frames)
    row["w_pybvh"] = compare(points, tool(pybvh_points, out))
    row["w_bvhio"] = compare(points, tool(bvhio_points, out, frames), frames)
    row["w_bvhtoolbox"] = compare(points, tool(bvhtoolbox_points, out))
    return row, points


def blender_errors(blender_python, out_dir, expected):
    """Run Blender's importer on every written file, in both rotation modes;
    ``{mode: {file name: error}}``."""
    script = HERE / "blender_bvh_positions.py"
    subprocess.run(
        [blender_python, str(script), str(out_dir)],
        check=True,
        capture_output=True,
        timeout=3600,
    )
    errors = {"NATIVE": {}, "QUATERNION": {}}
    for mode, found in errors.items():
        for name, points in expected.items():
            result = np.load(out_dir / f"{Path(name).stem}.{mode}.npz")
            if "error" in result:
                found[name] = str(result["error"]).strip().splitlines()[-1][:80]
                continue
            heads = dict(
                zip(result["names"], result["heads"].transpose(1, 0, 2), strict=True)
            )
            found[name] = max_error(points, heads)[0]
    return errors


def load_amcparser(path):
    if path is None:
        return None
    spec = importlib.util.spec_from_file_location("amc_parser", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


COLUMNS = [
    ("file", "file"),
    ("frames", "frames"),
    ("scale", "max |position|"),
    ("fk_pybvh", "FK pybvh"),
    ("fk_bvhio", "FK bvhio"),
    ("fk_bvhtoolbox", "FK bvhtoolbox"),
    ("fk_amcparser", "FK AMCParser"),
    ("rt_rot_deg", "round trip deg"),
    ("rt_pos", "round trip pos"),
    ("w_pybvh", "written pybvh"),
    ("w_bvhio", "written bvhio"),
    ("w_bvhtoolbox", "written bvhtoolbox"),
    ("w_blender", "written Blender"),
    ("w_blender_quat", "written Blender (quaternions)"),
]


def printable(row):
    """Errors as ``1.2e-05``; a tool's refusal or a failed step as a word."""
    out = {}
    for key, value in row.items():
        if isinstance(value, float):
            out[key] = f"{value:.1e}"
        elif isinstance(value, str) and key in READER_STEPS:
            out[key] = value if value == "ok" else "refused"
        else:
            out[key] = str(value)
    if row.get("round_trip", "ok") != "ok":
        out["rt_rot_deg"] = out["rt_pos"] = "failed"
    return out


def summary(rows, tolerance):
    """How many files pass each check, at ``tolerance``."""
    counts = {}
    for key, _ in COLUMNS[3:]:
        values = [row[key] for row in rows if key in row]
        numbers = [(row[key], row["scale"]) for row in rows if _is_number(row, key)]
        tol = 1e-6 if key.startswith("rt_") else tolerance
        counts[key] = {
            "files": len(values),
            "within": sum(error <= tol for error, _ in numbers),
            "tolerance": tol,
            "worst": max((error for error, _ in numbers), default=None),
            # float32 tools (bvhio, Blender): error relative to the coordinates
            "worst_relative": max((e / scale for e, scale in numbers), default=None),
        }
    return counts


def _is_number(row, key):
    return isinstance(row.get(key), float) and row.get("scale", 0) > 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folders", nargs="*", help="more folders of BVH/ASF/AMC")
    parser.add_argument(
        "--data-home", default=str(DEFAULT_DATA_HOME), help="has external_dev/"
    )
    parser.add_argument("--blender-python", help="a Python that has bpy")
    parser.add_argument("--amcparser", help="path of AMCParser's amc_parser.py")
    parser.add_argument("--max-frames", type=int, default=400)
    parser.add_argument("--tool-frames", type=int, default=40)
    parser.add_argument("--tolerance", type=float, default=1e-4)
    parser.add_argument("--output", default=None)
    args = parser.parse_args()
    folders = [Path(args.data_home) / "external_dev", *map(Path, args.folders)]
    missing = [str(folder) for folder in folders if not folder.is_dir()]
    if missing:
        parser.error(f"no such folder: {missing} (see --data-home)")
    amcparser = load_amcparser(args.amcparser)
    rows, expected = [], {}
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        out_dir = Path(tmp)
        for item in motion_files(folders):
            row, points = check_file(item, args, out_dir, amcparser)
            rows.append(row)
            if points is not None:
                expected[row["written_as"]] = points
            print(f"{row['file']}: done", file=sys.stderr, flush=True)
        if args.blender_python:
            blender = blender_errors(args.blender_python, out_dir, expected)
            for row in rows:
                if row.get("written_as") in expected:
                    row["w_blender"] = blender["NATIVE"][row["written_as"]]
                    row["w_blender_quat"] = blender["QUATERNION"][row["written_as"]]
    table = print_table(
        [printable(r) for r in rows],
        [(key, header, "") for key, header in COLUMNS],
        title=f"{len(rows)} files: max abs error (file units; degrees for rotations)",
    )
    counts = summary(rows, args.tolerance)
    for key, count in counts.items():
        print(
            f"{key}: {count['within']}/{count['files']} within {count['tolerance']:g}"
            f" (worst {count['worst']}, relative to max |position| "
            f"{count['worst_relative']})"
        )
    refusals = {}
    for row in rows:
        for key, value in row.items():
            if isinstance(value, str) and key in READER_STEPS and value != "ok":
                refusals.setdefault((key, value[:90]), []).append(row["file"])
    for (key, why), files in sorted(refusals.items()):
        print(f"  {key}: {len(files)} files: {why}")
    write_json(
        "real_files",
        {
            "folders": [str(f) for f in folders],
            "tolerance": args.tolerance,
            "seconds": time.perf_counter() - start,
            "summary": counts,
            "rows": rows,
            "table": table,
        },
        args.output,
    )


if __name__ == "__main__":
    main()
