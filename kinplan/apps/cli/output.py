"""What every command prints and writes: the console, one-line errors, numbers in fixed point,
the image file a ``--plot`` or ``--png`` writes."""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from kinplan.errors import KinplanError


def console(stderr: bool = False):
    from rich.console import Console

    stream = sys.stderr if stderr else sys.stdout
    interactive = bool(getattr(stream, "isatty", lambda: False)())
    return Console(file=stream, width=None if interactive else 120, highlight=False, markup=False)


def one_line(error: BaseException) -> str:
    """The error's message on one line."""
    from kinplan.program import ProgramError

    text = error.one_line() if isinstance(error, ProgramError) else str(error)
    return " ".join(text.split()) or type(error).__name__


def fail(message: str) -> int:
    print(f"kinplan: error: {message}", file=sys.stderr)
    return 1


def fmt(values: Sequence[float] | np.ndarray, digits: int = 4) -> str:
    """Numbers in fixed point (beyond 10⁶ in exponent notation: one short line whatever the
    value)."""
    return (
        "["
        + ", ".join(f"{v:.{digits}f}" if abs(v) < 1e6 else f"{v:.{digits}g}" for v in values)
        + "]"
    )


def _image_types() -> dict[str, str]:
    """Image file extensions Matplotlib writes (``png``, ``pdf``, ``svg``, ...) and their
    descriptions."""
    from matplotlib.backend_bases import FigureCanvasBase

    return dict(FigureCanvasBase.get_supported_filetypes())


def plot_file(text: str) -> Path:
    """The file ``--plot`` writes: ``text``, or ``text.png`` when it has no extension.

    Raises:
        KinplanError: an extension Matplotlib cannot write (the message lists those it can),
            or an existing folder.
    """
    path = Path(text)
    if path.is_dir():
        raise KinplanError(f"--plot {text} is a folder; give an image file name such as plot.png")
    extension = path.suffix.lower().lstrip(".")
    if not extension:  # Matplotlib would write <name>.png: say so
        return path.with_name(path.name.rstrip(".") + ".png")
    types = _image_types()
    if extension not in types:
        supported = ", ".join(f".{name}" for name in sorted(types))
        raise KinplanError(
            f"--plot {text}: Matplotlib cannot write .{extension} images; give a file ending in "
            f"one of {supported}"
        )
    return path
