"""The README's Python examples run as written (in order, in a scratch folder).

Blocks that start a MeshCat server (``Viewer(``) are left out: they need a browser session.
"""

from __future__ import annotations

import re
from pathlib import Path

README = Path(__file__).resolve().parent.parent / "README.md"


def python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)


def test_readme_examples_run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    blocks = [b for b in python_blocks() if "Viewer(" not in b]
    assert len(blocks) >= 4
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, str(README), "exec"), namespace)  # noqa: S102
    assert namespace["plan"].ok and namespace["bad"].status != "ok"
    assert abs(namespace["res"].q[1] - 1.6379) < 1e-3
    assert (tmp_path / "lecture.html").is_file()


def test_readme_quotes_the_failure_message_the_cli_prints(capsys):
    """The one-line failure quoted in the README's command-line section is what `kinplan run`
    prints for the example program (up to the README's `...`)."""
    from kinplan.apps.cli import main

    text = " ".join(README.read_text().split())
    quoted = re.search(r"e\.g\. `(move 3 \(weld across the base.*?)`", text).group(1)
    program = README.parent / "examples" / "programs" / "weld_unreachable.yaml"
    assert main(["run", str(program)]) == 1
    printed = capsys.readouterr().err.strip().splitlines()[-1]
    for part in quoted.split("..."):
        assert part.strip(" ;") in printed, (part, printed)
