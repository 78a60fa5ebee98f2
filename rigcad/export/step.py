"""STEP: deterministic writing, named and coloured parts, and the re-import check.

build123d's ``export_step`` takes a fixed ``timestamp`` so a single part's file is byte-for-byte
repeatable. With several coloured parts OCCT writes the colour (presentation) entities in an
order that follows heap addresses (STEPCAFControl_Writer iterates a map keyed by shape address),
so :func:`canonical_step` reorders that tail deterministically. Every file is re-read with OCCT's
STEP reader after writing and checked: a valid solid per part, and the volume of the shape written.
"""

from __future__ import annotations

import re
from pathlib import Path

from rigcad.errors import ExportError

#: The fixed header timestamp (STEP requires one; a clock time would change every file, so the
#: header's description says the time stamp is fixed).
TIMESTAMP = "2000-01-01T00:00:00"
#: Re-imported volume must match the written shape's to this relative precision: both are the
#: same B-rep integrated by the same adaptive rule (1e-9), so only STEP's float printing differs.
REIMPORT_VOLUME_RTOL = 1e-6


def _labelled(shape, name: str, color: tuple[float, float, float]):
    import build123d as bd

    solid = bd.Solid(shape) if shape.ShapeType().name == "TopAbs_SOLID" else bd.Compound(shape)
    solid.label = name
    solid.color = bd.Color(*color)
    return solid


def step_writer(parts: list[tuple[str, object, tuple[float, float, float]]], label: str):
    """A writer(path) that puts (name, TopoDS_Shape, rgb) parts in one deterministic STEP file."""
    import build123d as bd

    items = [_labelled(shape, name, color) for name, shape, color in parts]
    target = items[0] if len(items) == 1 else bd.Compound(label=label, children=items)
    if len(items) == 1:
        target.label = label

    def writer(tmp: Path) -> None:
        if not bd.export_step(target, str(tmp), timestamp=TIMESTAMP):
            raise ExportError(f"OCCT's STEP writer failed on {label}")
        text = tmp.read_text(encoding="latin-1")
        if len(items) > 1:
            text = canonical_step(text)
        what = f"part {label}" if len(items) == 1 else f"assembly {label} of {len(items)} parts"
        tmp.write_text(with_header(text, label, what), encoding="latin-1", newline="\n")

    return writer


def _step_string(text: str) -> str:
    """``text`` as an ISO 10303-21 string literal: quotes doubled, ASCII only (others as '?')."""
    return "'" + text.encode("ascii", "replace").decode().replace("'", "''") + "'"


def with_header(text: str, label: str, what: str) -> str:
    """``text`` (a STEP file) with rigcad's HEADER section: FILE_DESCRIPTION says what it holds
    (``what``, e.g. "part dome") and that the time stamp is fixed; FILE_NAME names ``label``, the
    fixed :data:`TIMESTAMP`, no author or organisation (OCCT's placeholders 'Author' and
    'Open CASCADE' removed), OCCT's STEP processor as the preprocessor (as it wrote it) and
    ``rigcad <version>`` as the originating system. FILE_SCHEMA is kept as OCCT wrote it."""
    from rigcad._version import __version__

    start, end = text.find("HEADER;"), text.find("ENDSEC;")
    schema = re.search(r"FILE_SCHEMA\s*\(.*?\)\s*;", text[start:end], re.S)
    processor = re.search(r"FILE_NAME\s*\(.*?,\s*('Open CASCADE STEP processor [^']*')", text[start:end], re.S)
    if start < 0 or end < start or schema is None or processor is None:
        raise ExportError(f"OCCT's STEP file for {label} has no HEADER section with FILE_NAME and FILE_SCHEMA")
    system = _step_string(f"rigcad {__version__}")
    header = (f"HEADER;\nFILE_DESCRIPTION(({_step_string(f'rigcad {__version__}: {what}')},"
              f"{_step_string('time stamp fixed: the same input gives the same bytes')}),'2;1');\n"
              f"FILE_NAME({_step_string(label)},{_step_string(TIMESTAMP)},(''),(''),\n  {processor.group(1)},"
              f"{system},'');\n{schema.group(0)}\n")
    return text[:start] + header + text[end:]


