"""The reach search's results kept on disk (kinplan.model.extent.stored_reach): read back bit
for bit by later robots, keyed by what the search depends on, and never a reason to fail."""

from __future__ import annotations

import numpy as np
import pytest

import kinplan
from kinplan.model import extent


@pytest.fixture
def cache(tmp_path, monkeypatch):
    folder = tmp_path / "cache"
    monkeypatch.setenv("KINPLAN_CACHE_DIR", str(folder))
    return folder


def _no_search(arm):
    raise AssertionError("the reach was searched again")


def test_stored_reach_is_the_search_read_back_bit_for_bit(cache, monkeypatch):
    searched = extent.search_reach(kinplan.load_robot("ur5"))
    first = kinplan.load_robot("ur5").reach()
    assert first == searched  # exactly: the search, then its repr read back
    assert len(list((cache / "reach").iterdir())) == 1
    monkeypatch.setattr(extent, "search_reach", _no_search)
    assert kinplan.load_robot("ur5").reach() == searched


def test_key_changes_with_what_the_search_depends_on(cache):
    ur5 = kinplan.load_robot("ur5")
    narrow = kinplan.load_robot("ur5", limits={"elbow_joint": {"lower": 1.0, "upper": 2.0}})
    tool = kinplan.load_robot("ur5", tip="forearm_link")
    keys = {extent.reach_key(robot) for robot in (ur5, narrow, tool)}
    assert len(keys) == 3
    assert extent.reach_key(kinplan.load_robot("ur5")) == extent.reach_key(ur5)
    assert narrow.reach() < ur5.reach() - 1e-3  # a folded elbow reaches less
    assert tool.reach() < ur5.reach()
    assert len(list((cache / "reach").iterdir())) == 3


def test_a_bad_cache_only_means_searching(cache, tmp_path, monkeypatch):
    robot = kinplan.load_robot("ur5")
    expected = extent.search_reach(robot)
    robot.reach()
    (stored,) = (cache / "reach").iterdir()
    for text in ("garbage", "nan", "-1.0", ""):
        stored.write_text(text)
        assert kinplan.load_robot("ur5").reach() == expected
        assert float(stored.read_text()) == expected  # written again
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("KINPLAN_CACHE_DIR", str(blocker))  # cannot be created: still searched
    assert kinplan.load_robot("ur5").reach() == expected


def test_cache_dir_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("KINPLAN_CACHE_DIR", str(tmp_path / "a"))
    assert extent.cache_dir() == tmp_path / "a"
    monkeypatch.delenv("KINPLAN_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert extent.cache_dir() == tmp_path / "xdg" / "kinplan"
    monkeypatch.delenv("XDG_CACHE_HOME")
    assert extent.cache_dir() == extent.Path.home() / ".cache" / "kinplan"


def test_planar_arms_need_no_search(cache):
    arm = kinplan.planar_arm([0.5, 0.3])
    assert arm.reach() == pytest.approx(0.8, abs=1e-12)
    assert not (cache / "reach").exists()
    assert np.isfinite(arm.reach())
