"""The self-contained HTML page: MeshCat's viewer, a scene and a playback bar in one file.

:func:`static_html` writes MeshCat's browser bundle (three.js included) inline, the scene as
msgpack commands (:mod:`kinplan.viewer.commands`) in base64, with large arrays that occur in
several commands stored once (:func:`shared_scene`), and a small script that applies them, frames
the camera and drives the playback bar (play/pause, time slider, loop). The page reads options
after ``#`` in its address: ``t=`` (a time [s], paused), ``hide=`` (layers), ``ui=0``.
"""

from __future__ import annotations

import base64
import html
import importlib.util
import json
from collections.abc import Iterator, Mapping, Sequence
from functools import lru_cache
from pathlib import Path
from typing import Any

import umsgpack

from kinplan.errors import KinplanError
from kinplan.viewer.commands import Command, pack


@lru_cache(maxsize=1)
def meshcat_javascript() -> str:
    """MeshCat's browser bundle (three.js included), as shipped by the ``meshcat`` package."""
    spec = importlib.util.find_spec("meshcat")  # found without importing meshcat's server
    if spec is None or not spec.submodule_search_locations:
        raise KinplanError("the meshcat package is not installed: pip install meshcat")
    bundle = Path(spec.submodule_search_locations[0]) / "viewer" / "dist" / "main.min.js"
    if not bundle.is_file():
        raise KinplanError(
            f"MeshCat's viewer bundle {bundle} is missing; reinstall the meshcat package "
            "(pip install --force-reinstall meshcat)"
        )
    text = bundle.read_text(encoding="utf-8")
    if "</script" in text.lower():  # would end the inline <script> early
        raise KinplanError(f"{bundle} cannot be inlined into HTML (it contains '</script')")
    return text


def static_html(
    commands: Sequence[Command],
    config: Mapping[str, Any],
    title: str,
    caption: Sequence[str],
    legend: Sequence[tuple[str, str]],
) -> str:
    """One self-contained HTML page: MeshCat's viewer, the scene and a playback bar.

    Args:
        commands: Scene commands, applied in order when the page loads (typed arrays that
            occur in several commands are stored once, see :func:`shared_scene`).
        config: Settings for the page script (``duration`` [s], ``camera_target`` in three.js
            coordinates [m], ``layers``: name -> scene path for the ``#hide=`` option, ``moves``:
            (start time [s], label) of each move, shown in the playback bar).
        title: Page title.
        caption: Lines shown at the top left (the first in bold).
        legend: (CSS colour, label) pairs shown under the caption.
    """
    scene, blobs = shared_scene(commands)
    legend_html = "".join(
        f'<span><i style="background:{html.escape(color)}"></i>{html.escape(label)}</span>'
        for color, label in legend
    )
    lines = [f"<b>{html.escape(caption[0])}</b>"] if caption else []
    lines += [f"<div>{html.escape(line)}</div>" for line in caption[1:]]
    page = _PAGE.format(
        title=html.escape(title),
        caption="".join(lines),
        legend=legend_html,
        meshcat=meshcat_javascript(),
        scene=_script_json(scene),
        blobs=_script_json(blobs),
        config=_script_json(dict(config)),
        script=_PAGE_SCRIPT,
    )
    return page


SHARED_MIN_BYTES = 256
"""Typed arrays of at least this many bytes are stored once in a page however often they occur."""


def shared_scene(commands: Sequence[Command]) -> tuple[list[Any], list[str]]:
    """Commands as base64 msgpack, with large arrays that occur more than once stored once.

    A mesh file drawn by several links (left and right legs, fingers) and the key times every
    animation track repeats make identical typed arrays (or texts, for mesh files embedded as
    they are). Each such payload (of at least :data:`SHARED_MIN_BYTES`) becomes a *blob*; a
    command that holds one is written as a list of pieces: base64 text of its own bytes, and
    blob indices, which joined give its msgpack bytes.

    Returns:
        (scene, blobs): one entry per command, a base64 string or a list of base64 strings and
        integers (indices into ``blobs``); and the blobs, base64.
    """
    packed = [pack(command) for command in commands]
    payloads = [list(_large_payloads(command)) for command in commands]
    counts: dict[bytes, int] = {}
    for found in payloads:
        for data in found:
            counts[data] = counts.get(data, 0) + 1
    index: dict[bytes, int] = {}
    scene: list[Any] = []
    for data_of_command, found in zip(packed, payloads):
        pieces: list[Any] = []
        cursor = 0
        for data in found:
            if counts[data] < 2:
                continue
            start = data_of_command.find(data, cursor)
            if start < 0:  # not where packing put it: keep it inline
                continue
            pieces.append(base64.b64encode(data_of_command[cursor:start]).decode("ascii"))
            pieces.append(index.setdefault(data, len(index)))
            cursor = start + len(data)
        if not pieces:
            scene.append(base64.b64encode(data_of_command).decode("ascii"))
            continue
        pieces.append(base64.b64encode(data_of_command[cursor:]).decode("ascii"))
        scene.append(pieces)
    blobs = [base64.b64encode(data).decode("ascii") for data in index]
    return scene, blobs


