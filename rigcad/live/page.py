"""The live view's page: ``rigcad view``'s three.js scene (the same inline three.js, nothing
downloaded), fed by the watcher's server over server-sent events instead of data in the page.

The page asks its own server for one thing, ``/events``; its content-security policy is the
view's (``default-src 'none'``, inline script and style only) with ``connect-src 'self'`` added
for that stream. Each ``frame`` event (see :func:`rigcad.live.server.frame_message`) carries the
meshes of the parts that changed only; the page swaps those, tints them for HIGHLIGHT_MS, redraws
the check table and the headline figures with their change since the last good state, and shows
a profile's error (file:line first) above the last good rig. When the stream ends (the watcher
stopped) the page says "disconnected". ``window.rigcad`` exposes the state to scripts (the browser
tests read it).
"""

from __future__ import annotations

import html

#: How long (ms) a part that changed stays tinted.
HIGHLIGHT_MS = 4000


def live_html(title: str) -> bytes:
    """The page, UTF-8; ``title`` is escaped. Deterministic (same title, same bytes)."""
    from rigcad.manual.view import SCENE_JS, three_js

    page = (_PAGE.replace("@@CSP@@", CSP).replace("@@TITLE@@", html.escape(title)).replace("@@HIGHLIGHT_MS@@", str(HIGHLIGHT_MS))
            .replace("@@THREE@@", three_js()).replace("@@SCENE@@", SCENE_JS))
    return page.encode("utf-8")


#: The policy, also sent as a header by the server.
CSP = ("default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; img-src data: blob:; "
       "connect-src 'self'")

