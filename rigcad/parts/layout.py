"""Where every part goes: the placements shared between parts, computed once from the profile
and the dome design (mm, rad; sample point at the origin, optical axis +z).

The printed mirror surfaces sit behind the design surfaces by the coating's total thickness
(thesis 3.4): outward for the dome, inward for the paraboloid. The beam runs along x under the
paraboloid; the paraboloid's stem rises from a clamp on the beam; the dome's base flange is
bolted to the base plate whose top face is the sample plane z = 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np
from scipy.optimize import brentq

from rigcad.errors import GeometryError
from rigcad.optics.dome import DomeProfile
from rigcad.optics.surfaces import Meridian, dome_meridian, paraboloid_meridian
from rigcad.profile.derived import Derived
from rigcad.profile.schema import Profile

if TYPE_CHECKING:  # pragma: no cover
    from rigcad.parts.tower import TowerLayout


def u_at_height(m: Meridian, z: float) -> float:
    """Parameter where meridian ``m`` crosses height z (it must cross it exactly once)."""
    u = m.sample(4001)
    dz = m.points(u)[:, 1] - z
    sign = np.nonzero(np.diff(np.sign(dz)) != 0)[0]
    if len(sign) == 0:
        raise GeometryError(f"the {m.kind} surface never reaches z = {z:.3f} mm")
    i = sign[0]
    return brentq(lambda v: m.points(np.array([v]))[0, 1] - z, u[i], u[i + 1], xtol=1e-14)


@dataclass(frozen=True)
class RigLayout:
    """Shared placements. Meridians: ``design_*`` are the coated mirror surfaces, ``printed_*``
    the surfaces the printer makes, ``dome_outer`` the outside of the dome's wall."""

    geometry: Derived
    coating: float
    design_dome: Meridian
    design_paraboloid: Meridian
    printed_dome: Meridian
    printed_paraboloid: Meridian
    dome_outer: Meridian
    u_inner_base: float  #: printed dome surface at z = 0
    u_outer_base: float  #: outer wall at z = 0
    u_outer_flange: float  #: outer wall at the flange's top
    flange_inner_r: float
    flange_outer_r: float
    bolt_circle_r: float
    bolt_angles: tuple[float, ...]
    plate_r: float
    paraboloid_back_z: float  #: bottom of the paraboloid's solid back
    beam_z: tuple[float, float]  #: bottom, top of the beam
    beam_half_length: float
    slot_r: float  #: the wall's largest outer radius across the beam's slot band
    dome_top_z: float  #: the dome's highest point
    tower: "TowerLayout"  #: the COP tower and its instruments (rigcad.parts.tower)
    #: The profile keys ("section.key") the layout read (rigcad.parts.make_layout): what moves every
    #: placement, so what the assembly gate may name when placed parts collide.
    shaped_by: tuple[str, ...] = field(default=(), compare=False)
    #: Sanding stock (mm) printed in front of ``printed_dome`` / ``printed_paraboloid`` (0 for the
    #: design exports; the fab stage sets it, :meth:`with_sanding_stock`).
    dome_stock: float = 0.0
    paraboloid_stock: float = 0.0

    @property
    def as_printed_dome(self) -> Meridian:
        """The dome's mirror as the printer makes it: ``printed_dome`` moved into the light by the stock."""
        return self.printed_dome.behind(-self.dome_stock) if self.dome_stock else self.printed_dome

    @property
    def as_printed_paraboloid(self) -> Meridian:
        """The paraboloid's mirror as printed: ``printed_paraboloid`` moved into the light by the stock."""
        return self.printed_paraboloid.behind(-self.paraboloid_stock) if self.paraboloid_stock else self.printed_paraboloid

    def with_sanding_stock(self, dome: float, paraboloid: float) -> "RigLayout":
        """This layout with the mirrors printed ``dome`` / ``paraboloid`` mm into the light, so that
        sanding down to ``printed_*`` (then coating) reaches the design surface; every other
        placement (the dome's outer wall, the paraboloid's back) stays."""
        if dome < 0 or paraboloid < 0:
            raise GeometryError(f"sanding stock must be >= 0 mm (dome {dome:g} mm, paraboloid {paraboloid:g} mm)")
        return replace(self, dome_stock=float(dome), paraboloid_stock=float(paraboloid))

    def describe(self) -> dict[str, float]:
        """Placements for the manifest (mm)."""
        return {
            "coating_total_mm": self.coating,
            **({"sanding_stock_dome_mm": self.dome_stock, "sanding_stock_paraboloid_mm": self.paraboloid_stock}
               if self.dome_stock or self.paraboloid_stock else {}),
            "flange_inner_r_mm": self.flange_inner_r,
            "flange_outer_r_mm": self.flange_outer_r,
            "bolt_circle_r_mm": self.bolt_circle_r,
            "base_plate_r_mm": self.plate_r,
            "paraboloid_back_z_mm": self.paraboloid_back_z,
            "beam_bottom_z_mm": self.beam_z[0],
            "beam_top_z_mm": self.beam_z[1],
            "beam_length_mm": 2 * self.beam_half_length,
            "dome_top_z_mm": self.dome_top_z,
            "tower": self.tower.describe(),
        }


