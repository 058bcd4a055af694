"""The ``kinplan`` command (the console script ``kinplan = kinplan.apps.cli:main``; also
``python -m kinplan.apps.cli``).

Usage::

    kinplan info ROBOT [--tip TIP] [--lock NAME=VALUE ...] [--frames]
    kinplan fk ROBOT --q Q [Q ...] [--deg]
    kinplan ik ROBOT --xyz X Y Z [--rpy-deg R P Y | --quat-xyzw X Y Z W] [--seed Q ...] [--deg]
    kinplan run PROGRAM.yaml [--html FILE] [--plot FILE] [--csv FILE] [--dt DT]
        [--urscript FILE [--servo-period S]] [--trajectory FILE.json|.yaml]
    kinplan run A.yaml B.yaml ... [--jobs N | --scheduler ADDR]
    kinplan reach ROBOT -o MAP.npz [--resolution R] [--orientations K] [--direction X Y Z
        --cone-deg DEG] [--region ...] [--png FILE] [--html FILE] [--jobs N | --scheduler ADDR]
    kinplan place PROGRAM.yaml --x X0 [X1] --y Y0 [Y1] [--z Z0 [Z1]] [--yaw-deg A [B]]
        [--step S] -o BEST.yaml [--png FILE] [--jobs N | --scheduler ADDR]
    kinplan demo lecture|weld [--html FILE] [--out DIR]
    kinplan teach ROBOT -o PROGRAM.yaml [--start Q ...] [--deg] [--view]

Every command that loads a robot takes ``--tip TIP`` and ``--lock NAME=VALUE`` (repeatable:
joint NAME held at VALUE, in radians or metres, out of the joint vector).

Exit status 0 on success, 1 on failure with a one-line reason on stderr (``kinplan: error: ...``),
2 for a malformed command line.

Modules, each one job (imports go down the list, never up, type-only imports included; what one
command alone needs, such as rich, Matplotlib, the program planner, the exports, the viewer or Dask,
is imported inside that command, so that start-up stays short):

* :mod:`~kinplan.apps.cli.__main__`: ``python -m kinplan.apps.cli``;
* :mod:`~kinplan.apps.cli.main`: :func:`main`: parse, call the command's handler, every failure one
  ``kinplan: error:`` line, the exit status;
* :mod:`~kinplan.apps.cli.parser`: :func:`build_parser`: the subcommands and their handlers, the
  argument types (finite numbers, numbers > 0, whole numbers), one-line usage errors;
* :mod:`~kinplan.apps.cli.app_commands`: ``demo`` and ``teach`` (the demos, the teach pendant);
* :mod:`~kinplan.apps.cli.run_command`: ``run`` of one program: progress, summary table, ``--csv``,
  ``--plot``, ``--html`` and the controller exports ``--urscript``, ``--trajectory``;
* :mod:`~kinplan.apps.cli.batch_commands`: ``reach``, ``place`` and ``run`` of several programs
  (in-process or on Dask);
* :mod:`~kinplan.apps.cli.robot_commands`: ``info``, ``fk``, ``ik``;
* :mod:`~kinplan.apps.cli.robot_args`: the robot a command names (``ROBOT``, ``--tip``, ``--lock``)
  and the joint values it is given;
* :mod:`~kinplan.apps.cli.output`: the console, one-line errors, numbers, ``--plot``/``--png``
  files.
"""

from __future__ import annotations

from kinplan.apps.cli.main import main
from kinplan.apps.cli.parser import build_parser as build_parser

__all__ = ["main"]
