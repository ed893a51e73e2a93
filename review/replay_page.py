"""`arena review FILE.mcap --html replay.html`: the match as one self-contained web page.

The page needs no network and loads no script or font from anywhere: the
timeline of the match (recording/analysis/timeline.py: ground truth decimated
to 10 Hz, positions in whole centimetres) is embedded as JSON, and a small
inline script draws it on a canvas: the field, robots with their numbers, the
ball (with its shadow when it flies), the score and the clock, with play /
pause, speed, and a timeline slider on which every goal (red) and restart
(white) is marked and can be clicked. A team can mail the file or put it on
a web page. A 2 x 300 s match is well under 1 MB (the budget is 5 MB).

After drawing a frame the page sets `data-frame`, `data-robots` (robots drawn)
and `data-field` on <body>; script errors are counted in `data-errors`. The
tests read them from a real headless Chromium.
"""

from __future__ import annotations

import html
import json
from pathlib import Path

from arena.recording.analysis.timeline import timeline
from arena.recording.reader import Recording
from arena.schemas.messages import Referee, World

HZ = 10.0  # [Hz] frames per simulated second in the page
TEAM_COLOURS = {"a": "#00bfff", "b": "#ff1abf"}  # MSL cyan and magenta, as in the Foxglove scene and the GIF


def page_data(rec: Recording) -> dict:
    cfg = rec.cfg
    tl = timeline(rec.decoded("world", World), rec.decoded("referee", Referee), cfg.timing.dt, hz=HZ)
    f = cfg.field
    # Frames as flat integer rows: tick, ball x y z, then x y theta per robot (null when absent).
    rows = []
    for fr in tl["frames"]:
        row = [fr["tick"], *fr["ball"]]
        for p in fr["robots"]:
            row.extend(p if p is not None else [None, None, None])
        rows.append(row)
    return {
        "home": cfg.home,
        "away": cfg.away,
        "seed": cfg.seed,
        "dt": cfg.timing.dt,
        "half_ticks": cfg.half_ticks,
        "total_ticks": cfg.total_ticks,
        "robots": tl["robots"],
        "robot_size": cfg.robot.size,
        "ball_radius": cfg.ball.radius,
        "colours": TEAM_COLOURS,
        "field": {
            k: getattr(f, k)
            for k in (
                "length",
                "width",
                "runoff",
                "goal_width",
                "goal_depth",
                "center_circle_radius",
                "penalty_area_depth",
                "penalty_area_width",
                "goal_area_depth",
                "goal_area_width",
                "penalty_mark_distance",
                "corner_arc_radius",
                "line_width",
            )
        },
        "frames": rows,
        "marks": tl["marks"],
        "scores": tl["scores"],
        "complete": rec.complete,
    }


def write_page(rec: Recording, path: str | Path) -> dict:
    """Write the page; returns {path, bytes, frames}."""
    data = page_data(rec)
    blob = json.dumps(data, separators=(",", ":")).replace("</", "<\\/")
    title = html.escape(f"{data['home']} (a) v {data['away']} (b), seed {data['seed']}")
    text = PAGE.replace("%TITLE%", title).replace("%DATA%", blob).replace("%SCRIPT%", SCRIPT)
    p = Path(path)
    p.write_text(text, encoding="utf-8")
    return {"path": str(p), "bytes": p.stat().st_size, "frames": len(data["frames"])}


PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>%TITLE%</title>
<style>
body{margin:0;background:#102a12;color:#eee;font:14px system-ui,sans-serif}
main{max-width:1100px;margin:0 auto;padding:8px}
h1{font-size:16px;margin:4px 0}
#hud{display:flex;justify-content:space-between;align-items:center;font-size:20px;font-weight:bold;margin:4px 0}
#pitch{width:100%;display:block;background:#1b5e20;border-radius:4px}
#controls{display:flex;gap:10px;align-items:center;margin-top:8px}
#controls button,#controls select{font-size:14px;padding:4px 10px}
#track{position:relative;flex:1;height:34px}
#slider{position:absolute;left:0;right:0;top:14px;width:100%;margin:0}
#marks{position:absolute;left:0;right:0;top:0;height:12px}
.mark{position:absolute;top:0;width:3px;height:12px;margin-left:-1px;cursor:pointer;background:#eee}
.mark.GOAL{background:#ff1744;width:5px;margin-left:-2px}
.half{position:absolute;top:0;width:1px;height:34px;background:#ffeb3b}
#legend{font-size:12px;color:#bbb;margin-top:4px}
</style></head>
<body data-frame="-1" data-robots="0" data-field="0" data-errors="0">
<main>
<h1>%TITLE%</h1>
<div id="hud"><span id="score"></span><span id="banner" style="color:#ffeb3b"></span><span id="clock"></span></div>
<canvas id="pitch" width="1000" height="700"></canvas>
<div id="controls">
<button id="play" title="space">play</button>
<label>speed <select id="speed"><option>0.5</option><option selected>1</option><option>2</option>
<option>4</option><option>8</option><option>16</option></select></label>
<div id="track"><div id="marks"></div><input id="slider" type="range" min="0" value="0" step="1"></div>
</div>
<div id="legend">marks: <span style="color:#ff1744">goal</span>, white: restart (hover for its name, click to go there);
yellow: half time. Keys: space play/pause, arrows step. Open at a time: replay.html#t=42.5</div>
</main>
<script id="match" type="application/json">%DATA%</script>
<script>%SCRIPT%</script>
</body></html>
"""

SCRIPT = r"""
"use strict";
window.addEventListener("error", function () {
  document.body.dataset.errors = String(Number(document.body.dataset.errors) + 1);
});
(function () {
  var M = JSON.parse(document.getElementById("match").textContent);
  var F = M.field, frames = M.frames, n = M.robots.length, dt = M.dt;
  var canvas = document.getElementById("pitch"), ctx = canvas.getContext("2d");
  var W = F.length + 2 * F.runoff + 2 * F.goal_depth, H = F.width + 2 * F.runoff;
  canvas.height = Math.round(canvas.width * H / W);
  var s = canvas.width / W;
  function px(x) { return (x + W / 2) * s; }
  function py(y) { return (H / 2 - y) * s; }
  var slider = document.getElementById("slider"), playBtn = document.getElementById("play");
  var speedSel = document.getElementById("speed");
  slider.max = String(Math.max(0, frames.length - 1));
  var total = Math.max(1, M.total_ticks);
  var marksDiv = document.getElementById("marks");
  // restarts first, goals last: a goal is drawn over the kickoff that follows it
  M.marks.filter(function (m) { return m.kind !== "GOAL"; }).concat(
    M.marks.filter(function (m) { return m.kind === "GOAL"; })).forEach(function (m) {
    var d = document.createElement("div");
    d.className = "mark " + m.kind;
    d.style.left = (100 * m.tick / total) + "%";
    d.title = (m.kind + " " + m.team).trim() + " at " + (m.tick * dt).toFixed(1) + " s" +
      (m.score ? " (" + m.score[0] + ":" + m.score[1] + ")" : "");
    d.addEventListener("click", function () { seekTick(m.tick); });
    marksDiv.appendChild(d);
  });
  var half = document.createElement("div");
  half.className = "half";
  half.style.left = (100 * M.half_ticks / total) + "%";
  document.getElementById("track").appendChild(half);

  function line(pts, close) {
    ctx.beginPath();
    ctx.moveTo(px(pts[0][0]), py(pts[0][1]));
    for (var i = 1; i < pts.length; i++) ctx.lineTo(px(pts[i][0]), py(pts[i][1]));
    if (close) ctx.closePath();
    ctx.stroke();
  }
  function drawField() {
    var hl = F.length / 2, hw = F.width / 2;
    ctx.fillStyle = "#1b5e20";
    ctx.fillRect(0, 0, canvas.width, canvas.height);
    ctx.fillStyle = "#2e7d32";
    ctx.fillRect(px(-hl - F.runoff), py(hw + F.runoff), (F.length + 2 * F.runoff) * s, (F.width + 2 * F.runoff) * s);
    ctx.strokeStyle = "#9e9e9e"; ctx.lineWidth = 3;
    ctx.strokeRect(px(-hl - F.runoff), py(hw + F.runoff), (F.length + 2 * F.runoff) * s, (F.width + 2 * F.runoff) * s);
    ctx.strokeStyle = "#ffffff"; ctx.lineWidth = Math.max(1.5, F.line_width * s * 0.5);
    line([[-hl, -hw], [hl, -hw], [hl, hw], [-hl, hw]], true);
    line([[0, -hw], [0, hw]]);
    ctx.beginPath(); ctx.arc(px(0), py(0), F.center_circle_radius * s, 0, 2 * Math.PI); ctx.stroke();
    [-1, 1].forEach(function (side) {
      var gx = side * hl;
      [[F.penalty_area_depth, F.penalty_area_width], [F.goal_area_depth, F.goal_area_width]].forEach(function (a) {
        var ix = gx - side * a[0];
        line([[gx, -a[1] / 2], [ix, -a[1] / 2], [ix, a[1] / 2], [gx, a[1] / 2]]);
      });
      ctx.fillStyle = "#ffffff";
      ctx.beginPath(); ctx.arc(px(gx - side * F.penalty_mark_distance), py(0), 3, 0, 2 * Math.PI); ctx.fill();
      ctx.fillStyle = "rgba(255,255,255,0.45)";
      var x0 = side > 0 ? gx : gx - F.goal_depth;
      ctx.fillRect(px(x0), py(F.goal_width / 2), F.goal_depth * s, F.goal_width * s);
      [-1, 1].forEach(function (cy) {
        // the quarter of the corner circle inside the field (canvas y points down)
        var mid = Math.atan2(cy, -side);
        ctx.beginPath();
        ctx.arc(px(gx), py(cy * hw), F.corner_arc_radius * s, mid - Math.PI / 4, mid + Math.PI / 4);
        ctx.stroke();
      });
    });
    document.body.dataset.field = "1";
  }
  var fieldImage = null;
  function scoreAt(tick) {
    var sc = [0, 0];
    for (var i = 0; i < M.scores.length && M.scores[i].tick <= tick; i++) sc = M.scores[i].score;
    return sc;
  }
  function bannerAt(tick) {
    var within = Math.round(3 / dt), best = null, goal = null;
    for (var i = 0; i < M.marks.length && M.marks[i].tick <= tick; i++) {
      if (tick - M.marks[i].tick <= within) { best = M.marks[i]; if (best.kind === "GOAL") goal = best; }
    }
    var m = goal || best;
    return m ? (m.kind.replace("_", " ") + " " + m.team).trim() : "";
  }
  var pos = 0, playing = false, last = null;  // pos: fractional frame index
  function lerp(a, b, u) { return a + (b - a) * u; }
  function draw() {
    if (!frames.length) return;
    var i = Math.min(frames.length - 1, Math.floor(pos)), j = Math.min(frames.length - 1, i + 1);
    var u = pos - i, A = frames[i], B = frames[j];
    if (fieldImage) ctx.putImageData(fieldImage, 0, 0); else { drawField(); fieldImage = ctx.getImageData(0, 0, canvas.width, canvas.height); }
    var drawn = 0, half = M.robot_size / 2 * s;
    for (var r = 0; r < n; r++) {
      var k = 4 + 3 * r;
      if (A[k] === null) continue;
      var x = A[k] / 100, y = A[k + 1] / 100, th = A[k + 2] / 100;
      if (B[k] !== null && Math.hypot(B[k] / 100 - x, B[k + 1] / 100 - y) < 0.5) {
        x = lerp(x, B[k] / 100, u); y = lerp(y, B[k + 1] / 100, u);
      }
      var team = M.robots[r].charAt(0), num = M.robots[r].split("/")[1];
      ctx.save();
      ctx.translate(px(x), py(y)); ctx.rotate(-th);
      ctx.fillStyle = M.colours[team] || "#ccc"; ctx.strokeStyle = "#000"; ctx.lineWidth = 1.5;
      ctx.fillRect(-half, -half, 2 * half, 2 * half); ctx.strokeRect(-half, -half, 2 * half, 2 * half);
      ctx.fillStyle = "#fff"; ctx.fillRect(half - 4, -3, 4, 6);  // the dribbler side
      ctx.restore();
      ctx.fillStyle = "#000"; ctx.font = "bold " + Math.round(half * 1.2) + "px sans-serif";
      ctx.textAlign = "center"; ctx.textBaseline = "middle";
      ctx.fillText(num, px(x), py(y));
      drawn++;
    }
    var bx = A[1] / 100, by = A[2] / 100, bz = A[3] / 100;
    if (Math.hypot(B[1] / 100 - bx, B[2] / 100 - by) < 1.5) {
      bx = lerp(bx, B[1] / 100, u); by = lerp(by, B[2] / 100, u); bz = lerp(bz, B[3] / 100, u);
    }
    var br = Math.max(3, M.ball_radius * s);
    if (bz > 0.02) {
      ctx.fillStyle = "rgba(0,0,0,0.35)";
      ctx.beginPath(); ctx.arc(px(bx), py(by), br, 0, 2 * Math.PI); ctx.fill();
    }
    ctx.fillStyle = "#ff8c00"; ctx.strokeStyle = "#000"; ctx.lineWidth = 1;
    ctx.beginPath(); ctx.arc(px(bx), py(by) - bz * s, br * (1 + bz * 0.6), 0, 2 * Math.PI); ctx.fill(); ctx.stroke();
    var tick = A[0], sc = scoreAt(tick);
    document.getElementById("score").textContent = M.home + " (a)  " + sc[0] + " : " + sc[1] + "  (b) " + M.away;
    document.getElementById("clock").textContent = (tick * dt).toFixed(1) + " s" + (tick > M.half_ticks ? " (2nd half)" : "");
    document.getElementById("banner").textContent = bannerAt(tick);
    slider.value = String(i);
    document.body.dataset.frame = String(i);
    document.body.dataset.robots = String(drawn);
  }
  function seekTick(tick) {
    var lo = 0, hi = frames.length - 1;
    while (lo < hi) { var mid = (lo + hi) >> 1; if (frames[mid][0] < tick) lo = mid + 1; else hi = mid; }
    pos = lo; draw();
  }
  // Timers rather than requestAnimationFrame: a page in a background tab or a headless
  // browser keeps playing, and a browser's virtual time (tests) drives it exactly.
  function later() { setTimeout(function () { step(performance.now()); }, 40); }
  function step(now) {
    if (!playing) { last = null; return; }
    if (last !== null) {
      pos += (now - last) / 1000 * Number(speedSel.value) / (frames.length > 1 ? (frames[1][0] - frames[0][0]) * dt : 1);
      if (pos >= frames.length - 1) { pos = frames.length - 1; setPlaying(false); }
    }
    last = now;
    draw();
    if (playing) later();
  }
  function setPlaying(p) {
    playing = p; playBtn.textContent = p ? "pause" : "play";
    if (p) { if (pos >= frames.length - 1) pos = 0; later(); }
  }
  playBtn.addEventListener("click", function () { setPlaying(!playing); });
  slider.addEventListener("input", function () { pos = Number(slider.value); draw(); });
  document.addEventListener("keydown", function (e) {
    if (e.key === " ") { e.preventDefault(); setPlaying(!playing); }
    else if (e.key === "ArrowRight") { pos = Math.min(frames.length - 1, Math.floor(pos) + 1); draw(); }
    else if (e.key === "ArrowLeft") { pos = Math.max(0, Math.floor(pos) - 1); draw(); }
  });
  draw();
  var at = /^#t=([0-9.]+)/.exec(location.hash);  // replay.html#t=42.5 opens at 42.5 s
  if (at) seekTick(Math.round(Number(at[1]) / dt));
  if (location.hash === "#play") setPlaying(true);
})();
"""
