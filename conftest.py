"""Root pytest configuration, loaded before any package module is imported."""

import os

# scikit-learn's check_array_api_input runs only when SciPy's array API
# support is switched on, which must happen before SciPy is first imported.
os.environ.setdefault("SCIPY_ARRAY_API", "1")

from threadpoolctl import threadpool_limits  # noqa: E402

# The test models are small: one BLAS thread is as fast, and on a loaded
# 2-core machine several threads per product are many times slower.
_BLAS_LIMITS = threadpool_limits(1)

from hypothesis import settings  # noqa: E402

# The suite's verdict must not depend on chance: property tests replay the same
# examples on every run.  `pytest --hypothesis-profile=explore` searches anew.
settings.register_profile("repeatable", derandomize=True, database=None)
settings.register_profile("explore", derandomize=False)
settings.load_profile("repeatable")


def pytest_report_header(config):
    """The versions this run tests with, so every log says what it saw."""
    from importlib import metadata

    names = [
        "numpy", "scipy", "scikit-learn", "joblib", "threadpoolctl", "matplotlib",
        "pandas", "dask", "hypothesis", "sphinx", "array-api-strict", "torch",
    ]  # fmt: skip
    versions = []
    for name in names:
        try:
            versions.append(f"{name} {metadata.version(name)}")
        except metadata.PackageNotFoundError:
            versions.append(f"{name} (not installed)")
    return "tested with: " + ", ".join(versions)
