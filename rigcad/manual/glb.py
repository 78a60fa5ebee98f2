"""``rigcad view --glb``: the assembled rig as one binary glTF 2.0 file (``rig.glb``) for Blender,
YACV or any glTF viewer.

One node per in-rig part (``manual.assembly.picture_meshes``: the picture meshes the HTML view draws,
in their working positions), named after the part, with a PBR material of the part's colour (the
see-through dome at the view's 30 % opacity); and one node ``rays``: the traced rays
(``manual.view.traced_rays``) as line strips, one per ray, coloured by their incidence angle at the
sample (viridis of theta / 90 deg, as the view). glTF's frame is y up and metres by convention; the
file keeps rigcad's (mm, +z up) and says so in the scene's ``extras``, as the HTML view does:
importers that scale or turn the scene offer it as an option. Written by trimesh's glTF exporter.
"""

from __future__ import annotations

import numpy as np

from rigcad.manual.assembly import SEE_THROUGH_OPACITY, PartMesh, encloses, ray_colors

def _rgba(color, alpha: float) -> list[int]:
    return [int(round(255 * min(max(c, 0.0), 1.0))) for c in color] + [int(round(255 * alpha))]


def rig_scene(rig, meshes: list[PartMesh], rays: dict):
    """A trimesh Scene of ``meshes`` (assembly.picture_meshes) and ``rays`` (view.traced_rays)."""
    import trimesh

    scene = trimesh.Scene()
    see_through = encloses(meshes)
    for m in meshes:
        alpha = SEE_THROUGH_OPACITY if m.name in see_through else 1.0
        material = trimesh.visual.material.PBRMaterial(
            name=m.name, baseColorFactor=_rgba(m.color, alpha), metallicFactor=0.0, roughnessFactor=0.8,
            alphaMode="BLEND" if alpha < 1 else "OPAQUE", doubleSided=True)
        mesh = trimesh.Trimesh(np.asarray(m.vertices, float), np.asarray(m.faces, np.int64), process=False,
                               visual=trimesh.visual.TextureVisuals(material=material))
        scene.add_geometry(mesh, node_name=m.name, geom_name=m.name)
    lines = rays["lines"]
    if len(lines):
        k, n = lines.shape[:2]
        entities = [trimesh.path.entities.Line(np.arange(i * n, (i + 1) * n)) for i in range(k)]
        rgb = (ray_colors(rays["theta"]) * 255).round()
        rgba = np.column_stack([rgb, np.full(len(rgb), 255.0)]).astype(np.uint8)
        path = trimesh.path.Path3D(entities=entities, vertices=lines.reshape(-1, 3), colors=rgba, process=False)
        scene.add_geometry(path, node_name="rays", geom_name="rays")
    scene.metadata.update({"profile": rig.name, "frame": "mm; sample point O at the origin; optical axis +z",
                           "rays": int(len(lines)), "rays_traced": int(rays["traced"])})
    return scene


def glb_bytes(rig, meshes: list[PartMesh], rays: dict) -> bytes:
    """The binary glTF of :func:`rig_scene`."""
    from trimesh.exchange.gltf import export_glb

    return export_glb(rig_scene(rig, meshes, rays), include_normals=False)


__all__ = ["glb_bytes", "rig_scene"]
