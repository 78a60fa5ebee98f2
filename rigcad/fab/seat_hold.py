"""How firmly the splitter seat holds the splitter holder and the camera on it (kernel-free; N, mm).

The holder stands on three balls (rigcad.parts.tower.splitter_seat: a cone, a vee and a flat) and is
pulled down by its two preload springs; its own weight and the camera's press it down too. A
horizontal force on the camera (a stiff cable, a hand) tips it about an edge of the balls' triangle,
lifting the ball opposite, once its moment about that edge passes the restoring moment: each downward
load times its distance inside the edge (a load outside an edge counts against it). The worst direction
is square to the edge, so the side pull that lifts a ball is the least restoring moment over the
camera's height above the balls (statics of a rigid body on three point supports; the springs' rate is
low enough that their force hardly grows as a ball starts to lift, so it is held at the preload).

:data:`SIDE_PULL_N` is the side pull the seat must take at the camera without lifting a ball:
:func:`check` refuses a seat that would not, at the springs' preload as set (the manual keeps each spring at
its installed length through the seat's adjustment), a GeometryError naming the springs to change.
"""

from __future__ import annotations

from dataclasses import dataclass

from rigcad.errors import GeometryError
from rigcad.fab import loads
from rigcad.parts import tower as T

#: The side pull (N) at the camera the seat must take without lifting a ball. A lift while a hand brushes
#: the camera is harmless (the seat returns to its place: rigcad.fab.stack.KINEMATIC_REPEAT); a sustained
#: pull is not: a stiff camera cable held the review's seat (14 N springs) off a ball with about 5.3 N. The
#: cable is tied to the column (rigcad.parts.tower.CABLE_TIE), so what pulls on the camera is the slack
#: loop from the tie: taken as 10 N (about 1 kgf; assumed), twice what the untied cable pulled.
SIDE_PULL_N = 10.0


@dataclass(frozen=True)
class SeatHold:
    """The seat's restoring moments (N mm) about its three edges (named by their two contacts), the
    camera's height (mm) over the balls' centres, the downward loads (N; x, y mm) that make them, and
    the side pull (N) at the camera that lifts a ball (the least moment over the height)."""

    moments_nmm: dict[str, float]
    camera_height_mm: float
    loads: tuple[tuple[str, float, float, float], ...]
    lift_pull_n: float

    def describe(self) -> dict:
        return {"restoring_moment_N_m": {k: v / 1000 for k, v in self.moments_nmm.items()},
                "camera_height_mm": self.camera_height_mm, "lift_off_side_pull_N": self.lift_pull_n,
                "loads": [{"what": w, "force_N": f, "x_mm": x, "y_mm": y} for w, f, x, y in self.loads],
                "design_side_pull_N": SIDE_PULL_N}


def _inside(p, a, b, c) -> float:
    """Signed distance (mm) of point ``p`` from the line through ``a`` and ``b`` (x, y), positive on
    the side of ``c`` (the triangle's third corner)."""
    ex, ey = b[0] - a[0], b[1] - a[1]
    n = (ex * ex + ey * ey) ** 0.5

    def side(q):
        return (ex * (q[1] - a[1]) - ey * (q[0] - a[0])) / n

    s = side(p)
    return s if side(c) > 0 else -s


def seat_hold(profile, layout, masses: dict[str, float] | None = None, preload_n: float | None = None) -> SeatHold:
    """The seat's restoring moments and lift-off side pull (:class:`SeatHold`) from the seat's contacts
    and springs as drawn, the springs' preload (each; default the bought springs' at their installed
    length, rigcad.parts.tower.spring_force), and the holder's and the camera's weights (kg: ``masses``,
    else the holder's rigcad.fab.loads.ASSUMED_MASS_KG and the profile's ``camera.mass``) at the holder's middle and
    the camera body's centre; the camera's height is its body's centre over the balls' centres."""
    t = layout.tower
    seat = T.splitter_seat(profile, layout)
    pts = {c.kind: (c.x, c.y) for c in seat.contacts}
    spring = T.spring_force(1)["force_N"] if preload_n is None else preload_n
    (cx0, cy0, cz0), (cx1, cy1, cz1) = t.camera_box
    camera = (0.5 * (cx0 + cx1), 0.5 * (cy0 + cy1))
    holder = (0.5 * (t.holder_x[0] + t.holder_x[1]), 0.0)
    g = loads.G
    ld = [*((f"spring {i + 1}", spring, x, y) for i, (x, y) in enumerate(T._holder_flange_points(t, profile))),
          ("holder's weight", loads._mass(profile, "holder", masses) * g, *holder),
          ("camera's weight", loads._mass(profile, "camera", masses) * g, *camera)]
    moments = {}
    for a, b, c in (("cone", "vee", "flat"), ("vee", "flat", "cone"), ("flat", "cone", "vee")):
        moments[f"{a}-{b}"] = sum(f * _inside((x, y), pts[a], pts[b], pts[c]) for _, f, x, y in ld)
    height = 0.5 * (cz0 + cz1) - seat.contacts[0].ball_z
    return SeatHold(moments, height, tuple(ld), min(moments.values()) / height)


def check(profile, layout, masses: dict[str, float] | None = None) -> SeatHold:
    """:func:`seat_hold`, refused (GeometryError) when SIDE_PULL_N at the camera would lift a ball."""
    hold = seat_hold(profile, layout, masses)
    if hold.lift_pull_n < SIDE_PULL_N:
        sp = T.SEAT_SPRING
        edge = min(hold.moments_nmm, key=hold.moments_nmm.get)
        raise GeometryError(f"the splitter seat lifts a ball under {hold.lift_pull_n:.1f} N at the camera "
                            f"({hold.camera_height_mm:.0f} mm over the balls; its {edge} edge's restoring moment "
                            f"{hold.moments_nmm[edge] / 1000:.2f} N m), short of the {SIDE_PULL_N:g} N it must take: "
                            f"stiffer preload springs than wire {sp['wire']:g} mm set to {sp['installed_length']:g} mm "
                            "(rigcad.parts.tower.SEAT_SPRING)", where=profile.where("camera", "mass"))
    return hold


__all__ = ["SIDE_PULL_N", "SeatHold", "check", "seat_hold"]