def flange_extent(flange_in: float, wall: np.ndarray, shell, wall_r_at=None) -> tuple[float, float]:
    """The flange's outer radius and bolt circle radius (mm) for a dome whose outer wall meets the
    flange's top at ``flange_in`` mm, its wall sampled as (r, z) rows ``wall`` (``wall_r_at(z)``: the
    wall's radius at a height, exactly, when the caller has it). The bolts stand mid-flange, or farther
    out where the wall leans over the flange: each bolt is turned by its hex key's short arm up from
    the head and its long arm out from the arm's end, and the key must clear the wall (ISO 2936,
    ``HexKey.room``; the thread is the one the flange's holes are for). One home for the optimiser's
    fast outline (rigcad.optimize.fast) and the parts' layout."""
    from rigcad.standards import CONICAL_SPRING_WASHERS, HEX_KEYS, ISO_7093, THREADS, thread_for_hole

    bolt = flange_in + shell.flange_width / 2
    try:
        th = THREADS[thread_for_hole(shell.bolt_diameter).name]
    except ValueError:
        return bolt + shell.flange_width / 2, bolt  # no thread fits the hole: the flange joint refuses it
    key = HEX_KEYS[th.hex_key]
    # under the head: the large washer over the opened hole (ISO 7093-1 of its size) and the conical spring
    # washer at its free height (DIN 6796), as the flange joint has them (rigcad.parts.dome, rigcad.parts.joints)
    under = (ISO_7093[th.name][2] if th.name in ISO_7093 else th.washer_thickness) + (
        CONICAL_SPRING_WASHERS[th.name][3] if th.name in CONICAL_SPRING_WASHERS else 0.0)
    shaft = shell.flange_thickness + under + th.head_height + key.short_arm  # the short arm's end

    def widest(z0: float, z1: float) -> float | None:
        band = list(wall[(wall[:, 1] >= z0) & (wall[:, 1] <= z1), 0])
        if wall_r_at is not None and wall[:, 1].max() >= z1:  # the band's top edge: the wall rises towards it
            band.append(float(wall_r_at(z1)))
        return max(band) if band else None

    arm, over = widest(shell.flange_thickness, shaft), widest(shaft, shaft + key.room)
    if arm is not None:  # the short arm, and the room about it, up to its end
        bolt = max(bolt, arm + key.room)
    if over is not None:  # the long arm leaves the short one's end outwards: its end face stands on the bolt's axis
        bolt = max(bolt, over)
    return bolt + shell.flange_width / 2, bolt


