"""A teach pendant in the terminal: jog the arm, record points and paths, write a program.

The pendant lives in :mod:`kinplan.teach.pendant`; its public names are re-exported here (its
other defaults and limits too, importable from here as before though not in ``__all__``).
"""

from kinplan.teach.pendant import (  # noqa: F401
    COMMANDS,
    DEFAULT_ANGULAR_STEP_DEG,
    DEFAULT_JOG_SPEED,
    DEFAULT_LINEAR_STEP,
    DEFAULT_PATH_TOLERANCE,
    DEFAULT_RATE_HZ,
    HELP,
    HISTORY_ENV,
    HISTORY_LENGTH,
    MAX_BRANCH_STEP,
    MAX_JOINT_JOG_DEG,
    MAX_LINEAR_JOG,
    MAX_PATH_TOLERANCE_DEG,
    MAX_RATE_HZ,
    MAX_RECORDING_SAMPLES,
    MAX_ROTATION_JOG_DEG,
    PromptLines,
    RecordedPath,
    Reply,
    TeachPendant,
    default_history_file,
    fit_spline,
    home_configuration,
    run_session,
)

__all__ = [
    "COMMANDS",
    "DEFAULT_JOG_SPEED",
    "DEFAULT_PATH_TOLERANCE",
    "DEFAULT_RATE_HZ",
    "HELP",
    "HISTORY_ENV",
    "PromptLines",
    "RecordedPath",
    "Reply",
    "TeachPendant",
    "default_history_file",
    "fit_spline",
    "home_configuration",
    "run_session",
]
