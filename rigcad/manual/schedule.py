"""The one schedule from print to calibrated rig: every stage of the manual's work as data, each with
the rig state it needs (which parts are whole, in, off, what is cured or coated) and the state it
leaves, in the one order the manual is written in.

A state is a set of facts (short phrases: "dome on its register", "clear coat polished"). A stage
needs some facts, ends some (the dome lifted off ends "dome on its register") and makes others. The
order is right when every stage finds what it needs made by an earlier stage and not ended since
(:func:`unmet`); the manual refuses to write itself in an order that is not (:func:`check`), and a test
walks ``manual.json``'s ``schedule`` the same way.

Why an order is needed at all: the dome's seams are glued standing on the base plate on its flange
screws (the plate's inserts first), before the dome's own inserts (the beam seats') are melted; the
dome is indicated in from the bore (the holder in it) before the film and the camera_cross_base take the
holder's place, and the beam and the paraboloid go into the dome while it is off, before it is set back on its
pins over the film; the slope test needs the whole rig with its camera, on the
polished clear coat, before the mirror coat; the mirror coat needs the dome and the paraboloid off
again; the projector is aligned before the circle is set, the circle before the film comes off, the
whole film and its tape come off the plate before anything else lies on z = 0 (the checkerboard, the gray
card's straightedge, the screens), and the camera's hung cross replaces the paraboloid, which goes back after it.
"""

from __future__ import annotations

from dataclasses import dataclass

from rigcad.errors import AssemblyError
from rigcad.manual import calibration as C

#: The manual's section for each kind of stage (its headings, as the document writes them).
BEFORE = "0. Before printing: measure or choose"
PRINT = "2. Print"
SAND = "3. Sand the mirrors to the template"
RECIPE = "Finishing recipe, stage by stage"
COAT = "4. Coat, layer by layer, checking with the template"
ASSEMBLE = "5. Assemble"


@dataclass(frozen=True)
class Stage:
    """One stage of the schedule: ``what`` to do (one sentence), the manual's section that says how
    (``where``), the facts it ``needs`` in the rig's state, those it ``ends`` and those it ``makes``."""

    what: str
    where: str
    needs: frozenset[str] = frozenset()
    makes: frozenset[str] = frozenset()
    ends: frozenset[str] = frozenset()
    #: The assembly steps (rigcad.manual.plan's, by name) this stage first puts in place, in section 5's sense.
    places: tuple[str, ...] = ()

    def record(self) -> dict:
        return {"what": self.what, "where": self.where, "needs": sorted(self.needs), "makes": sorted(self.makes),
                "ends": sorted(self.ends), "places": list(self.places)}


def _s(what: str, where: str, needs=(), makes=(), ends=(), places=()) -> Stage:
    return Stage(what, where, frozenset(needs), frozenset(makes), frozenset(ends), tuple(places))


#: The assembly steps the schedule's own stages place before the rest (the tower) goes up: each stage
#: that places them names them, and :func:`rest` takes every other step of the plan.
PLACED_FIRST = ("sample_holder", "base_plate", "dome", "beam", "paraboloid")


def rest(steps) -> tuple[str, ...]:
    """The plan's steps (rigcad.manual.plan.steps, in its order) that no stage before the tower's places."""
    return tuple(st.name for st in steps if st.name not in PLACED_FIRST)


def _rest_stage(steps, tower: bool) -> Stage | None:
    """The stage that builds what stands on the plate after the dome: the tower's parts, named from the
    plan's steps when given (so a step the plan gains is in the schedule), else as the thesis's tower has them."""
    names = rest(steps) if steps is not None else ()
    if not tower and not names:
        return None
    listed = (", ".join(n.replace("_", " ") for n in names) if steps is not None else
              "column, shelf, seat, lens mount, shims, splitter holder, projector, lens, splitter, camera")
    return _s(f"Build the {'tower' if tower else 'rest'}: {listed} (the steps after the paraboloid).", ASSEMBLE,
              needs={"base plate down", "flat parts whole"}, makes={"projector on", "camera on"} if tower else (),
              places=names)