_PAGE = r"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>@@TITLE@@</title>
<meta http-equiv="Content-Security-Policy" content="@@CSP@@">
<style>
  html, body { margin: 0; height: 100%; overflow: hidden; font: 13px/1.35 sans-serif; background: #f4f4f4; }
  #view { position: absolute; inset: 0; }
  .box { position: absolute; background: rgba(255,255,255,0.92); padding: 8px 10px; border-radius: 6px;
         box-shadow: 0 1px 4px rgba(0,0,0,0.25); overflow: auto; }
  #panel { top: 8px; left: 8px; max-height: calc(100% - 40px); }
  #report { top: 8px; right: 8px; max-width: 52%; max-height: calc(100% - 40px); }
  h1 { font-size: 14px; margin: 0 0 6px; }
  label { display: block; white-space: nowrap; cursor: pointer; }
  .swatch { display: inline-block; width: 10px; height: 10px; margin: 0 4px; border: 1px solid #555; }
  .changed { font-weight: bold; color: #c05000; }
  table { border-collapse: collapse; font-size: 12px; }
  td, th { padding: 1px 6px; text-align: left; white-space: nowrap; }
  td.num { text-align: right; font-variant-numeric: tabular-nums; }
  .ok { color: #17702f; } .fail { color: #b00020; font-weight: bold; }
  #status { font-weight: bold; }
  #status.disconnected, #status.error { color: #b00020; }
  #error { display: none; background: #fde8ea; color: #7a0014; border: 1px solid #b00020; padding: 6px;
           margin: 6px 0; white-space: pre-wrap; font-family: monospace; max-width: 60ch; }
  .small { color: #555; font-size: 11px; }
</style>
</head>
<body>
<div id="view"></div>
<div id="panel" class="box">
  <h1 id="title">rigcad watch</h1>
  <div><span id="status">connecting</span> <span class="small">frame <span id="frame">0</span></span></div>
  <div id="error"></div>
  <div id="parts"></div>
  <hr>
  <label><input type="checkbox" id="rays" checked> rays, coloured by incidence angle</label>
  <div class="small" id="raylabel"></div>
  <div class="small">drag: rotate; wheel: zoom; right drag: pan</div>
</div>
<div id="report" class="box">
  <h1>design</h1>
  <table id="figures"></table>
  <h1>check <span class="small" id="checkstate"></span></h1>
  <table id="checks"></table>
  <div id="printers" class="small"></div>
  <div id="timings" class="small"></div>
</div>
<script>@@THREE@@</script>
<script>
"use strict";
(function () {
  const HIGHLIGHT_MS = @@HIGHLIGHT_MS@@;
@@SCENE@@  function el(tag, text, cls) { const e = document.createElement(tag); if (text !== undefined) e.textContent = text;
    if (cls) e.className = cls; return e; }
  const controls = new THREE.TrackballControls(camera, renderer.domElement);
  controls.rotateSpeed = 2.0; controls.zoomSpeed = 1.2; controls.panSpeed = 0.8; controls.staticMoving = true;

  const parts = {};          // name -> {mesh, key, color, info}
  const hidden = {};         // name -> true when the user hid it
  let rays = null, raysKey = null, framed = false, frames = 0, seq = 0, applied = 0, highlighted = {};
  const state = { status: "connecting", error: null, rows: null, figures: null, timings: null };
  function render() { light.position.copy(camera.position); renderer.render(scene, camera); frames++; }

  function setPart(p, m) {
    const old = parts[p.name];
    if (old) { scene.remove(old.mesh); old.mesh.geometry.dispose(); old.mesh.material.dispose(); }
    const mesh = partMesh(p, m);
    mesh.visible = !hidden[p.name];
    scene.add(mesh);
    parts[p.name] = { mesh: mesh, key: p.key, color: p.color };
  }
  function dropPart(name) {
    const old = parts[name];
    if (!old) return;
    scene.remove(old.mesh); old.mesh.geometry.dispose(); old.mesh.material.dispose(); delete parts[name];
  }
  function highlight(names) {
    const now = performance.now();
    for (const n of names) highlighted[n] = now + HIGHLIGHT_MS;
    tint();
  }
  function tint() {
    const now = performance.now();
    for (const n in parts) {
      const on = highlighted[n] !== undefined && highlighted[n] > now;
      parts[n].mesh.material.emissive = new THREE.Color(on ? 0xff6a00 : 0x000000);
      if (!on) delete highlighted[n];
    }
    render();
  }
  function setRays(r) {
    if (rays) { scene.remove(rays); rays.geometry.dispose(); rays.material.dispose(); rays = null; }
    const g = new THREE.BufferGeometry();
    g.setAttribute("position", new THREE.BufferAttribute(decode(r.positions, Float32Array), 3));
    g.setAttribute("color", new THREE.BufferAttribute(decode(r.colors, Float32Array), 3));
    rays = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ vertexColors: true }));
    rays.name = "rays";
    rays.visible = document.getElementById("rays").checked;
    scene.add(rays);
    raysKey = r.key;
    document.getElementById("raylabel").textContent = r.count + " of " + r.traced + " traced rays reach the sample";
  }
  function partList(list, changed) {
    const box = document.getElementById("parts");
    box.textContent = "";
    for (const p of list) {
      const label = el("label"); label.title = p.description;
      const input = el("input"); input.type = "checkbox"; input.id = "part-" + p.name; input.checked = !hidden[p.name];
      input.addEventListener("change", function (e) { setVisible(p.name, e.target.checked); });
      const sw = el("span", "", "swatch"); sw.style.background = p.color;
      label.append(input, sw, el("span", p.name + (p.quantity > 1 ? " (x" + p.quantity + ")" : ""),
                                 changed.indexOf(p.name) >= 0 ? "changed" : ""));
      box.appendChild(label);
    }
  }
  function fmt(v) { return (v === null || v === undefined) ? "-" : Number(v).toPrecision(5); }
  function figures(list) {
    const t = document.getElementById("figures"); t.textContent = "";
    for (const f of list) {
      const tr = el("tr");
      const d = f.delta === null ? "" : (f.delta >= 0 ? "+" : "") + Number(f.delta).toPrecision(3);
      tr.append(el("td", f.label), el("td", fmt(f.value), "num"), el("td", f.unit),
                el("td", d, f.delta ? "num changed" : "num"));
      t.appendChild(tr);
    }
  }
  function checks(rows, pending) {
    const t = document.getElementById("checks"); t.textContent = "";
    document.getElementById("checkstate").textContent = pending ? "(checking...)" : "";
    if (!rows) { t.appendChild(el("tr")).appendChild(el("td", pending ? "checking..." : "off")); return; }
    const head = el("tr"); for (const h of ["check", "measured", "", "target", "unit", ""]) head.appendChild(el("th", h));
    t.appendChild(head);
    for (const r of rows) {
      const tr = el("tr"); tr.className = r.ok ? "row-ok" : "row-fail";
      tr.append(el("td", r.check), el("td", fmt(r.measured), "num"), el("td", r.relation),
                el("td", fmt(r.limit), "num"), el("td", r.unit), el("td", r.ok ? "pass" : "FAIL", r.ok ? "ok" : "fail"));
      t.appendChild(tr);
    }
  }
  function frameView() {
    if (framed || Object.keys(parts).length === 0) return;
    const box = new THREE.Box3();
    for (const n in parts) box.expandByObject(parts[n].mesh);
    fitCamera(box, controls);
    framed = true;   // once: later frames keep the user's view
  }
  function setStatus(s, text) {
    const e = document.getElementById("status"); e.className = s; e.textContent = text || s; state.status = s;
  }
  function apply(msg) {
    document.getElementById("title").textContent = msg.profile + ": live";
    const err = document.getElementById("error");
    state.error = msg.error;
    err.style.display = msg.error ? "block" : "none";
    err.textContent = msg.error ? msg.error + "\n(showing the last good rig)" : "";
    setStatus(msg.error ? "error" : "connected", msg.error ? "profile error" : "live");
    const names = msg.parts.map(function (p) { return p.name; });
    for (const n in parts) if (names.indexOf(n) < 0) dropPart(n);
    for (const p of msg.parts) if (msg.meshes[p.name]) setPart(p, msg.meshes[p.name]);
    if (msg.rays && msg.rays.key !== raysKey) setRays(msg.rays);
    frameView();
    if (msg.parts.length) partList(msg.parts, msg.changed);
    if (applied > 0) highlight(msg.changed);  // the first frame is the rig itself, not a change
    figures(msg.figures);
    checks(msg.rows, msg.check_pending);
    state.rows = msg.rows; state.figures = msg.figures; state.timings = msg.timings;
    const pr = document.getElementById("printers"); pr.textContent = "";
    for (const name in msg.printers) {
      const p = msg.printers[name];
      pr.appendChild(el("div", name + ": " + (p.parts - p.split.length) + " of " + p.parts + " printed parts fit whole" +
                               (p.split.length ? "; split: " + p.split.join(", ") : "")));
    }
    document.getElementById("timings").textContent = "last update: " + Object.keys(msg.timings).map(function (k) {
      return k + " " + msg.timings[k].toFixed(2) + " s"; }).join(", ");
    seq = msg.seq; applied++;
    document.getElementById("frame").textContent = String(seq);
    render();
  }
  function setVisible(name, on) {
    if (name === "rays") { if (rays) rays.visible = on; document.getElementById("rays").checked = on; }
    else { hidden[name] = !on; if (parts[name]) parts[name].mesh.visible = on;
           const box = document.getElementById("part-" + name); if (box) box.checked = on; }
    render();
  }
  document.getElementById("rays").addEventListener("change", function (e) { setVisible("rays", e.target.checked); });
  window.addEventListener("resize", function () {
    camera.aspect = host.clientWidth / host.clientHeight; camera.updateProjectionMatrix();
    renderer.setSize(host.clientWidth, host.clientHeight); controls.handleResize(); render();
  });
  controls.addEventListener("change", render);
  (function animate() { requestAnimationFrame(animate); controls.update(); })();
  setInterval(function () { if (Object.keys(highlighted).length) tint(); }, 500);

  const source = new EventSource("/events");
  source.addEventListener("frame", function (e) { apply(JSON.parse(e.data)); });
  source.addEventListener("bye", function () { source.close(); setStatus("disconnected", "disconnected: the watcher stopped"); });
  source.onerror = function () {
    if (source.readyState !== EventSource.OPEN) setStatus("disconnected", "disconnected: the watcher stopped");
  };
  render();
  window.rigcad = { setVisible: setVisible, frames: function () { return frames; },
                    seq: function () { return seq; }, applied: function () { return applied; },
                    parts: function () { return Object.keys(parts); },
                    key: function (name) { return parts[name] ? parts[name].key : null; },
                    highlighted: function () { return Object.keys(highlighted).sort(); },
                    state: state, webgl: !!renderer.getContext(), ready: true };
})();
</script>
</body>
</html>
"""

__all__ = ["CSP", "HIGHLIGHT_MS", "live_html"]
