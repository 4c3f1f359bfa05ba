"""Sphinx configuration of the sklearn_crbm documentation.

Build with ``python -m sphinx -W --keep-going -b html doc doc/_build/html``.
The gallery examples in ``doc/examples`` are executed, so their pages show the
paper's figures (a few minutes: they train models).
``SKLEARN_CRBM_DOCS_RUN_EXAMPLES=0`` shows their code without running it, as
the test suite's build does to stay fast.
"""

import os
import sys
from pathlib import Path

import sklearn_crbm

DOC_DIR = Path(__file__).resolve().parent
REPO_ROOT = DOC_DIR.parent

# The real motion-capture data: $SKLEARN_CRBM_DATA if set, else the shared
# checkout next to the repository (where tests and benchmarks find it), else
# the package default (~/sklearn_crbm_data).  Examples fall back to synthetic
# motion when none of these holds the data.
if not os.environ.get("SKLEARN_CRBM_DATA"):
    _shared = REPO_ROOT.parent / "shared" / "data"
    if _shared.is_dir():
        os.environ["SKLEARN_CRBM_DATA"] = str(_shared)

# Figures are drawn off-screen.
os.environ.setdefault("MPLBACKEND", "Agg")

# The local extension: api.rst from the modules' __all__, benchmark tables,
# docstring touch-ups (doc/sphinxext/crbm_docs.py).
sys.path.insert(0, str(DOC_DIR / "sphinxext"))


# -- Project -----------------------------------------------------------------

project = "sklearn_crbm"
author = "sklearn_crbm developers"
copyright = "2026, sklearn_crbm developers"
version = sklearn_crbm.__version__
release = sklearn_crbm.__version__

# -- General -----------------------------------------------------------------

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
    "matplotlib.sphinxext.plot_directive",
    "myst_parser",
    "crbm_docs",
]

templates_path = ["_templates"]
# doc/examples holds the gallery sources; sphinx-gallery renders them into
# auto_examples, so Sphinx must not read them a second time.
exclude_patterns = ["_build", "examples", "sphinxext", "Thumbs.db", ".DS_Store"]
root_doc = "index"
default_role = "literal"
pygments_style = "sphinx"
nitpicky = False

# -- autodoc / autosummary / numpydoc ------------------------------------------

autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {"members": True}
autodoc_typehints = "none"
autoclass_content = "class"

numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_attributes_as_param_list = True
numpydoc_xref_param_type = False

# No network here or in CI: no intersphinx.  Cross-references to numpy, scipy
# and scikit-learn are written as plain text.
intersphinx_mapping = {}

# -- sphinx-gallery ------------------------------------------------------------

# The examples are executed (minutes: they train models) and their figures put
# in the gallery; SKLEARN_CRBM_DOCS_RUN_EXAMPLES=0 shows the code only (the
# test suite's build).  SKLEARN_CRBM_DOCS_EXAMPLES_PATTERN (a regular
# expression on the path) executes only some, e.g. "plot_doc_root".
RUN_EXAMPLES = os.environ.get("SKLEARN_CRBM_DOCS_RUN_EXAMPLES", "1") == "1"
EXAMPLES_PATTERN = os.environ.get("SKLEARN_CRBM_DOCS_EXAMPLES_PATTERN", r"/plot_")

sphinx_gallery_conf = {
    "examples_dirs": ["examples"],
    "gallery_dirs": ["auto_examples"],
    "filename_pattern": EXAMPLES_PATTERN,
    "ignore_pattern": r"(__init__|_common)\.py$",
    "plot_gallery": RUN_EXAMPLES,
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "abort_on_example_error": False,
    "only_warn_on_example_error": False,
    "image_scrapers": ("matplotlib",),
    "min_reported_time": 5,
    "show_memory": False,
    "reference_url": {"sklearn_crbm": None},
    "doc_module": ("sklearn_crbm",),
    "backreferences_dir": "gen_modules/backreferences",
    "inspect_global_variables": False,
}

# -- matplotlib plot directive (figures of the user guide) ---------------------

plot_include_source = False
plot_html_show_source_link = False
plot_html_show_formats = False
plot_formats = [("png", 100)]
plot_rcparams = {"figure.autolayout": False}
plot_working_directory = str(REPO_ROOT)

# -- HTML ----------------------------------------------------------------------

try:
    import pydata_sphinx_theme  # noqa: F401

    html_theme = "pydata_sphinx_theme"
    html_theme_options = {
        "navbar_end": ["navbar-icon-links"],
        "show_prev_next": True,
        "navigation_with_keys": False,
        "secondary_sidebar_items": ["page-toc"],
        "footer_start": ["copyright"],
        "footer_end": ["sphinx-version"],
    }
except ImportError:  # the docs extra not installed: still build, plainly
    html_theme = "alabaster"
    html_theme_options = {}

html_title = f"sklearn_crbm {release}"
html_static_path = ["_static"]
html_css_files = ["custom.css"]
html_show_sourcelink = False
html_last_updated_fmt = None

# -- MyST (only for including benchmarks/README.md) -------------------------------

source_suffix = {".rst": "restructuredtext"}
myst_heading_anchors = 0
# Relative links of the included Markdown point at files in benchmarks/, which
# are not pages of this site: they render as plain text.
suppress_warnings = ["myst.xref_missing", "myst.header"]