#: The camera aligned on its crosses before the slope test, the film laid (O's mark traced over the base cross).
CAMERA_FIRST = ("Lift the dome off, hang the camera cross on the beam in the paraboloid's place, set the dome back; "
                "align the camera on it and on O's mark on the film over the base cross, before the slope test; then "
                "put the paraboloid back the same way.")


def schedule(rig, fab_report: dict | None = None, steps=None) -> tuple[Stage, ...]:
    """The rig's schedule, print to calibrated rig (see the module docstring): the tower's stages when
    the rig has the COP tower, the dome's seams when the fab report split it, the deflectometry when the
    profile has a calibration section. ``steps``: the assembly plan's (rigcad.manual.plan.steps), which
    the stages' ``places`` cover, each step once; without them the tower's stage names no steps."""
    tower = getattr(rig.layout, "tower", None) is not None
    parts = (fab_report or {}).get("parts", {})
    seams = "step_on_gauge_mm" in ((parts.get("dome") or {}).get("seams") or {})
    split = sorted(n for n, e in parts.items() if len(e.get("pieces") or ()) > 1 and n != "dome")
    out = [
        _s("Measure the sizes the profile assumes and build again.", BEFORE, makes={"sizes measured"}),
        _s("Print every piece; cut the templates, the dome's printed-stage template with them.", PRINT,
           needs={"sizes measured"}, makes={"pieces printed", "templates cut"}),
    ]
    if tower:
        out.append(_s("Lap the column's foot-side and flange-side glue faces flat (float glass, P240).",
                      "5. Assemble (tower column)", needs={"pieces printed"}, makes={"column faces lapped"}))
    out.append(_s("Join the split flat parts on their pins with the glue the consumables name"
                  + (f" ({', '.join(split)})" if split else "") + "; let them cure.", PRINT,
                  needs={"pieces printed"} | ({"column faces lapped"} if tower else set()),
                  makes={"flat parts whole"}))
    out.append(_s("Melt the base plate's heat-set inserts and push the nuts into its traps (the base plate's step: before it goes in).",
                  ASSEMBLE, needs={"flat parts whole"}, makes={"base plate inserts"}))
    if seams:
        out.append(_s("Glue the dome's seams one at a time on the printed-stage template, its pieces standing on the "
                      "base plate on their flange screws, finger-tight; let each cure.", PRINT,
                      needs={"base plate inserts", "templates cut", "pieces printed"}, makes={"dome whole"}))
    elif "error" in (parts.get("dome") or {}):  # fab could not print it: never 'as printed'
        out.append(_s(f"The dome is not printable on this printer ({parts['dome']['error']}): solve that (the box at "
                      "the top of the manual) and print it before this stage; nothing below holds until it is whole.",
                      PRINT, needs={"pieces printed"}, makes={"dome whole"}))
    else:
        out.append(_s("Take the dome as printed (one piece).", PRINT, needs={"pieces printed"}, makes={"dome whole"}))
    out += [
        _s("Melt the dome's beam-seat inserts and the clamp's insert; press the beam's stop pin.", ASSEMBLE,
           needs={"dome whole"}, makes={"dome inserts"}),
        _s("Knock down the mirrors' layer lines on the printed sanding blocks until the sanded-stage template fits "
           "flush (the dome whole, upside down on blocks, its open base up: the template reads it from there, "
           "section 3).", SAND,
           needs={"dome whole", "templates cut"}, makes={"mirrors sanded"}),
        _s("Spray the base, the primer (blocked) and the clear coat; cure, wet-sand and polish the clear coat.",
           RECIPE, needs={"mirrors sanded"}, makes={"clear coat polished"}),
        _s("Put the sample holder in the base plate's bore and the plate on the bench (their steps).", ASSEMBLE,
           needs={"base plate inserts"}, makes={"base plate down", "dome off", "sample holder in the bore",
                                                "plate top clear"}, places=("sample_holder", "base_plate")),
        _s("Indicate the dome in from the bore (the test indicator on its arm on the sample holder, turned in the "
           "bore), drill and ream its register, press the pins; lift the dome off its pins again (the dome's step).",
           ASSEMBLE, needs={"base plate down", "dome off", "dome inserts", "clear coat polished",
                            "sample holder in the bore"},
           makes={"dome register drilled"}, places=("dome",)),
        _s("Take the sample holder out of the bore, stand the camera_cross_base in it, lay the film on the plate and "
           "trace O on it.", C.STEP_FILM, needs={"base plate down", "dome off", "dome register drilled"},
           makes={"film laid", "cross in the bore"}, ends={"sample holder in the bore", "plate top clear"}),
        _s("With the dome still off (upside down on the bench, its open base up), slide the beam in through its "
           "slots onto its seats, and put the paraboloid in through the dome's open base beside the beam and up onto "
           "it from below (their steps).",
           ASSEMBLE, needs={"dome off", "dome register drilled"},
           makes={"paraboloid on the beam"}, places=("beam", "paraboloid")),
        _s("Indicate the paraboloid in on the dome's axis (the dome upside down on the turntable, centred on its base) "
           "and set the clamp's foil packs to the placement tolerance (the optical acceptance test's first step).",
           C.STEP_ACCEPTANCE, needs={"paraboloid on the beam", "dome off"}, makes={"paraboloid placed"}),
        _s("Set the dome, the beam and the paraboloid in it, back on its register pins over the film and bolt it "
           "down.", ASSEMBLE, needs={"dome register drilled", "dome off", "paraboloid on the beam"},
           makes={"dome on its register"}, ends={"dome off"}),
    ]
    built = _rest_stage(steps, tower)
    if built is not None:
        out.append(built)
    out += _slope_and_coat(tower)
    return tuple(out + _calibration(rig, tower))


