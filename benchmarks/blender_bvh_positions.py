"""Joint positions of BVH files as Blender's importer reads them.

Run with a Python that has Blender as a module (``pip install bpy``, which
needs the Python version Blender was built for), not with the package's
environment::

    /path/to/bpy-python benchmarks/blender_bvh_positions.py FOLDER

For every ``FOLDER/*.bvh`` it imports the file with Blender's own BVH
importer (axes kept as in the file: forward Y, up Z, scale 1), once with
the importer's default rotation mode (``NATIVE``: Euler angles in each
joint's order) and once with ``QUATERNION``, and writes
``FOLDER/*.MODE.npz`` with ``names`` (the armature's bones, one per BVH
joint) and ``heads`` (n_frames, n_bones, 3): the world position of every
joint at every frame of the file, or ``error`` with the importer's message.
Blender computes in float32; converting to Euler angles in the bones' own
frames costs it more digits than quaternions do.
``benchmarks/real_files.py`` calls it.
"""

import sys
import traceback
from pathlib import Path

import bpy
import numpy as np

MODES = ("NATIVE", "QUATERNION")


def joint_positions(path, mode):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_anim.bvh(
        filepath=str(path),
        axis_forward="Y",
        axis_up="Z",
        rotate_mode=mode,
        global_scale=1.0,
        use_fps_scale=False,
        update_scene_fps=False,
        update_scene_duration=True,
    )
    armature = next(o for o in bpy.context.scene.objects if o.type == "ARMATURE")
    start, end = (int(f) for f in armature.animation_data.action.frame_range)
    scene = bpy.context.scene
    heads = []
    for frame in range(start, end + 1):
        scene.frame_set(frame)
        world = armature.matrix_world
        heads.append([list(world @ bone.head) for bone in armature.pose.bones])
    names = [bone.name for bone in armature.pose.bones]
    return names, np.array(heads, dtype=np.float64)


def main(folder):
    for path in sorted(Path(folder).glob("*.bvh")):
        for mode in MODES:
            out = path.with_suffix(f".{mode}.npz")
            try:
                names, heads = joint_positions(path, mode)
                np.savez(out, names=np.array(names), heads=heads)
            except Exception:  # report what Blender said, go on with the next
                np.savez(out, error=np.array(traceback.format_exc(limit=2)))


if __name__ == "__main__":
    main(sys.argv[1])
