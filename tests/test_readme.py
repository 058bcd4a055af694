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