def _slope_and_coat(tower: bool) -> list[Stage]:
    """The slope test on the polished clear coat, the camera aligned first when the tower carries it, then
    the mirror coat."""
    out = []
    if tower:  # the slope test's budget counts the paraboloid's placement only: the camera must be on its place
        out.append(_s(CAMERA_FIRST, C.STEP_CAMERA, needs={"camera on", "cross in the bore", "dome on its register",
                                                          "film laid", "paraboloid placed"},
                      makes={"camera aligned"}))
    out += [
        _s("Slope test on the polished clear coat, before the mirror coat.", C.STEP_ACCEPTANCE,
           needs={"clear coat polished", "film laid", "camera on", "dome on its register", "paraboloid on the beam",
                  "paraboloid placed"} | ({"camera aligned"} if tower else set()),
           makes={"slope passed"}),
        _s("Lift the dome off its register (the beam and the paraboloid with it), take the paraboloid off the beam, "
           "spray the mirror coat on both; let it cure; set the paraboloid back and the dome on its pins.",
           RECIPE, needs={"slope passed", "dome on its register"}, makes={"mirrors coated"}),
    ]
    return out


def _calibration(rig, tower: bool) -> list[Stage]:
    """The schedule's calibration stages, after the mirror coat (section 6)."""
    out = []
    if tower:
        out += [
            _s("Align the projector on the crosses (the splitter holder off its seat, then back).", C.STEP_CROSSES,
               needs={"projector on"}, makes={"projector aligned"}),
            _s("Set the splitter's tilt with the seat's push screws; lock them.", C.STEP_SEAT,
               needs={"projector aligned", "mirrors coated", "film laid"}, makes={"splitter set"},
               ends={"camera aligned"}),  # the screws tilt the holder the camera rides on
        ]
    out += [
        _s("Set the circle on the paraboloid, judged on the film from below.", C.STEP_CIRCLE,
           needs={"mirrors coated", "film laid"} | ({"splitter set"} if tower else set()), makes={"circle set"}),
        _s("Lift the dome off its register pins, peel the whole film and its tape off the plate's top (nothing may "
           "stand on z = 0 under the checkerboard, the gray card's straightedge or the calibration screens), set the "
           "dome back; the camera_cross_base stays in the bore.", C.STEP_FILM,
           needs={"circle set", "film laid", "dome on its register"}, makes={"bore open", "plate top clear"},
           ends={"film laid"}),
        _s("Lift the dome off, hang the camera cross on the beam in the paraboloid's place, set the dome back; align "
           "the camera" + (" again (the splitter seat's screws tilted it with the holder)" if tower else "")
           + "; then put the paraboloid back the same way and the sample holder in the bore in the "
           "camera_cross_base's place.",
           C.STEP_CAMERA, needs={"bore open", "dome on its register", "cross in the bore"}
           | ({"camera on"} if tower else set()),
           makes={"camera aligned", "sample holder in the bore"}, ends={"cross in the bore"}),
        _s("Lay the checkerboard disc under the lifted dome, capture, take it out.", C.STEP_CHECKER,
           needs={"camera aligned", "circle set", "dome on its register", "plate top clear"},
           makes={"camera correspondence"}),
        _s("Capture the gray card in the sample holder and run rigcad calibrate --gray-card.", C.STEP_GRAY,
           needs={"camera aligned", "mirrors coated", "plate top clear", "sample holder in the bore"},
           makes={"reflectance scaled"}),
    ]
    if getattr(rig.profile, "calibration", None) is not None:
        out.append(_s("Capture the screens on their spacers and the upright display, run rigcad calibrate --images; "
                      "re-seat the paraboloid by what it reads.", C.STEP_AS_BUILT,
                      needs={"camera aligned", "mirrors coated", "dome on its register", "plate top clear"},
                      makes={"rig calibrated"}))
    return out