def rig_layout(profile: Profile, geometry: Derived, dome: DomeProfile) -> RigLayout:
    """Compute the placements; raise GeometryError naming the parameter when parts cannot fit."""
    if dome.kind != "smooth":
        raise GeometryError(
            f"3D parts need a smooth dome profile; dome.method = {dome.method!r} gives the thesis's polyline. "
            "Use dop853, rk45 or equal_path", where=profile.where("dome", "method"))
    coating = float(sum(t for _, t in profile.coating.layers))
    design_dome = dome_meridian(dome)
    design_para = paraboloid_meridian(geometry)
    printed_dome = design_dome.behind(coating)
    printed_para = design_para.behind(coating)
    shell = profile.dome_shell
    dome_outer = printed_dome.behind(shell.wall)
    u_in0 = u_at_height(printed_dome, 0.0)
    u_out0 = u_at_height(dome_outer, 0.0)
    u_flange = u_at_height(dome_outer, shell.flange_thickness)
    flange_in = float(dome_outer.points(np.array([u_flange]))[0, 0])
    flange_out = flange_in + shell.flange_width
    if shell.bolt_diameter >= shell.flange_width - 2.0:
        raise GeometryError(
            f"bolt holes of {shell.bolt_diameter:g} mm do not fit a {shell.flange_width:g} mm flange with 1 mm of "
            "material each side: widen dome_shell.flange_width or shrink dome_shell.bolt_diameter",
            where=profile.where("dome_shell", "bolt_diameter"))
    # mid-flange, or out from under a wall that leans over it (the bolts' hex keys: flange_extent)
    flange_out, bolt_r = flange_extent(
        flange_in, dome_outer.points(dome_outer.sample(4001)), shell,
        lambda z: dome_outer.points(np.array([u_at_height(dome_outer, z)]))[0, 0])
    angles = tuple((k + 0.5) * 2 * math.pi / shell.bolts for k in range(shell.bolts))

    mount, beam = profile.paraboloid_mount, profile.beam
    rim_printed_z = float(printed_para.points(np.array([printed_para.u_range[0]]))[0, 1])
    back_z = rim_printed_z - mount.back_thickness
    if mount.stem_length <= mount.clamp_wall:
        raise GeometryError(
            f"paraboloid_mount.stem_length ({mount.stem_length:g} mm) must exceed the clamp's top wall "
            f"({mount.clamp_wall:g} mm)", where=profile.where("paraboloid_mount", "stem_length"))
    beam_top = back_z - mount.stem_length
    beam_bottom = beam_top - beam.height
    if beam_bottom <= shell.flange_thickness:
        raise GeometryError(
            f"the beam would sit at z = {beam_bottom:.1f} mm, below the dome's flange: shorten "
            "paraboloid_mount.stem_length or beam.height", where=profile.where("paraboloid_mount", "stem_length"))
    band = np.linspace(beam_bottom, beam_top + shell.slot_clearance, 50)
    outer_r = [float(dome_outer.points(np.array([u_at_height(dome_outer, z)]))[0, 0]) for z in band]
    slot_r = max(outer_r)
    plate_r = flange_out + profile.base_plate.margin
    holder = profile.sample_holder
    if holder.sample_thickness >= profile.base_plate.thickness:
        raise GeometryError(
            f"sample_holder.sample_thickness ({holder.sample_thickness:g} mm) must be under the base plate's "
            f"thickness ({profile.base_plate.thickness:g} mm) for the holder to reach it",
            where=profile.where("sample_holder", "sample_thickness"))
    base_r = float(printed_dome.points(np.array([u_in0]))[0, 0])
    if holder.stop_radius <= holder.radius + holder.clearance or holder.stop_radius >= base_r:
        raise GeometryError(
            f"sample_holder.stop_radius must lie between the bore ({holder.radius + holder.clearance:g} mm) and "
            f"the dome's base ({base_r:.1f} mm)", where=profile.where("sample_holder", "stop_radius"))
    from rigcad.parts.tower import tower_layout

    u_top = printed_dome.u_range[1]
    dome_top_z = max(float(printed_dome.points(np.array([u_top]))[0, 1]),
                     float(dome_outer.points(np.array([u_top]))[0, 1]))
    tower = tower_layout(profile, geometry, plate_r, dome_top_z)
    from rigcad.parts.projector_mount import check_mount

    check_mount(profile, tower)  # the shelf carries the projector by its own mounting holes
    return RigLayout(
        geometry=geometry, coating=coating, design_dome=design_dome, design_paraboloid=design_para,
        printed_dome=printed_dome, printed_paraboloid=printed_para, dome_outer=dome_outer,
        u_inner_base=u_in0, u_outer_base=u_out0, u_outer_flange=u_flange,
        flange_inner_r=flange_in, flange_outer_r=flange_out, bolt_circle_r=bolt_r, bolt_angles=angles,
        plate_r=plate_r, paraboloid_back_z=back_z, beam_z=(beam_bottom, beam_top),
        beam_half_length=slot_r + beam.overhang, slot_r=slot_r, dome_top_z=dome_top_z, tower=tower)
