"""``rigcad view``: the assembled rig as one self-contained HTML file (three.js, WebGL).

Everything is inside the file: three.js, its TrackballControls (the copy trimesh ships in
``trimesh/resources/templates/viewer.zip``: three.js r140, MIT licence, its notice kept), the
geometry (every in-rig part's picture mesh, float32 positions and uint32 triangles, base64) and a
few hundred rays traced through the exact surfaces (COP -> paraboloid -> dome -> sample,
``rigcad.check``'s tracer), coloured by their incidence angle at the sample. No request leaves
the page: no CDN, no fonts, no fetch (the geometry is decoded from the page itself).

The page: parts toggled by name (a check box each), the rays on/off, an exploded view (a slider
from assembled to exploded, offsets from ``rigcad.manual.assembly``), mouse orbit/zoom/pan.
``window.rigcad`` exposes the same controls to scripts (the browser test drives it).
"""

from __future__ import annotations

import base64
import html
import json
import zipfile
from pathlib import Path

import numpy as np

from rigcad.errors import ExportError
from rigcad.manual.assembly import SEE_THROUGH_OPACITY, PartMesh, encloses, hex_color, ray_colors

#: Rays drawn in the view: enough to show the fan from the COP over the paraboloid's annulus to the
#: sample, few enough to tell them apart.
VIEW_RAYS = 300
#: Where the three.js script ends in trimesh's template and the template's own viewer code begins.
_TEMPLATE_SPLIT = "var camera,controls,scene,renderer,tracklight;"


def three_js() -> str:
    """three.js r140 with TrackballControls and GLTFLoader, as trimesh ships them (one minified
    script). Raises ExportError when the installed trimesh has no such template."""
    import trimesh

    path = Path(trimesh.__file__).parent / "resources" / "templates" / "viewer.zip"
    try:
        with zipfile.ZipFile(path) as z:
            text = z.read("viewer.html.template").decode("utf-8")
    except (OSError, KeyError, zipfile.BadZipFile) as err:
        raise ExportError(f"cannot read three.js from trimesh {trimesh.__version__} ({path}): {err}; "
                          "rigcad view needs trimesh's viewer template (trimesh >= 4)") from err
    start = text.find("<script>")
    end = text.find(_TEMPLATE_SPLIT)
    if start < 0 or end < 0 or "TrackballControls" not in text[start:end]:
        raise ExportError(f"trimesh {trimesh.__version__}'s viewer template ({path}) has changed: three.js and "
                          "TrackballControls not found where rigcad expects them")
    return text[start + len("<script>"):end]


def traced_rays(rig, count: int = VIEW_RAYS, seed: int | None = None) -> dict:
    """``count`` pinhole rays from the COP over the paraboloid's useful annulus (seeded: the
    profile's raycheck.seed), traced through the exact surfaces; the ones that reach the sample as
    polylines (k, 4, 3) mm (COP, paraboloid, dome, sample) with their incidence angle theta (k,) rad;
    with a COP tower (k, 5, 3), from the projector's COP by the splitter's front face."""
    from rigcad.check.scene import analytic_optics
    from rigcad.check.sources import annulus_rays
    from rigcad.check.trace3d import trace

    design = rig.incidence
    src = annulus_rays(design, count, rig.profile.raycheck.seed if seed is None else seed, rig.pose("projector"))
    tr = trace(analytic_optics(rig), src.origins, src.dirs)
    ok = tr.ok
    lines = np.stack([src.origins[ok], tr.p1[ok], tr.p2[ok], tr.landing[ok]], axis=1)
    tower = getattr(rig.layout, "tower", None)
    if tower is not None and len(lines):
        lines = _folded(lines, tower)
    return {"lines": lines, "theta": tr.theta[ok], "traced": int(count), "reached": int(ok.sum()),
            "folded_at_splitter": tower is not None}


