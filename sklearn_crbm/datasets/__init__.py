"""Motion-capture data: skeletons, file readers and writers, data sets.

- :class:`Skeleton` and :class:`Bone`: bones, channels, forward kinematics.
- :func:`read_amc`, :func:`write_amc`, :func:`read_bvh`, :func:`write_bvh`.
- :func:`read_bvh_folder` and :func:`read_amc_folder` read a folder of files
  into long format, with a label per file when asked;
  :func:`resample_frames` brings sequences to a common frame rate.
- :func:`load_cmu35`, :func:`load_mit_walk`, :func:`load_bandai_walks` and
  :func:`load_bandai_dataset2` load the real data from
  :func:`get_data_home`; :func:`fetch_cmu35`, :func:`fetch_mit_walk`,
  :func:`fetch_bandai_walks` and :func:`fetch_bandai_dataset2` download it.
- :func:`make_oscillations` and :func:`make_walker` make small synthetic
  motion for tests and examples.
"""

from ._acclaim import read_amc, write_amc
from ._base import (
    get_data_home,
    load_bandai_dataset2,
    load_bandai_walks,
    load_cmu35,
    load_mit_walk,
)
from ._bone import Bone
from ._bvh import read_bvh, write_bvh
from ._channels import bone_columns
from ._fetch import (
    fetch_bandai_dataset2,
    fetch_bandai_walks,
    fetch_cmu35,
    fetch_mit_walk,
)
from ._folders import read_amc_folder, read_bvh_folder
from ._frame_rate import resample_frames
from ._generators import make_oscillations, make_styled_oscillations, make_walker
from ._skeleton import Skeleton

__all__ = [
    "Bone",
    "Skeleton",
    "bone_columns",
    "fetch_bandai_dataset2",
    "fetch_bandai_walks",
    "fetch_cmu35",
    "fetch_mit_walk",
    "get_data_home",
    "load_bandai_dataset2",
    "load_bandai_walks",
    "load_cmu35",
    "load_mit_walk",
    "make_oscillations",
    "make_styled_oscillations",
    "make_walker",
    "read_amc",
    "read_amc_folder",
    "read_bvh",
    "read_bvh_folder",
    "resample_frames",
    "write_amc",
    "write_bvh",
]
