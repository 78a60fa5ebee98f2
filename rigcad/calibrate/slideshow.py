"""The calibration screen's slideshow: one self-contained page (``patterns/slideshow.html``) that shows
the capture's frames full screen, unscaled, in capture order, each for a fixed time, after a start
delay, so that nobody touches the screen once the dome is back on its register (a touch would move it;
the dome cannot come off between frames without moving it either).

Page: a start screen with the delay and the hold (buttons change them, or the keys d/D and h/H); Start
turns the screen black and counts the delay down in large grey figures (seen in the camera's live view
through the dome), then shows each frame ``hold`` seconds, one device pixel per image pixel from the top
left, then black. It asks the browser to keep the screen awake (the Screen Wake Lock API, where the
browser has it). No request leaves the page: the frames are inline (data: URIs) and its content-security
policy forbids anything else.
"""

from __future__ import annotations

import base64
import html
import json

#: Seconds each frame stays on the screen: the camera takes one picture in the middle of each, at its
#: own interval timer started at the first frame; half of it is the slack either side for starting the
#: timer by eye and for the camera's exposure.
HOLD_S = 4
#: Seconds from Start to the first frame: time to lower the dome over its register pins and screw it
#: down (the kit's page says so), then to start the camera's timer.
DELAY_S = 300

_PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>@@TITLE@@</title>
<meta name="viewport" content="width=device-width, initial-scale=1, user-scalable=no">
<meta http-equiv="Content-Security-Policy" content="default-src 'none'; style-src 'unsafe-inline'; script-src 'unsafe-inline'; img-src data:">
<style>html,body{margin:0;height:100%;background:#000;color:#999;font:24px sans-serif;overflow:hidden}
canvas{position:fixed;left:0;top:0;width:100vw;height:100vh}#start{position:fixed;inset:0;padding:5vh 5vw;background:#000}
button{font:24px sans-serif;margin:6px;padding:10px 18px}#count{position:fixed;inset:0;display:none;align-items:center;
justify-content:center;font:30vh sans-serif;color:#444}</style></head>
<body><canvas id="c"></canvas><div id="count"></div>
<div id="start"><p>@@TITLE@@</p><p id="what"></p>
<button id="d-">delay -1 min</button><button id="d+">delay +1 min</button>
<button id="h-">hold -1 s</button><button id="h+">hold +1 s</button>
<p><button id="go">Start</button></p><p id="warn"></p></div>
<script>
"use strict";
const FRAMES = @@FRAMES@@;
const S = {delay: @@DELAY@@, hold: @@HOLD@@, width: @@WIDTH@@, height: @@HEIGHT@@};
const $ = (id) => document.getElementById(id);
const canvas = $("c"), images = FRAMES.map(([name, uri]) => { const i = new Image(); i.src = uri; return i; });
function what() {
  const dpr = window.devicePixelRatio || 1;
  const w = Math.round(screen.width * dpr), h = Math.round(screen.height * dpr);
  $("what").textContent = FRAMES.length + " frames, " + S.hold + " s each, after a delay of " + S.delay +
    " s: the first frame (" + FRAMES[0][0] + ") at " + S.delay + " s, the last (" + FRAMES[FRAMES.length - 1][0] +
    ") until " + (S.delay + FRAMES.length * S.hold) + " s.";
  const fits = (w === S.width && h === S.height) || (w === S.height && h === S.width);
  $("warn").textContent = fits ? "" : "this screen is " + w + " x " + h + " px, not the kit's " + S.width + " x " +
    S.height + " px: the frames would not be shown unscaled";
}
function paint(k) {
  const dpr = window.devicePixelRatio || 1;
  canvas.width = Math.round(window.innerWidth * dpr); canvas.height = Math.round(window.innerHeight * dpr);
  const g = canvas.getContext("2d");
  g.imageSmoothingEnabled = false;
  g.fillStyle = "#000"; g.fillRect(0, 0, canvas.width, canvas.height);
  if (k >= 0 && k < images.length) g.drawImage(images[k], 0, 0);
  window.rigcadSlide = {frame: k >= 0 && k < FRAMES.length ? FRAMES[k][0] : null};
}
async function go() {
  try { if (navigator.wakeLock) await navigator.wakeLock.request("screen"); } catch (e) {}
  try { await document.documentElement.requestFullscreen(); } catch (e) {}
  $("start").style.display = "none"; paint(-1);
  const t0 = performance.now(), count = $("count");
  count.style.display = "flex";
  const tick = () => {
    const t = (performance.now() - t0) / 1000;
    if (t < S.delay) { count.textContent = Math.ceil(S.delay - t); requestAnimationFrame(tick); return; }
    count.style.display = "none";
    const k = Math.floor((t - S.delay) / S.hold);
    if (k !== shown) { shown = k; paint(k); }
    if (k < FRAMES.length) requestAnimationFrame(tick);
  };
  let shown = -1;
  tick();
}
$("d-").onclick = () => { S.delay = Math.max(0, S.delay - 60); what(); };
$("d+").onclick = () => { S.delay += 60; what(); };
$("h-").onclick = () => { S.hold = Math.max(1, S.hold - 1); what(); };
$("h+").onclick = () => { S.hold += 1; what(); };
$("go").onclick = go;
window.rigcadSlide = {frame: null};
what();
</script></body></html>
"""


def slideshow_page(title: str, frames: list[tuple[str, bytes]], resolution: tuple[int, int],
                   hold_s: int = HOLD_S, delay_s: int = DELAY_S) -> bytes:
    """The page (UTF-8 bytes) that shows ``frames`` ((name, PNG bytes), in capture order) at a screen of
    ``resolution`` px (width, height), each ``hold_s`` seconds after ``delay_s`` (see the module docstring)."""
    inline = [[name, "data:image/png;base64," + base64.b64encode(data).decode("ascii")] for name, data in frames]
    return (_PAGE.replace("@@TITLE@@", html.escape(title)).replace("@@FRAMES@@", json.dumps(inline))
            .replace("@@DELAY@@", str(int(delay_s))).replace("@@HOLD@@", str(int(hold_s)))
            .replace("@@WIDTH@@", str(int(resolution[0]))).replace("@@HEIGHT@@", str(int(resolution[1])))
            .encode("utf-8"))


def frames_of(page: bytes) -> list[tuple[str, bytes]]:
    """The frames a page shows, in its order (name, PNG bytes): what :func:`slideshow_page` put in."""
    text = page.decode("utf-8")
    start = text.index("const FRAMES = ") + len("const FRAMES = ")
    inline = json.loads(text[start:text.index(";\n", start)])
    return [(name, base64.b64decode(uri.split(",", 1)[1])) for name, uri in inline]


__all__ = ["DELAY_S", "HOLD_S", "frames_of", "slideshow_page"]
