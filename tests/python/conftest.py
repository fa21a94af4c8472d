"""Shared helpers of the Python suite (fixtures: ecsim.pytest_plugin, loaded with -p)."""
import os


def ci_mode():
    """Under CI=true a missing capability fails instead of skipping (as the C++ tests' ciMode())."""
    return os.environ.get("CI") == "true"
