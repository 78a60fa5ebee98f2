"""Profile templates (thesis 3.4, Figure 3.11): flat gauges whose edge is the negative of a mirror
profile, held against the surface while it is polished. They gauge the surface of the coating
layer named by ``templates.gauged_layer`` (by default the clearcoat that is polished before the
mirror paint), i.e. the design surface moved behind by the layers above that one. They are drawn
in the meridional plane (x-z), in their gauging position."""

from __future__ import annotations

import numpy as np

from rigcad.parts.layout import RigLayout, u_at_height
from rigcad.parts.recipe import Curve, Line, Part, Prism, Section
from rigcad.profile.schema import Profile


def gauged_depth(profile: Profile) -> float:
    """How far behind the design surface the gauged surface lies (mm)."""
    layers = profile.coating.layers
    name = profile.templates.gauged_layer
    if name == "design":
        return 0.0
    idx = [n for n, _ in layers].index(name)
    return float(sum(t for _, t in layers[idx + 1:]))


def _pt(m, u) -> tuple[float, float]:
    return tuple(float(v) for v in m.points(np.array([u]))[0])


def dome_template(profile: Profile, layout: RigLayout, depth: float | None = None) -> Part:
    """The dome's template; ``depth`` (mm behind the design surface) gauges another surface than
    the profile's gauged layer (the fab stage's printed and sanded stages)."""
    g = layout.design_dome.behind(gauged_depth(profile) if depth is None else depth)
    front = g.behind(-profile.templates.band)  # on the reflecting side: the template's body
    u1 = g.u_range[1]
    lifted = _pt(g, g.u_range[0])[1] >= 0.0  # a surface in front of the design by more than the coating
    # (the printed stage under a deep sanding stock) starts microns above the plate: the template's datum
    # edge stays on z = 0, its gauging edge runs straight down to it from the surface's start
    u0 = g.u_range[0] if lifted else u_at_height(g, 0.0)
    base = ((Line(_pt(front, u0), (_pt(front, u0)[0], 0.0)), Line((_pt(front, u0)[0], 0.0), (_pt(g, u0)[0], 0.0)),
             Line((_pt(g, u0)[0], 0.0), _pt(g, u0))) if lifted else (Line(_pt(front, u0), _pt(g, u0)),))
    section = Section((
        Curve(g, u0, u1),
        Line(_pt(g, u1), _pt(front, u1)),
        Curve(front, u1, u0),
        *base,
    ))
    return Part("dome_template", Prism(section, profile.templates.thickness), (0.95, 0.85, 0.3),
                f"dome profile template: its curved edge is the {profile.templates.gauged_layer} surface "
                "(hold it in a meridional plane against the inside of the dome)", in_rig=False)


def paraboloid_template(profile: Profile, layout: RigLayout, depth: float | None = None) -> Part:
    """The paraboloid's template (``depth`` as for :func:`dome_template`)."""
    g = layout.design_paraboloid.behind(gauged_depth(profile) if depth is None else depth)
    u_rim, u_v = g.u_range
    rim = _pt(g, u_rim)
    vertex_z = _pt(g, u_v)[1]
    band = profile.templates.band
    x_out, z_top = rim[0] + band, vertex_z + band
    section = Section((
        Curve(g, u_rim, u_v, mirror_x=True),
        Curve(g, u_v, u_rim),
        Line(rim, (x_out, rim[1])),
        Line((x_out, rim[1]), (x_out, z_top)),
        Line((x_out, z_top), (-x_out, z_top)),
        Line((-x_out, z_top), (-x_out, rim[1])),
        Line((-x_out, rim[1]), (-rim[0], rim[1])),
    ))
    return Part("paraboloid_template", Prism(section, profile.templates.thickness), (0.95, 0.85, 0.3),
                f"paraboloid profile template: its cut-out is the {profile.templates.gauged_layer} surface "
                "(hold it over the paraboloid in a meridional plane)", in_rig=False)