def _folded(lines: np.ndarray, tower) -> np.ndarray:
    """Polylines (k, 4, 3) from the design COP folded at the beam splitter's front face: the light
    comes from the projector's real COP (the design COP's mirror image in that face), reflects at
    the face and goes on down as traced; (k, 5, 3)."""
    c = np.asarray(tower.plate.center, float)
    n = np.asarray(tower.plate.normal, float)
    o, d = lines[:, 0], lines[:, 1] - lines[:, 0]
    s = ((c - o) @ n) / (d @ n)
    hit = o + s[:, None] * d
    start = np.broadcast_to(np.asarray(tower.projector_cop, float), o.shape)
    return np.concatenate([start[:, None], hit[:, None], lines[:, 1:]], axis=1)


def b64(a: np.ndarray, dtype) -> str:
    """``a`` as ``dtype`` (e.g. ``"<f4"``), its bytes in base64: how a page carries an array."""
    return base64.b64encode(np.ascontiguousarray(a, dtype=dtype).tobytes()).decode("ascii")


def ray_segments(rays: dict) -> tuple[np.ndarray, np.ndarray]:
    """The polylines of ``rays`` (traced_rays) as line segments: both ends of every segment (2 s, 3)
    mm and their colours (2 s, 3) (ray_colors)."""
    lines = rays["lines"]
    if not len(lines):
        return np.zeros((0, 3)), np.zeros((0, 3))
    seg = np.concatenate([lines[:, :-1], lines[:, 1:]], axis=2).reshape(-1, 3)
    return seg, np.repeat(ray_colors(rays["theta"]), 2 * (lines.shape[1] - 1), axis=0)  # 2 ends per segment


def view_html(rig, meshes: list[PartMesh], rays: dict) -> bytes:
    """The page for ``rig`` with its assembly ``meshes`` (assembly.picture_meshes) and ``rays``
    (traced_rays), as UTF-8 bytes; deterministic (same inputs, same bytes)."""
    from matplotlib import colormaps

    cmap = colormaps["viridis"]
    see_through = encloses(meshes)
    parts = [{"name": m.name, "color": hex_color(m.color), "quantity": m.quantity, "description": m.description,
              "opacity": SEE_THROUGH_OPACITY if m.name in see_through else 1.0,
              "explode_mm": [round(float(x), 6) for x in m.explode],
              "positions": b64(m.vertices, "<f4"), "indices": b64(m.faces, "<u4"), "triangles": int(len(m.faces))}
             for m in meshes]
    lines = rays["lines"]
    seg, colours = ray_segments(rays)
    theta_deg = np.degrees(rays["theta"])
    g = rig.geometry
    data = {
        "profile": rig.name,
        "frame": "mm; sample point O at the origin; optical axis +z",
        "cop_z_mm": None if g.cop_at_infinity else float(g.cop_z),
        "parts": parts,
        "rays": {"positions": b64(seg, "<f4"), "colors": b64(colours, "<f4"), "count": int(len(lines)),
                 "traced": rays["traced"], "theta_min_deg": float(theta_deg.min()) if len(lines) else None,
                 "theta_max_deg": float(theta_deg.max()) if len(lines) else None},
        "colorbar": [hex_color(cmap(k / 8)[:3]) for k in range(9)],
    }
    payload = json.dumps(data, sort_keys=True, separators=(",", ":")).replace("</", "<\\/")
    page = (_PAGE.replace("@@TITLE@@", html.escape(f"{rig.name}: the rig in 3D (rigcad view)"))
            .replace("@@THREE@@", three_js()).replace("@@SCENE@@", SCENE_JS).replace("@@DATA@@", payload))
    return page.encode("utf-8")


