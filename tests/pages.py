"""Reading a saved MeshCat page back in the tests: its commands, configuration, objects,
transforms and animation clips (shared by the viewer, program and plot tests), and its DOM
after its script ran in headless Chromium (:func:`page_dom`)."""

from __future__ import annotations

import base64
import json
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np

from kinplan.viewer import commands as ms


def page_parts(text: str) -> tuple[list[dict], dict]:
    """The MeshCat commands and the page configuration embedded in a saved page."""
    scene = re.search(r'<script id="kinplan-scene" type="application/json">(.*?)</script>', text)
    blobs = re.search(r'<script id="kinplan-blobs" type="application/json">(.*?)</script>', text)
    config = re.search(r'<script id="kinplan-config" type="application/json">(.*?)</script>', text)
    assert scene and blobs and config, "the page misses its embedded scene or configuration"
    shared = [base64.b64decode(b) for b in json.loads(blobs.group(1))]
    commands = []
    for entry in json.loads(scene.group(1)):  # base64 text, or pieces: text and shared arrays
        pieces = [entry] if isinstance(entry, str) else entry
        data = b"".join(shared[p] if isinstance(p, int) else base64.b64decode(p) for p in pieces)
        commands.append(ms.unpack(data))
    return commands, json.loads(config.group(1))


def transforms(commands: list[dict]) -> dict[str, np.ndarray]:
    """path -> 4×4 matrix of every set_transform (the last one wins)."""
    return {
        c["path"]: np.array(c["matrix"], dtype=float).reshape(4, 4).T
        for c in commands
        if c["type"] == "set_transform"
    }


def objects(commands: list[dict]) -> dict[str, dict]:
    return {c["path"]: c["object"] for c in commands if c["type"] == "set_object"}


def animation(commands: list[dict]) -> dict[str, dict]:
    """path -> {"times", "position", "quaternion"} of the page's animation (pose clips)."""
    (command,) = [c for c in commands if c["type"] == "set_animation"]
    clips = {}
    for entry in command["animations"]:
        tracks = {t["name"]: t for t in entry["clip"]["tracks"]}
        if ".position" not in tracks:
            continue  # a visibility clip (visibility() reads those)
        clips[entry["path"]] = {
            "times": ms.ext_array(tracks[".position"]["times"], np.float32),
            "position": ms.ext_array(tracks[".position"]["values"], np.float32).reshape(-1, 3),
            "quaternion": ms.ext_array(tracks[".quaternion"]["values"], np.float32).reshape(-1, 4),
        }
    return clips


#: Headless Chromium, when installed (the browser tests are skipped without it).
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


def page_dom(page: Path, fragment: str, profile: Path) -> subprocess.CompletedProcess:
    """The DOM of a saved page after its script ran in headless Chromium at ``#fragment``
    (e.g. ``t=3``): ``stdout`` holds it, ``stderr`` Chromium's log. ``profile`` is a fresh
    user-data folder."""
    assert CHROMIUM is not None, "no chromium on PATH"
    return subprocess.run(
        [
            CHROMIUM, "--headless", "--no-sandbox", "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader", "--no-first-run", f"--user-data-dir={profile}",
            "--virtual-time-budget=6000", "--dump-dom", f"{page.as_uri()}#{fragment}",
        ],
        capture_output=True, text=True, timeout=90,
    )  # fmt: skip
