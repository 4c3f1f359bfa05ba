"""``sample --seed-file PATH --seed-frame N``: seed frames from a take of one's own.

The generated motion continues a real take after one of its frames: the
model's ``history_length`` frames up to that frame, at the frame rate the
model was fitted at, encoded by the model's preprocessing as part of the
whole take.
"""

import numpy as np
from sklearn.utils import Bunch

from ..datasets import read_amc, read_bvh, resample_frames

__all__ = ["seed_from_file"]

# AMC files do not say their rate: the CLI reads them as CMU's (see --frame-rate).
AMC_FRAME_RATE = 120.0


def seed_from_file(pipeline, model_rate, path, frame=None):
    """The seed window ending at ``frame`` of the take in ``path``.

    Parameters
    ----------
    pipeline : MotionPipeline
        The fitted pipeline that will generate.
    model_rate : float
        Frames per second the pipeline was fitted at.
    path : pathlib.Path
        A BVH file (or an AMC file, for a model fitted on ASF/AMC files) of
        the model's skeleton.
    frame : int or None
        The last seed frame, counted from 0 at the file's own rate; ``None``:
        the middle frame (inside the motion, after any start-up).

    Returns
    -------
    seed : Bunch
        ``window`` (``(width, n_features)``, the model's space), ``first``
        and ``last`` (the file frames it spans) and ``text``, which says
        where it comes from.
    """
    data, rate = _read_take(pipeline.skeleton, path)
    if frame is None:
        frame = len(data) // 2
    if not 0 <= frame < len(data):
        raise ValueError(
            f"--seed-frame {frame}: {path.name} has frames 0 to {len(data) - 1}."
        )
    if rate < model_rate * (1 - 1e-3):
        raise ValueError(
            f"--seed-file {path} has {rate:g} frames per second, the model was "
            f"fitted at {model_rate:g}: seed from a take at least as fast."
        )
    # the take at the model's rate with ``frame`` among the frames kept (the
    # encoding of a frame looks at the next one: the whole take goes through)
    before = resample_frames(
        np.arange(frame + 1)[::-1], frame_rate=rate, target_rate=model_rate
    )[::-1]
    after = resample_frames(
        np.arange(frame, len(data)), frame_rate=rate, target_rate=model_rate
    )
    width = max(pipeline[-1].history_length, 1)
    if len(before) < width:
        step = (frame + 1) / len(before)
        raise ValueError(
            f"--seed-frame {frame}: the model continues {width} frames of motion "
            f"at {model_rate:g} frames per second, which end at frame "
            f"{int(np.ceil((width - 1) * step))} of {path.name} or later."
        )
    Z = pipeline[:-1].transform(data[np.concatenate([before, after[1:]])])
    window = Z[len(before) - width : len(before)]
    first, last = int(before[-width]), int(before[-1])
    span = f"frame {last}" if first == last else f"frames {first}-{last}"
    return Bunch(window=window, first=first, last=last, text=f"{span} of {path.name}")


def _read_take(skeleton, path):
    """``(raw channels in the skeleton's order, frame rate)`` of one file."""
    if not path.is_file():
        raise FileNotFoundError(f"--seed-file {path} is not a file.")
    suffix = path.suffix.lower()
    if suffix == ".amc" and skeleton.convention == "acclaim":
        data, _ = read_amc(path, skeleton)
        return data, AMC_FRAME_RATE
    if suffix != ".bvh":
        kinds = (
            "a BVH or AMC file" if skeleton.convention == "acclaim" else "a BVH file"
        )
        raise ValueError(f"--seed-file {path} must be {kinds} of the model's skeleton.")
    _, data, names, rate = read_bvh(path)
    names, wanted = list(names), list(skeleton.feature_names)
    if sorted(names) != sorted(wanted):
        missing = [name for name in wanted if name not in names]
        listed = ", ".join(missing[:5]) + (", ..." if len(missing) > 5 else "")
        raise ValueError(
            f"--seed-file {path} is not of the model's skeleton"
            + (f": it lacks the channels {listed}" if missing else "")
            + "; seed from a take of the motion the model was fitted on."
        )
    return data[:, [names.index(name) for name in wanted]], rate