#: The script both 3D pages (this one and ``rigcad watch``'s, rigcad.live.page) start with: base64
#: decoding, the renderer, scene, lights and camera (mm, +z up), a part's mesh from its data
#: (``partMesh``: colour, opacity, base64 positions and indices) and the first view of a box
#: (``fitCamera``).
SCENE_JS = r"""  function decode(b64, Type) {
    const bin = atob(b64), bytes = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
    return new Type(bytes.buffer);
  }
  const host = document.getElementById("view");
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setSize(host.clientWidth, host.clientHeight);
  host.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf4f4f4);
  scene.add(new THREE.AmbientLight(0xffffff, 0.45));
  const light = new THREE.DirectionalLight(0xffffff, 0.75);
  scene.add(light);
  const camera = new THREE.PerspectiveCamera(30, host.clientWidth / host.clientHeight, 1, 1e6);
  camera.up.set(0, 0, 1);
  function partMesh(p, data) {
    const geom = new THREE.BufferGeometry();
    geom.setAttribute("position", new THREE.BufferAttribute(decode(data.positions, Float32Array), 3));
    geom.setIndex(new THREE.BufferAttribute(decode(data.indices, Uint32Array), 1));
    const mat = new THREE.MeshPhongMaterial({ color: new THREE.Color(p.color), flatShading: true,
      side: THREE.DoubleSide, transparent: p.opacity < 1, opacity: p.opacity, depthWrite: p.opacity >= 1 });
    const mesh = new THREE.Mesh(geom, mat);
    mesh.name = p.name;
    return mesh;
  }
  function fitCamera(box, controls) {
    const sphere = box.getBoundingSphere(new THREE.Sphere());
    const dir = new THREE.Vector3(1.0, -1.7, 0.75).normalize();
    const dist = sphere.radius / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2)) * 0.8;
    camera.position.copy(sphere.center).addScaledVector(dir, dist);
    camera.lookAt(sphere.center);
    controls.target.copy(sphere.center);
  }
"""