def _large_payloads(value: Any) -> Iterator[bytes]:
    """Bytes of the typed arrays and texts (embedded mesh files) of at least
    :data:`SHARED_MIN_BYTES` in a command, in packing order."""
    if isinstance(value, umsgpack.Ext):
        if len(value.data) >= SHARED_MIN_BYTES:
            yield value.data
    elif isinstance(value, str):
        if len(value) >= SHARED_MIN_BYTES:
            yield value.encode("utf-8")
    elif isinstance(value, Mapping):
        for key, item in value.items():
            yield from _large_payloads(key)
            yield from _large_payloads(item)
    elif isinstance(value, (list, tuple)):
        for item in value:
            yield from _large_payloads(item)


def scene_from_page(scene: Sequence[Any], blobs: Sequence[str]) -> list[bytes]:
    """Inverse of :func:`shared_scene`: the msgpack bytes of every command (for tests)."""
    decoded = [base64.b64decode(blob) for blob in blobs]
    out = []
    for entry in scene:
        if isinstance(entry, str):
            out.append(base64.b64decode(entry))
        else:
            out.append(
                b"".join(decoded[p] if isinstance(p, int) else base64.b64decode(p) for p in entry)
            )
    return out


def _script_json(value: Any) -> str:
    """JSON that can sit inside a <script> element (no '</' to end it early)."""
    return json.dumps(value).replace("</", "<\\/")


_PAGE = """<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title}</title>
<style>
body {{ margin: 0; overflow: hidden; font: 13px/1.4 system-ui, sans-serif;
  background: linear-gradient(#f4f6f9, #c4ccd8); }}
#meshcat-pane {{ width: 100vw; height: 100vh; overflow: hidden; }}
#kp-info {{ position: absolute; left: 10px; top: 8px; color: #1d2530; pointer-events: none;
  background: rgba(255, 255, 255, 0.7); border-radius: 4px; padding: 4px 8px; }}
#kp-info b {{ font-weight: 600; }}
#kp-info {{ max-width: min(620px, 72vw); }}
#kp-info div {{ font-size: 12px; color: #3a4350; }}
#kp-legend span {{ margin-right: 10px; white-space: nowrap; }}
#kp-legend i {{ display: inline-block; width: 10px; height: 10px; border-radius: 5px;
  margin-right: 4px; vertical-align: -1px; }}
#kp-bar {{ position: absolute; left: 0; right: 0; bottom: 0; display: flex; gap: 10px;
  align-items: center; padding: 6px 12px; background: rgba(22, 27, 36, 0.78); color: #eef; }}
#kp-bar input[type=range] {{ flex: 1; }}
#kp-bar button {{ width: 34px; }}
#kp-time {{ font-variant-numeric: tabular-nums; min-width: 120px; text-align: right; }}
#kp-roll {{ font-variant-numeric: tabular-nums; white-space: nowrap; }}
#kp-arc {{ color: #ff6a00; font-weight: 600; white-space: nowrap; }}
#kp-move {{ max-width: 40%; overflow: hidden; text-overflow: ellipsis; white-space: nowrap; }}
</style>
</head>
<body>
<div id="meshcat-pane"></div>
<div id="kp-info">{caption}<div id="kp-legend">{legend}</div></div>
<div id="kp-bar">
<button id="kp-play" title="play / pause (space)">&#9654;</button>
<input id="kp-slider" type="range" min="0" max="1" step="0.001" value="0">
<span id="kp-move"></span>
<span id="kp-roll"></span>
<span id="kp-arc"></span>
<span id="kp-time"></span>
<label><input id="kp-loop" type="checkbox"> loop</label>
</div>
<script>{meshcat}</script>
<script id="kinplan-scene" type="application/json">{scene}</script>
<script id="kinplan-blobs" type="application/json">{blobs}</script>
<script id="kinplan-config" type="application/json">{config}</script>
<script>{script}</script>
</body>
</html>
"""

