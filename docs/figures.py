"""Every figure the docs quote, generated: what `make docs` runs.

    python docs/figures.py run [--exports DIR]   # the documented commands on the default profile, then
                                                 #   collect, copy the pictures, write the Markdown
                                                 #   (DIR, build/docs by default, emptied first)
    python docs/figures.py collect [--exports DIR]   # the same without running the commands
    python docs/figures.py render                # only rewrite the Markdown from docs/figures.json

A figure in README.md or docs/*.md is written as the number followed by its name in an HTML comment,
``1,096<!--fig:optimize.base.dome_mass--> g``: GitHub shows ``1,096 g``. ``run`` writes every figure
the spec below names into docs/figures.json (value, unit, the tolerance the docs test holds the text
to, the command and file it comes from, and for a measured time or a bench figure the machine and the
date), copies every picture the docs show (with the SHA-256 of its bytes and of the outputs it was
drawn from) and rewrites each marked number from the file. tests/test_docs.py holds the Markdown to
the file and the file to the current code's outputs.

The spec (FIGURES, BENCH, PICTURES) lives in docs/figure_spec.py.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import platform
import re
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Callable

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
FILE = DOCS / "figures.json"
PROFILE = "achutha2006"
#: The wall times of the last `run`, beside its outputs (so that `collect` can be re-run alone).
TIMES = "make_docs_times.json"
#: Where `make docs` runs the commands: its own folder (emptied by ``run``), not the user's exports/.
DOCS_EXPORTS = ROOT / "build" / "docs"

#: A number as the docs write it (thousands commas, a decimal part, an exponent), or several joined by
#: " x " (a size), followed by the marker naming its figure.
NUMBER = r"(?:(?<![\w>])-)?\d[\d,]*(?:\.\d+)?(?:e[-+]?\d+)?"  # a "-" after a marker is a range's dash
MARKED = re.compile(rf"(?P<num>{NUMBER}(?: x {NUMBER})*)<!--fig:(?P<name>[\w.\-]+)-->")


@dataclass(frozen=True)
class Run:
    """One documented command: ``rigcad <argv>`` with ``--exports <root>/<folder>``."""

    id: str
    argv: tuple[str, ...]
    folder: str = ""  # a separate exports root under the docs' exports (a partial fab run would
                      # overwrite the full one's report)

    @property
    def command(self) -> str:
        return "rigcad " + " ".join(self.argv)


#: How far a figure at the arithmetic's floor may move (:attr:`Figure.roundoff`): a changed design
#: moves it by orders of magnitude (the dome integrated to 1e-6 mm instead of 1e-8), a CPU by percents.
ROUNDOFF_FACTOR = 2.0


@dataclass(frozen=True)
class Figure:
    """A figure: ``get`` reads it from ``file`` (JSON, relative to the run's exports root)."""

    name: str
    run: str
    file: str
    get: str | Callable[[Any], Any]  # a dotted path (keys, list indices), a function of the JSON, or
                                     # "@bytes": the file's size in MB
    unit: str
    fmt: str = ".3g"  # the format spec the Markdown shows it in (each number of a size)
    count: bool = False  # an integer count: held exactly
    # a residual at the arithmetic's floor (1e-8 mm on 100-mm parts): its size is the claim, not its
    # digits; another CPU's vector width and FMA move it by percents (1.48e-8 -> 1.47e-8 mm, the dome's
    # largest miss on an AMD EPYC): held within a factor (ROUNDOFF_FACTOR)
    roundoff: bool = False

    def holds(self, new: Any, old: Any) -> bool:
        """Whether the current code's value ``new`` is still the recorded ``old``: a count exactly, a
        residual at the floor within :data:`ROUNDOFF_FACTOR`, any other figure to 1e-6 relative (the
        outputs are deterministic on one machine, another CPU's last bits move a figure by ~1e-12,
        and a changed part moves it visibly)."""
        news, olds = (new, old) if isinstance(new, list) else ([new], [old])
        if self.count:
            return news == olds
        if self.roundoff:
            return all(abs(a) <= ROUNDOFF_FACTOR * abs(b) and abs(b) <= ROUNDOFF_FACTOR * abs(a)
                       for a, b in zip(news, olds))
        return all(math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-12) for a, b in zip(news, olds))