_PAGE = r"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>@@TITLE@@</title>
<meta http-equiv="Content-Security-Policy" content="default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; img-src data: blob:">
<style>
  html, body { margin: 0; height: 100%; overflow: hidden; font: 13px/1.35 sans-serif; background: #f4f4f4; }
  #view { position: absolute; inset: 0; }
  #panel { position: absolute; top: 8px; left: 8px; background: rgba(255,255,255,0.92); padding: 8px 10px;
           border-radius: 6px; box-shadow: 0 1px 4px rgba(0,0,0,0.25); max-height: calc(100% - 40px); overflow: auto; }
  #panel h1 { font-size: 14px; margin: 0 0 6px; }
  #panel label { display: block; white-space: nowrap; cursor: pointer; }
  .swatch { display: inline-block; width: 10px; height: 10px; margin: 0 4px; border: 1px solid #555; }
  #bar { height: 10px; width: 180px; margin: 2px 0; }
  .small { color: #555; font-size: 11px; }
</style>
</head>
<body>
<div id="view"></div>
<div id="panel">
  <h1 id="title"></h1>
  <div id="parts"></div>
  <hr>
  <label><input type="checkbox" id="rays" checked> rays, coloured by incidence angle</label>
  <div id="bar"></div>
  <div class="small" id="barlabel"></div>
  <hr>
  <label>exploded view <input type="range" id="explode" min="0" max="100" value="0"></label>
  <div class="small">drag: rotate; wheel: zoom; right drag: pan</div>
</div>
<script type="application/json" id="rig-data">@@DATA@@</script>
<script>@@THREE@@</script>
<script>
"use strict";
(function () {
  const DATA = JSON.parse(document.getElementById("rig-data").textContent);
@@SCENE@@
  const parts = {};
  const list = document.getElementById("parts");
  document.getElementById("title").textContent = DATA.profile + ": the rig";
  for (const p of DATA.parts) {
    const mesh = partMesh(p, p);
    scene.add(mesh);
    parts[p.name] = { mesh: mesh, explode: p.explode_mm };
    const label = document.createElement("label");
    label.title = p.description;
    label.innerHTML = '<input type="checkbox" checked id="part-' + p.name + '"><span class="swatch" style="background:' +
      p.color + '"></span>' + p.name + (p.quantity > 1 ? " (x" + p.quantity + ")" : "");
    list.appendChild(label);
    label.querySelector("input").addEventListener("change", function (e) { setVisible(p.name, e.target.checked); });
  }
  const rg = new THREE.BufferGeometry();
  rg.setAttribute("position", new THREE.BufferAttribute(decode(DATA.rays.positions, Float32Array), 3));
  rg.setAttribute("color", new THREE.BufferAttribute(decode(DATA.rays.colors, Float32Array), 3));
  const rays = new THREE.LineSegments(rg, new THREE.LineBasicMaterial({ vertexColors: true }));
  rays.name = "rays";
  scene.add(rays);
  document.getElementById("bar").style.background = "linear-gradient(to right," + DATA.colorbar.join(",") + ")";
  document.getElementById("barlabel").textContent = DATA.rays.count + " of " + DATA.rays.traced +
    " traced rays reach the sample; colour: theta 0..90 deg (traced " +
    (DATA.rays.count ? DATA.rays.theta_min_deg.toFixed(1) + ".." + DATA.rays.theta_max_deg.toFixed(1) : "-") + " deg)";

  const controls = new THREE.TrackballControls(camera, renderer.domElement);
  controls.rotateSpeed = 2.0; controls.zoomSpeed = 1.2; controls.panSpeed = 0.8; controls.staticMoving = true;
  fitCamera(new THREE.Box3().setFromObject(scene), controls);

  let frames = 0;
  function render() { light.position.copy(camera.position); renderer.render(scene, camera); frames++; }
  let exploded = 0;
  function setVisible(name, on) {
    if (name === "rays") { rays.visible = on && exploded === 0; document.getElementById("rays").checked = on; }
    else { parts[name].mesh.visible = on; document.getElementById("part-" + name).checked = on; }
    render();
  }
  function setExplode(f) {
    for (const name in parts) {
      const e = parts[name].explode;
      parts[name].mesh.position.set(f * e[0], f * e[1], f * e[2]);
    }
    document.getElementById("explode").value = Math.round(100 * f);
    exploded = f;
    rays.visible = document.getElementById("rays").checked && f === 0;  // the rays belong to the assembled rig
    render();
  }
  document.getElementById("rays").addEventListener("change", function (e) { setVisible("rays", e.target.checked); });
  document.getElementById("explode").addEventListener("input", function (e) { setExplode(e.target.value / 100); });
  window.addEventListener("resize", function () {
    camera.aspect = host.clientWidth / host.clientHeight; camera.updateProjectionMatrix();
    renderer.setSize(host.clientWidth, host.clientHeight); controls.handleResize(); render();
  });
  controls.addEventListener("change", render);  // draw when the view moves, not every frame
  (function animate() { requestAnimationFrame(animate); controls.update(); })();
  render();
  window.rigcad = { parts: Object.keys(parts), setVisible: setVisible, setExplode: setExplode,
                    frames: function () { return frames; }, webgl: !!renderer.getContext(), ready: true };
})();
</script>
</body>
</html>
"""


def write_view(rig, out_dir: Path, lock: Path | None = None, progress=None, rays: int = VIEW_RAYS,
               glb: bool = False) -> dict:
    """Write ``out_dir/rig.html`` (the 3D view) and ``out_dir/rig.png`` (the assembled rig for the
    README), and with ``glb`` ``out_dir/rig.glb`` (manual.glb), published together
    (export.atomic.Staging). Returns a summary (paths, sizes)."""
    from rigcad import plots
    from rigcad.export.atomic import Staging
    from rigcad.manual.assembly import picture_meshes

    step = progress or (lambda label: None)
    meshes = picture_meshes(rig)
    step("parts meshed")
    traced = traced_rays(rig, rays)
    step("rays traced")
    page = view_html(rig, meshes, traced)
    png = plots.rig_picture(meshes, traced, f"{rig.name}: the assembled rig", cut_away=encloses(meshes))
    step("page and picture")
    from rigcad.export.manifest import profile_digest

    with Staging(out_dir, lock, made_from=profile_digest(rig.profile)) as stage:
        stage.write_bytes(out_dir / "rig.html", page)
        stage.write_bytes(out_dir / "rig.png", png)
        if glb:
            from rigcad.manual.glb import glb_bytes

            stage.write_bytes(out_dir / "rig.glb", glb_bytes(rig, meshes, traced))
        stage.commit()
    step("written")
    return {"html": out_dir / "rig.html", "png": out_dir / "rig.png", "html_bytes": len(page),
            "parts": [m.name for m in meshes], "triangles": sum(len(m.faces) for m in meshes),
            "rays": int(len(traced["lines"])), "rays_traced": traced["traced"],
            **({"glb": out_dir / "rig.glb"} if glb else {})}


__all__ = ["SCENE_JS", "VIEW_RAYS", "b64", "ray_segments", "three_js", "traced_rays", "view_html",
           "write_view"]
