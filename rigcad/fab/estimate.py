"""Print time and material without a slicer: a model of what PrusaSlicer does, fitted to
PrusaSlicer's own figures on this rig's pieces (``bench/fab_stages.py --estimates --fit``).

A piece is read as the slicer builds it: a shell of ``perimeters`` beads around every surface
(``shell_mm`` thick: perimeters x extrusion width), the core inside it at the infill's share,
support under its overhangs (the columns from each overhang down to what it stands on, and the
overhang's area for the dense interface layers: rigcad.fab.orientation.support_contact), and the
island-layers: each island of each layer (a closed outline of the slice) is one loop the slicer
travels to, retracts for, starts a seam on and closes. A tall, thin piece (a tower column: 513
layers of thin walls, several islands each) spends much of its time there, which no volume term
sees. Material and time are linear in those, with non-negative coefficients (scipy's NNLS, each
piece's relative error weighing alike):

    material (mm3) = m_shell V_shell + m_core V_core + m_support V_support + m_island N_island
    time (s)       = t_shell V_shell + t_core V_core + t_support V_support + t_overhang A_overhang
                     + t_island N_island + t_piece

Where V_shell = min(V, surface area x shell_mm), V_core = V - V_shell, N_island = the islands
summed over the layers. The coefficients below were fitted on the Prusa MK3S (0.15 mm QUALITY, 3
perimeters, 20 % gyroid infill, Prusament PLA, PrusaSlicer 2.5) and hold there within
MAX_REL_ERROR on every piece; left out of the fit one part at a time, each part's pieces are
predicted within the leave-one-out errors in bench/results/fab_estimates.json. Another printer
scales the volume terms by its own deposition rate and the island term by its layer time against
the MK3S file's (8 mm3/s, 1 s): a first-order transfer, not a calibration.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Largest error (relative to PrusaSlicer) the fit is held to on every piece of the default profile.
MAX_REL_ERROR = 0.25
#: The calibration printer's figures the time scales against (profiles/printers/prusa_mk3s.yaml).
CALIBRATION = {"printer": "prusa_mk3s", "deposition_rate_mm3_s": 8.0, "layer_time_s": 1.0}


@dataclass(frozen=True)
class Fit:
    """Coefficients of the model (see the module docstring): material per mm3 of shell, core and
    support envelope (mm3/mm3) and per island-layer (mm3); time per mm3 (s/mm3), per mm2 of
    overhang (s/mm2), per island-layer (s) and per piece (s)."""

    m_shell: float
    m_core: float
    m_support: float
    m_island: float
    t_shell: float
    t_core: float
    t_support: float
    t_overhang: float
    t_island: float
    t_piece: float
    source: str


#: Fitted by `bench/fab_stages.py --estimates --fit` on achutha2006 / prusa_mk3s (28 pieces of 17
#: parts, PrusaSlicer 2.5.0): worst error 20.6 % in the fit, 28.9 % on a part left out of it;
#: bench/results/fab_estimates.json holds the table and the leave-one-part-out errors.
FIT = Fit(m_shell=0.922548, m_core=0.13058, m_support=0.217561, m_island=1.93945,
          t_shell=0.387839, t_core=0.0404128, t_support=0.0, t_overhang=2.88925, t_island=5.06252,
          t_piece=67.704, source="fitted to PrusaSlicer 2.5.0 on achutha2006 / prusa_mk3s")


@dataclass(frozen=True)
class Features:
    """What the model reads of a piece (mm, mm2, mm3; island_layers: the islands of every layer,
    summed: island_layers(layers))."""

    volume_mm3: float
    surface_mm2: float
    layers: int
    support_envelope_mm3: float
    overhang_mm2: float
    shell_mm: float
    island_layers: int

    @property
    def shell_volume_mm3(self) -> float:
        return min(self.volume_mm3, self.surface_mm2 * self.shell_mm)

    @property
    def core_volume_mm3(self) -> float:
        return self.volume_mm3 - self.shell_volume_mm3

    def material_row(self) -> np.ndarray:
        return np.array([self.shell_volume_mm3, self.core_volume_mm3, self.support_envelope_mm3,
                         float(self.island_layers)])

    def time_row(self) -> np.ndarray:
        return np.array([self.shell_volume_mm3, self.core_volume_mm3, self.support_envelope_mm3, self.overhang_mm2,
                         float(self.island_layers), 1.0])


def island_layers(layers) -> int:
    """The islands of every layer, summed: the outlines that enclose material (positive signed
    area, counter-clockwise as manifold3d returns a slice's outer boundaries; holes are clockwise)
    of ``layers`` (rigcad.fab.staircase.Layers, printer frame)."""
    count = 0
    for polys in layers.contours:
        for p in polys:
            x, y = p[:, 0], p[:, 1]
            count += int(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y) > 0.0)
    return count


def shell_thickness(printer) -> float:
    """Perimeters (the slicer settings', else 3) x their width (rigcad.fab.printers.perimeter_width: the
    settings', else PrusaSlicer's automatic 1.125 x the nozzle) (mm); an SLA print is solid (inf: all shell)."""
    from rigcad.fab.printers import perimeter_width

    if printer.process != "fdm":
        return float("inf")
    eff = printer.slicer_config.effective() if printer.slicer_config else {}
    try:
        perimeters = int(float(eff.get("perimeters", 3)))
    except ValueError:
        perimeters = 3
    return perimeters * perimeter_width(printer)


def estimate(features: Features, printer, fit: Fit = FIT) -> dict:
    """Time (s) and material (cm3, g) of one piece on ``printer`` by the fitted model."""
    mat = float(features.material_row() @ np.array([fit.m_shell, fit.m_core, fit.m_support, fit.m_island]))
    if printer.process != "fdm":
        mat = features.volume_mm3  # resin: the part itself (no infill; supports not modelled)
    rate = printer.deposition_rate_mm3_s or CALIBRATION["deposition_rate_mm3_s"]
    scale_v = CALIBRATION["deposition_rate_mm3_s"] / rate
    scale_l = (printer.layer_time_s / CALIBRATION["layer_time_s"]) if printer.layer_time_s > 0 else 1.0
    row = features.time_row()
    t = float(row[:4] @ np.array([fit.t_shell, fit.t_core, fit.t_support, fit.t_overhang])) * scale_v
    t += row[4] * fit.t_island * scale_l + fit.t_piece
    if printer.process != "fdm":  # resin: a whole layer is exposed at once, the time is per layer
        t = features.layers * printer.layer_time_s
    return {"method": f"rigcad model fitted to PrusaSlicer (rigcad.fab.estimate; {fit.source})",
            "print_time_s": t, "material_cm3": mat / 1000.0,
            "material_g": mat / 1000.0 * printer.material_density_g_cm3,
            "features": {"volume_mm3": features.volume_mm3, "surface_mm2": features.surface_mm2,
                         "layers": features.layers, "support_envelope_mm3": features.support_envelope_mm3,
                         "overhang_mm2": features.overhang_mm2, "shell_mm": features.shell_mm,
                         "island_layers": features.island_layers}}


def fit(rows: list[tuple[Features, float, float]], density_g_cm3: float, source: str) -> Fit:
    """Fit the model to (features, slicer time s, slicer filament g) of many pieces: NNLS on the
    relative error (each piece weighs alike, as the 25 % target does)."""
    from scipy.optimize import nnls

    f = [r[0] for r in rows]
    t = np.array([r[1] for r in rows], dtype=float)
    m = np.array([r[2] for r in rows], dtype=float) / density_g_cm3 * 1000.0  # mm3
    A = np.array([x.material_row() for x in f]) / m[:, None]
    cm, _ = nnls(A, np.ones(len(f)))
    B = np.array([x.time_row() for x in f]) / t[:, None]
    ct, _ = nnls(B, np.ones(len(f)))
    return Fit(*(float(v) for v in cm), *(float(v) for v in ct), source=source)