@dataclass(frozen=True)
class Picture:
    """A picture the docs show: ``docs/<doc>`` copied from ``<exports root>/<src>``; ``source`` names
    what it was drawn from: ``file`` (bytes), ``file#a.b`` (a JSON section), ``file#a,b,c`` (JSON
    sections) or ``part:<name>`` (the part's shape in the manifest: :data:`PART_SHAPE`)."""

    doc: str
    run: str
    src: str
    source: str


def dig(data: Any, path: str) -> Any:
    """``data`` at a dotted path: dict keys, and integers as list indices."""
    for key in path.split("."):
        data = data[int(key)] if isinstance(data, list) else data[key]
    return data


def canonical_json(data: Any) -> bytes:
    """JSON with sorted keys and every float to 9 significant digits: what a source digest hashes, so
    that another CPU's last bits do not change it while any real change does."""
    def norm(v: Any) -> Any:
        if isinstance(v, float):
            return float(f"{v:.9g}") if math.isfinite(v) else repr(v)
        if isinstance(v, dict):
            return {k: norm(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [norm(x) for x in v]
        return v
    return json.dumps(norm(data), sort_keys=True, separators=(",", ":")).encode()


def sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


#: What a part's picture shows, as the manifest states it: the exact solid's volume, its bounding box
#: and genus, and how many the rig takes. Not the part's recipe hash: that hashes every float of the
#: recipe to the last bit, and another CPU's last bits change it (OPENBLAS_CORETYPE=Prescott with
#: numpy's SIMD off changes 7 parts' hashes, their volumes by <= 4e-14 and boxes by <= 5e-13 mm).
PART_SHAPE = ("volume_mm3", "bbox_min_mm", "bbox_max_mm", "genus", "quantity")


def part_shape(root: Path, name: str) -> dict:
    """Part ``name``'s :data:`PART_SHAPE` from the manifest under the exports root."""
    entry = json.loads((root / PROFILE / "manifest.json").read_text())["parts"][name]
    return {key: entry[key] for key in PART_SHAPE}


def picture_source(root: Path, source: str) -> dict:
    """What :func:`collect` records of a picture's source (see :class:`Picture`): a part's shape as
    numbers (``source_values``), anything else as its SHA-256 (``source_sha256``)."""
    if source.startswith("part:"):
        return {"source_values": part_shape(root, source[len("part:"):])}
    return {"source_sha256": source_digest(root, source)}


def same_source(recorded: dict, now: dict) -> bool:
    """Whether a picture's source is what it was drawn from: a digest the same, numbers within 1e-9
    (relative, and absolute: mm), integers the same."""
    if "source_sha256" in recorded or "source_sha256" in now:
        return recorded.get("source_sha256") == now.get("source_sha256")
    a, b = recorded.get("source_values"), now.get("source_values")
    if a is None or b is None or set(a) != set(b):
        return False
    def close(x, y) -> bool:
        if isinstance(x, list) and isinstance(y, list):
            return len(x) == len(y) and all(close(u, v) for u, v in zip(x, y))
        if isinstance(x, int) and isinstance(y, int):
            return x == y
        return isinstance(x, (int, float)) and isinstance(y, (int, float)) and math.isclose(
            x, y, rel_tol=1e-9, abs_tol=1e-9)
    return all(close(a[key], b[key]) for key in a)


def source_digest(root: Path, source: str) -> str:
    """SHA-256 of what a picture was drawn from (a file, or JSON sections: see :class:`Picture`),
    under the exports root."""
    file, _, section = source.partition("#")
    path = root / PROFILE / file
    if path.suffix != ".json":
        return sha256(path.read_bytes())
    data = json.loads(path.read_text())
    if "," in section:
        return sha256(canonical_json({key: dig(data, key) for key in section.split(",")}))
    return sha256(canonical_json(dig(data, section) if section else data))


def machine() -> str:
    """The CPU, its count and the load: what a measured time depends on."""
    model = platform.machine()
    with open("/proc/cpuinfo", encoding="utf-8") as f:
        for line in f:
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    return f"{model}, {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}"


def today() -> str:
    return datetime.now(timezone.utc).strftime("%Y-%m-%d")


def run_commands(runs, root: Path) -> dict[str, dict]:
    """Each command in turn (`nice` is the caller's), timed; a failing one stops `make docs`. The
    profile's outputs under every exports root the commands use are removed first: each time is a
    cold run (a command whose outputs are up to date returns at once) and no stale file is read."""
    for folder in sorted({run.folder for run in runs}):
        shutil.rmtree((root / folder if folder else root) / PROFILE, ignore_errors=True)
    times = {}
    for run in runs:
        exports = root / run.folder if run.folder else root
        argv = [sys.executable, "-c", "from rigcad.cli import main; raise SystemExit(main())", *run.argv,
                "--exports", str(exports)]
        print(f"make docs: {run.command}", flush=True)
        t0 = time.perf_counter()
        done = subprocess.run(argv, cwd=ROOT, stdout=subprocess.DEVNULL)
        seconds = time.perf_counter() - t0
        if done.returncode != 0:
            raise SystemExit(f"make docs: `{run.command}` failed (exit {done.returncode})")
        print(f"make docs: {run.command}: {seconds:.1f} s", flush=True)
        times[run.id] = {"seconds": seconds, "machine": machine(), "date": today()}
        (root / TIMES).write_text(json.dumps(times, indent=1) + "\n")  # `collect` reads them again
    return times


def _value(fig: Figure, root: Path, runs: dict[str, Run]) -> Any:
    run = runs[fig.run]
    path = (root / run.folder if run.folder else root) / fig.file
    if fig.get == "@bytes":  # a file's size, in MB
        value = path.stat().st_size / 1e6
    else:  # JSON is parsed; any other file (Markdown) is given to ``get`` as text
        data = json.loads(path.read_text()) if path.suffix == ".json" else path.read_text(encoding="utf-8")
        value = fig.get(data) if callable(fig.get) else dig(data, fig.get)
    if fig.count:
        if value != int(value):
            raise SystemExit(f"make docs: {fig.name} is a count but reads {value!r}")
        return int(value)
    if isinstance(value, (list, tuple)):
        return [float(v) for v in value]
    return float(value)


def extract(figures, runs, root: Path) -> dict[str, Any]:
    """Every figure's value read from the outputs under ``root`` (the test calls this on its own)."""
    by_id = {r.id: r for r in runs}
    return {f.name: _value(f, root, by_id) for f in figures}


def collect(spec, root: Path, times: dict[str, dict] | None) -> dict:
    """figures.json's content from the outputs under ``root``, the measured ``times`` (kept from the
    old file when the commands were not run) and the bench results."""
    old = json.loads(FILE.read_text()) if FILE.is_file() else {"figures": {}}
    runs = {r.id: r for r in spec.RUNS}
    figures: dict[str, dict] = {}
    for fig in spec.FIGURES:
        run = runs[fig.run]
        figures[fig.name] = {
            "value": _value(fig, root, runs), "unit": fig.unit, "format": fig.fmt,
            "tolerance": "exact" if fig.count else "as printed",
            "source": f"`{run.command}` -> {fig.file}" + ("" if callable(fig.get) else f" {fig.get}")}
    for run in spec.RUNS:
        name = f"time.{run.id}"
        t = (times or {}).get(run.id) or {k: old["figures"].get(name, {}).get(k) for k in ("value", "machine", "date")}
        seconds = t.get("seconds", t.get("value"))
        if seconds is None:
            continue
        figures[name] = {"value": round(seconds, 1), "unit": "s", "format": ".0f", "tolerance": "5 %",
                         "source": f"wall time of `{run.command}` in `make docs`", "kind": "measured",
                         "machine": t["machine"], "date": t["date"]}
    timed = [figures[f"time.{r.id}"] for r in spec.RUNS if f"time.{r.id}" in figures]
    if len(timed) == len(spec.RUNS):
        figures["time.make_docs"] = {**timed[-1], "value": round(sum(t["value"] for t in timed) / 60, 1), "unit": "min",
                                     "source": "the wall times of every command in `make docs`, summed"}
    figures.update(spec.bench_figures(ROOT))
    pictures = {}
    for pic in spec.PICTURES:
        run = runs[pic.run]
        exports = root / run.folder if run.folder else root
        src = exports / PROFILE / pic.src
        pictures[pic.doc] = {"sha256": sha256(src.read_bytes()), "from": f"`{run.command}` -> {pic.src}",
                             "source": pic.source, **picture_source(exports, pic.source)}
    return {"about": "every figure README.md and docs/*.md quote; written by `make docs` (docs/figures.py)",
            "profile": PROFILE, "figures": dict(sorted(figures.items())), "pictures": dict(sorted(pictures.items()))}


def copy_pictures(spec, root: Path) -> None:
    runs = {r.id: r for r in spec.RUNS}
    for pic in spec.PICTURES:
        run = runs[pic.run]
        exports = root / run.folder if run.folder else root
        dest = DOCS / pic.doc
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(exports / PROFILE / pic.src, dest)


def formatted(entry: dict) -> str:
    """A figure as the Markdown writes it."""
    value, fmt = entry["value"], entry.get("format", ".3g")
    if isinstance(value, list):
        return " x ".join(format(v, fmt) for v in value)
    return format(value, fmt)


def shown_numbers(num: str, entry: dict) -> str:
    """The part of a marked match that is the figure: its last number, or its last k for a size of k
    numbers ("1.75 x 11.5<!--fig:length-->" marks only 11.5)."""
    k = len(entry["value"]) if isinstance(entry["value"], list) else 1
    return " x ".join(num.split(" x ")[-k:])


def shown_prefix(num: str, entry: dict) -> str:
    """What precedes the figure's own numbers in a marked match (kept as written)."""
    return num[: len(num) - len(shown_numbers(num, entry))]


def pages() -> list[Path]:
    return [ROOT / "README.md", *sorted(DOCS.glob("*.md"))]


def render(figures: dict[str, dict]) -> list[str]:
    """Rewrite every marked number of the pages from ``figures``; returns the names no figure has."""
    missing = []
    for page in pages():
        text = page.read_text(encoding="utf-8")

        def sub(m: re.Match) -> str:
            entry = figures.get(m["name"])
            if entry is None:
                missing.append(f"{page.name}: {m['name']}")
                return m[0]
            return f"{shown_prefix(m['num'], entry)}{formatted(entry)}<!--fig:{m['name']}-->"

        new = MARKED.sub(sub, text)
        if new != text:
            page.write_text(new, encoding="utf-8")
    return missing


def write_file(data: dict) -> None:
    tmp = FILE.with_suffix(".tmp")
    tmp.write_text(json.dumps(data, indent=1, sort_keys=False, ensure_ascii=False) + "\n", encoding="utf-8")
    tmp.replace(FILE)


def main(argv: list[str] | None = None) -> int:
    sys.path.insert(0, str(DOCS))
    import figure_spec as spec  # noqa: PLC0415 - beside this file

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("action", choices=["run", "collect", "render"])
    ap.add_argument("--exports", type=Path, default=DOCS_EXPORTS)
    args = ap.parse_args(argv)
    root = args.exports.resolve()
    if args.action != "render":
        if args.action == "run":
            times = run_commands(spec.RUNS, root)
        else:
            times = json.loads((root / TIMES).read_text()) if (root / TIMES).is_file() else None
        copy_pictures(spec, root)
        write_file(collect(spec, root, times))
    missing = render(json.loads(FILE.read_text())["figures"])
    if missing:
        print("make docs: no figure named " + "; ".join(missing), file=sys.stderr)
        return 1
    n = len(json.loads(FILE.read_text())["figures"])
    print(f"make docs: {n} figures in {FILE.relative_to(ROOT)}; pages rewritten")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