def unmet(stages) -> list[tuple[int, str, list[str]]]:
    """The stages (1-based number, what, the facts missing) that need a fact no earlier stage made, or
    one an earlier stage ended since. ``stages``: Stage objects or their records (manual.json's)."""
    state: set[str] = set()
    out = []
    for k, st in enumerate(stages, 1):
        rec = st.record() if isinstance(st, Stage) else st
        missing = sorted(set(rec["needs"]) - state)
        if missing:
            out.append((k, rec["what"], missing))
        state = (state - set(rec["ends"])) | set(rec["makes"])
    return out


#: The facts that say where the dome is while a step is done: off its register (upside down on the bench,
#: its open base up) or on its register pins.
DOME_OFF = "dome off"
DOME_ON = "dome on its register"


def placing_states(stages) -> dict[str, tuple[int, frozenset[str], frozenset[str]]]:
    """Each assembly step a stage places (by name) -> (that stage's 1-based number, the rig's state when the
    stage begins, the state it leaves): what section 5 says about the dome at that step must be this.
    ``stages``: Stage objects or their records (manual.json's)."""
    state: frozenset[str] = frozenset()
    out = {}
    for k, st in enumerate(stages, 1):
        rec = st.record() if isinstance(st, Stage) else st
        after = (state - set(rec["ends"])) | set(rec["makes"])
        for name in rec["places"]:
            out[name] = (k, state, frozenset(after))
        state = frozenset(after)
    return out


def stage_ending(stages, fact: str) -> int | None:
    """The 1-based number of the first stage that ends ``fact`` (the dome set back: it ends DOME_OFF)."""
    for k, st in enumerate(stages, 1):
        rec = st.record() if isinstance(st, Stage) else st
        if fact in rec["ends"]:
            return k
    return None


def check(stages) -> None:
    """AssemblyError naming the first stage whose state no earlier stage made."""
    bad = unmet(stages)
    if bad:
        k, what, missing = bad[0]
        raise AssemblyError(f"the manual's schedule is out of order: stage {k} ({what}) needs "
                            f"{', '.join(missing)}, which no earlier stage leaves")


__all__ = ["DOME_OFF", "DOME_ON", "PLACED_FIRST", "Stage", "check", "placing_states", "rest", "schedule", "stage_ending",
           "unmet"]