def reimport_check(path: Path, expected_volume: float, expected_solids: int) -> dict:
    """Read ``path`` back with OCCT and check validity, solid count and volume; return figures."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_Reader

    from rigcad.parts._kernel import is_valid, solids, volume

    reader = STEPControl_Reader()
    if reader.ReadFile(str(path)) != IFSelect_RetDone:
        raise ExportError(f"{path}: OCCT cannot read the STEP file it just wrote")
    reader.TransferRoots()
    shape = reader.OneShape()
    valid, n, vol = is_valid(shape), solids(shape), volume(shape)
    rel = abs(vol - expected_volume) / abs(expected_volume)
    if not valid or n != expected_solids or rel > REIMPORT_VOLUME_RTOL:
        raise ExportError(
            f"{path}: re-imported STEP is wrong (valid={valid}, solids={n} of {expected_solids}, volume "
            f"{vol:.6g} vs {expected_volume:.6g} mm^3): faces were lost on export")
    return {"valid": valid, "solids": n, "volume_mm3": vol, "volume_rel_diff": rel}


_REF = re.compile(r"#(\d+)")
_NAUO = re.compile(r"#(\d+)\s*=\s*NEXT_ASSEMBLY_USAGE_OCCURRENCE\s*\(\s*'[^']*'\s*,(.*)$", re.S)
_STYLE_ROOTS = ("MECHANICAL_DESIGN_GEOMETRIC_PRESENTATION_REPRESENTATION", "DRAUGHTING_MODEL")


def _outside_strings(body: str) -> str:
    """``body`` with the insides of quoted strings blanked, so '#12' in a name is no reference."""
    out, quoted = [], False
    for ch in body:
        if ch == "'":
            quoted = not quoted
        out.append(" " if quoted and ch != "'" else ch)
    return "".join(out)


def _compact(body: str) -> str:
    """``body`` without whitespace outside quoted strings (OCCT wraps long entities over lines)."""
    out, quoted = [], False
    for ch in body:
        if ch == "'":
            quoted = not quoted
        if quoted or not ch.isspace():
            out.append(ch)
    return "".join(out)


def _statements(data: str) -> list[str]:
    out, buf, quoted = [], [], False
    for ch in data:
        buf.append(ch)
        if ch == "'":
            quoted = not quoted
        elif ch == ";" and not quoted:
            out.append("".join(buf).strip())
            buf = []
    if "".join(buf).strip():
        raise ExportError("STEP DATA section does not end with a complete entity")
    return out


def canonical_step(text: str) -> str:
    """Make an OCCT assembly STEP file deterministic: number the assembly occurrences in file
    order, and reorder the presentation (colour) tail.

    The tail starts at the first presentation root; nothing before it refers into it. Each root's
    closure of tail entities is sorted by the (deterministic) head entities it styles, then the
    tail is renumbered in that order. Entities before the tail are left byte-for-byte alone.
    """
    start = text.index("DATA;") + len("DATA;")
    end = text.rindex("ENDSEC;")
    stmts = _statements(text[start:end])
    ents: dict[int, str] = {}
    order: list[int] = []
    for s in stmts:
        m = re.match(r"#(\d+)\s*=\s*(.*);$", s, re.S)
        if not m:
            raise ExportError(f"unexpected STEP statement: {s[:60]!r}")
        ents[int(m.group(1))] = m.group(2)
        order.append(int(m.group(1)))
    # OCCT numbers assembly occurrences from a process-wide counter: number them in file order.
    occurrence = 0
    for i, stmt in enumerate(stmts):
        m = _NAUO.match(stmt)
        if m:
            occurrence += 1
            body = _compact(m.group(2))
            stmts[i] = f"#{m.group(1)} = NEXT_ASSEMBLY_USAGE_OCCURRENCE('{occurrence}',{body}"
            ents[int(m.group(1))] = stmts[i].split(" = ", 1)[1][:-1]
    roots = [n for n in order if ents[n].lstrip().startswith(_STYLE_ROOTS)]
    if len(roots) < 2:
        return text[:start] + "\n" + "\n".join(stmts) + "\n" + text[end:] if occurrence else text
    t0 = order.index(min(roots))
    tail = set(order[t0:])
    refs = {n: [int(r) for r in _REF.findall(_outside_strings(ents[n]))] for n in order}
    if any(set(refs[n]) & tail for n in order[:t0]):
        raise ExportError("STEP colour tail is referenced from the geometry: cannot canonicalise")

    def walk(root: int, seen: set[int]) -> tuple[list[int], list[int]]:
        inside, outside, stack = [], [], [root]
        while stack:
            n = stack.pop()
            if n in seen:
                continue
            seen.add(n)
            inside.append(n)
            for r in reversed(refs[n]):
                (stack if r in tail else outside).append(r)
        return inside, outside

    keyed = sorted((sorted(walk(r, set())[1]), ents[r], r) for r in order[t0:] if r in roots)
    seen: set[int] = set()
    new_order: list[int] = []
    for _, _, root in keyed:
        new_order += walk(root, seen)[0]
    new_order += [n for n in order[t0:] if n not in seen]
    remap = dict(zip(new_order, sorted(order[t0:])))

    def renumber(body: str) -> str:
        """Rewrite references and put the entity on one line."""
        out, quoted, i = [], False, 0
        while i < len(body):
            ch = body[i]
            if ch == "'":
                quoted = not quoted
            if not quoted and ch == "#":
                m = _REF.match(body, i)
                out.append(f"#{remap.get(int(m.group(1)), int(m.group(1)))}")
                i = m.end()
                continue
            out.append(ch)
            i += 1
        return _compact("".join(out))

    head = stmts[:t0]
    tail_lines = sorted((remap[n], f"#{remap[n]} = {renumber(ents[n])};") for n in new_order)
    return text[:start] + "\n" + "\n".join(head + [line for _, line in tail_lines]) + "\n" + text[end:]