_PAGE_SCRIPT = r"""
(function () {
  "use strict";
  function bytes(text) {
    const binary = atob(text);
    const out = new Uint8Array(binary.length);
    for (let i = 0; i < binary.length; i++) out[i] = binary.charCodeAt(i);
    return out;
  }
  const config = JSON.parse(document.getElementById("kinplan-config").textContent);
  const viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
  window.kinplanViewer = viewer;
  // A command is base64 msgpack, or pieces: base64 text and indices of arrays stored once.
  const blobs = JSON.parse(document.getElementById("kinplan-blobs").textContent).map(bytes);
  function joined(pieces) {
    const parts = pieces.map(p => (typeof p === "number" ? blobs[p] : bytes(p)));
    const out = new Uint8Array(parts.reduce((n, p) => n + p.length, 0));
    let offset = 0;
    for (const p of parts) { out.set(p, offset); offset += p.length; }
    return out;
  }
  for (const command of JSON.parse(document.getElementById("kinplan-scene").textContent)) {
    viewer.handle_command_bytearray(typeof command === "string" ? bytes(command) : joined(command));
  }
  // MeshCat's commands place the camera; its orbit centre is set here (three.js frame).
  const target = config.camera_target;
  viewer.controls.target.set(target[0], target[1], target[2]);
  viewer.controls.update();

  // Options in the address: #t=1.5 (show that time [s], paused), #hide=path,markers, #ui=0.
  const options = new URLSearchParams(window.location.hash.replace(/^#/, ""));
  for (const name of (options.get("hide") || "").split(",")) {
    const path = config.layers[name.trim()];
    if (path) viewer.set_property(path.split("/").filter(x => x), "visible", false);
  }
  const animator = viewer.animator;
  const duration = config.duration;
  const bar = document.getElementById("kp-bar");
  const button = document.getElementById("kp-play");
  const slider = document.getElementById("kp-slider");
  const label = document.getElementById("kp-time");
  const moveLabel = document.getElementById("kp-move");
  const moves = config.moves || [];
  function moveAt(t) {  // the label of the move under way at t (moves in time order)
    let text = "";
    for (const [start, name] of moves) { if (t >= start - 1e-9) text = name; else break; }
    return text;
  }
  // The torch roll plan_seam chose (per seam: [time, degrees] points), at time t, or "".
  const rollLabel = document.getElementById("kp-roll");
  const rolls = config.roll || [];
  function rollAt(t) {
    for (const points of rolls) {
      const n = points.length;
      if (n === 0 || t < points[0][0] - 1e-9 || t > points[n - 1][0] + 1e-9) continue;
      let k = 1;
      while (k < n - 1 && points[k][0] < t) k++;
      const [t0, r0] = points[Math.max(0, k - 1)], [t1, r1] = points[k];
      const f = t1 > t0 ? Math.min(1, Math.max(0, (t - t0) / (t1 - t0))) : 1;
      return "torch roll " + (r0 + f * (r1 - r0)).toFixed(0).replace("-", "\u2212") + "\u00b0";
    }
    return "";
  }
  // "arc on" while a program's arc is on (config.arc: [on, off] times [s]), else "".
  const arcLabel = document.getElementById("kp-arc");
  const arcs = config.arc || [];
  function arcAt(t) {
    for (const [on, off] of arcs) {
      if (t >= on - 1e-9 && t < off - 1e-9) return "\u25cf arc on";
    }
    return "";
  }
  const loop = document.getElementById("kp-loop");
  if (options.get("ui") === "0") {
    bar.style.display = "none";
    document.getElementById("kp-info").style.display = "none";
    viewer.gui.domElement.style.display = "none";
  }
  if (animator.actions.length === 0) {
    bar.style.display = "none";
    viewer.set_dirty();
    return;
  }
  function setLoop(on) {
    for (const action of animator.actions) {
      action.setLoop(on ? MeshCat.THREE.LoopRepeat : MeshCat.THREE.LoopOnce, on ? Infinity : 1);
    }
  }
  function seek(t) {
    if (animator.playing) animator.pause();
    animator.seek(t);
    animator.display_progress(Math.max(0, Math.min(duration, t)));
  }
  loop.checked = config.loop;
  setLoop(loop.checked);
  loop.onchange = () => setLoop(loop.checked);
  slider.max = duration;
  if (!animator.playing) { animator.play(); animator.pause(); }  // activates the actions
  const start = parseFloat(options.get("t"));
  if (Number.isFinite(start)) seek(start);
  function toggle() {
    if (animator.playing) { animator.pause(); return; }
    if (animator.time >= duration - 1e-6) animator.seek(0);
    animator.play();
  }
  button.onclick = toggle;
  document.addEventListener("keydown", (e) => {
    if (e.code === "Space") { e.preventDefault(); toggle(); }
  });
  let dragging = false;
  slider.addEventListener("pointerdown", () => { dragging = true; });
  slider.addEventListener("pointerup", () => { dragging = false; });
  slider.oninput = () => seek(parseFloat(slider.value));
  function tick() {
    const t = animator.time || 0;
    if (!dragging) slider.value = t;
    label.textContent = t.toFixed(2) + " / " + duration.toFixed(2) + " s";
    const current = moveAt(t);
    if (moveLabel.textContent !== current) moveLabel.textContent = current;
    const roll = rollAt(t);
    if (rollLabel.textContent !== roll) rollLabel.textContent = roll;
    const arc = arcAt(t);
    if (arcLabel.textContent !== arc) arcLabel.textContent = arc;
    button.innerHTML = animator.playing ? "&#10074;&#10074;" : "&#9654;";
    requestAnimationFrame(tick);
  }
  tick();
  viewer.set_dirty();
})();
"""
