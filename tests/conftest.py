"""Shared fixtures: robots are loaded once per test session (loading parses the URDF)."""

from __future__ import annotations

import functools
import os
import tempfile
from pathlib import Path

import pytest

import kinplan

# Results kinplan keeps on disk (the reach search's) come from the code under test: each test
# process starts with an empty cache of its own, never the user's.
os.environ["KINPLAN_CACHE_DIR"] = tempfile.mkdtemp(prefix="kinplan-test-cache-")

#: The tests' folder (fixtures such as ``urdf/``) and the repository (``examples/``, ...).
TESTS = Path(__file__).resolve().parent
REPOSITORY = TESTS.parent


@functools.cache
def cached_robot(name: str) -> kinplan.Robot:
    return kinplan.load_robot(name)


@pytest.fixture(scope="session")
def planar_2r() -> kinplan.Robot:
    return cached_robot("planar_2r")


@pytest.fixture(scope="session")
def ur5() -> kinplan.Robot:
    return cached_robot("ur5")


@pytest.fixture(scope="session")
def panda() -> kinplan.Robot:
    return cached_robot("panda")
