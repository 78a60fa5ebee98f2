"""Hostile input: every class of malformed profile or printer file the fault campaign found, generated
here, run through the command line in-process. Each one must end in one `rigcad: error:` line (exit
1 or 2, never a traceback), in under 2 s of CPU, with nothing written; a file `extends:` may not reach is
never opened (an audit hook watches every open) and never echoed. `make test` runs the corpus
(>= 300 cases) and hypothesis over the YAML text; `make stress` the large version (>= 2,000).
"""

from __future__ import annotations

import os
import random
import sys
import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rigcad.cli import main
from rigcad.errors import RigcadError
from rigcad.fab.printers import load_printer
from rigcad.profile.loader import MAX_BYTES, MAX_DEPTH, MAX_NODES

SECRET = "SECRET-MARKER root:x:0:0"
BASE = "extends: achutha2006\n"
LENGTH_KEYS = ["paraboloid:\n  vertical_extent", "layout:\n  cop_to_vertex", "layout:\n  sample_to_rim",
               "dome_shell:\n  wall", "beam:\n  width", "dome:\n  tolerance"]
ANGLE_KEYS = ["paraboloid:\n  tangent_angle", "targets:\n  theta_min", "misalignment:\n  camera_tilt"]
INT_KEYS = ["dome:\n  table_rows", "dome:\n  euler_steps", "raycheck:\n  rays", "raycheck:\n  seed",
            "dome_shell:\n  bolts", "tolerancing:\n  seed"]
FLOAT_KEYS = ["projector:\n  throw_ratio", "raycheck:\n  min_px_per_deg", "tolerancing:\n  min_yield"]
STRANGE_CHARS = ["\uff11", "\u0661", "\u0967", "\u06f1", "\u00a0", "\u2009", "\u2007", "\u3000", "\u00b2",
                 "\u2212", "\u200b", "\ufeff"]


# -- the corpus ------------------------------------------------------------------------------------

def _utf8(text: str) -> bytes:
    return text.encode("utf-8")


def _encoding_cases(rng: random.Random, scale: int):
    good = (Path(__file__).resolve().parents[2] / "profiles" / "achutha2006.yaml").read_text()
    text = BASE + "description: caf\u00e9 \u00fcber na\u00efve\n"
    yield "latin-1", text.encode("latin-1")
    yield "cp1252", (BASE + "description: \u201cquoted\u201d\n").encode("cp1252")
    for enc in ("utf-16", "utf-16-le", "utf-16-be", "utf-32", "utf-32-le"):
        yield enc, good.encode(enc)
    for name, junk in [("overlong", b"\xc0\xaf"), ("surrogate", b"\xed\xa0\x80"), ("truncated", b"\xe2\x82"),
                       ("lone continuation", b"\x80"), ("ff", b"\xff\xfe\xfd")]:
        yield f"invalid utf-8 {name}", _utf8(BASE + "description: x") + junk + b"\n"
    for i in range(8 * scale):
        yield f"binary junk {i}", bytes(rng.randrange(256) for _ in range(rng.choice([1, 16, 500, 4000])))
    for i in range(4 * scale):
        pos = rng.randrange(len(good))
        yield f"NUL at {pos}", _utf8(good[:pos]) + b"\x00" + _utf8(good[pos:])
    for code in [*range(1, 9), 11, 12, *range(14, 32), 0x7F, 0x80, 0x9F]:
        yield f"control U+{code:04X}", _utf8(BASE + f"description: a{chr(code)}b\n")
    yield "noncharacter U+FFFE", _utf8(BASE + "description: a\ufffeb\n")


def _size_cases(scale: int):
    yield "just over the limit", _utf8(BASE + "#" * (MAX_BYTES + 1) + "\n")
    yield "1 MiB of keys", _utf8(BASE + "".join(f"k{i}: {i}\n" for i in range(100_000)))
    yield "4 MiB comment", _utf8(BASE + "# " + "x" * (4 << 20) + "\n")
    if scale > 1:
        yield "50 MB profile", _utf8("description: x\n" + ("# " + "x" * 98 + "\n") * 500_000)
    yield "a 20,000-character value", _utf8(BASE + "description: " + "x" * 20_000 + "\n")


def _nesting_cases(scale: int):
    for depth in [MAX_DEPTH + 1, 100, 500, 5000, 50_000][: 3 + scale]:
        yield f"flow lists {depth}", _utf8("a: " + "[" * depth + "]" * depth + "\n")
        yield f"flow maps {depth}", _utf8("a: " + "{b: " * depth + "1" + "}" * depth + "\n")
        if depth <= 5000:
            yield f"block maps {depth}", _utf8("".join("  " * i + f"k{i}:\n" for i in range(depth)) + "  " * depth + "v: 1\n")
            yield f"block lists {depth}", _utf8("".join("  " * i + "-\n" for i in range(depth)) + "  " * depth + "- 1\n")
    yield "mixed deep", _utf8("a: " + "[{b: " * 300 + "1" + "}]" * 300 + "\n")


def _bomb(width: int, depth: int, under: str) -> bytes:
    first = ", ".join(['"lol"'] * width)
    lines = [f"{under}:", f"  a0: &a0 [{first}]"]
    for i in range(1, depth + 1):
        lines.append(f"  a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * width) + "]")
    return _utf8("\n".join(lines) + "\n")


def _alias_cases(scale: int):
    for width in (2, 5, 9, 10):
        for depth in range(3, 7 + scale):
            yield f"alias bomb {width}^{depth}", _bomb(width, depth, "layout")
    yield "alias bomb in description", _utf8('x: &x ["a","a","a","a","a","a","a","a","a","a"]\n'
                                             + "".join(f"y{i}: &y{i} [" + ",".join([f"*{'x' if i == 0 else f'y{i - 1}'}"] * 10)
                                                       + "]\n" for i in range(8)) + "description: *y7\n")
    yield "alias cycle", _utf8("a: &a [*a]\n")
    yield "alias cycle in map", _utf8("a: &a {b: *a}\n")
    yield "undefined alias", _utf8("a: *nope\n")


def _number_cases():
    for key in INT_KEYS:
        yield f"{key.split()[-1]} 5000 digits", _utf8(f"{BASE}{key}: {'9' * 5000}\n")
        yield f"{key.split()[-1]} 4000 digits", _utf8(f"{BASE}{key}: {'9' * 4000}\n")
        yield f"{key.split()[-1]} 2**70", _utf8(f"{BASE}{key}: {2 ** 70}\n")
        yield f"{key.split()[-1]} float", _utf8(f"{BASE}{key}: 1.0e+400\n")
        yield f"{key.split()[-1]} negative", _utf8(f"{BASE}{key}: -{'9' * 30}\n")
    for key in LENGTH_KEYS:
        for value in ["1e400 mm", "1e308 m", "-1e309 mm", "1" + "0" * 400 + " mm", "1e-400 mm", "9" * 60 + " mm",
                      "1e300 m", "nan mm", ".nan", "1e6 mm", "-1e5 m"]:
            yield f"{key.split()[-1]} {value[:20]}", _utf8(f"{BASE}{key}: {value}\n")
    for key in ANGLE_KEYS:
        for value in ["1e400 deg", "inf deg", "-inf rad", "1e308 rad", "nan deg", "9" * 60 + " deg"]:
            yield f"{key.split()[-1]} {value[:20]}", _utf8(f"{BASE}{key}: {value}\n")
    for key in FLOAT_KEYS:
        for value in [".inf", "-.inf", ".nan", "1.0e+400", "1" + "0" * 400, "1e300"]:
            yield f"{key.split()[-1]} {value[:20]}", _utf8(f"{BASE}{key}: {value}\n")


def _digit_cases():
    for ch in STRANGE_CHARS:
        for key, unit in [(k, "mm") for k in LENGTH_KEYS[:3]] + [(k, "deg") for k in ANGLE_KEYS[:2]]:
            for value in (f"1{ch}3 {unit}", f"13{ch}{unit}", f"{ch}13 {unit}"):
                yield f"{key.split()[-1]} U+{ord(ch):04X} {value.index(ch)}", _utf8(f"{BASE}{key}: '{value}'\n")
        yield f"int U+{ord(ch):04X}", _utf8(f"{BASE}dome:\n  table_rows: 2{ch}01\n")


def _extends_cases():
    for value in ["/etc/passwd", "/etc/shadow", "../../etc/passwd", "../../x", "''", "' '", "[]", "{}", "5", "true",
                  "/", ".", "..", "~/x", "../secret/secret.yaml", "SECRET_ABS", "nosuch", "sub/../../secret/secret.yaml",
                  "link.yaml", "link", "/proc/self/environ", "/dev/zero"]:
        yield f"extends {value}", value


def _tag_cases():
    for value in ["!!python/object/apply:os.system ['touch PWNED']", "!!python/name:os.system",
                  "!!python/object/new:os.system ['touch PWNED']", "!!binary aGVsbG8=", "!!set {a, b}",
                  "!!timestamp 2001-12-14", "!!omap [a: 1]", "!custom 5", "!!float abc", "!!int 1e400",
                  "!!int " + "9" * 5000]:
        for key in ("layout:\n  cop_to_vertex", "description"):
            yield f"tag {value[:30]} in {key.split()[-1]}", _utf8(f"{BASE}{key}: {value}\n")


def _structure_cases():
    yield "complex key", _utf8(BASE + "? [a]\n: b\n")
    yield "int key", _utf8(BASE + "1: x\n")
    yield "null key", _utf8(BASE + "~: x\n")
    yield "duplicate key", _utf8(BASE + "layout:\n  cop_to_vertex: 1 cm\n  cop_to_vertex: 2 cm\n")
    yield "top-level list", _utf8("- a\n- b\n")
    yield "scalar document", _utf8("hello\n")
    yield "two documents", _utf8(BASE + "---\nx: 1\n")
    yield "empty", b""
    yield "only a BOM", b"\xef\xbb\xbf"
    yield "tabs", _utf8(BASE + "layout:\n\tcop_to_vertex: 1 cm\n")
    yield "unclosed", _utf8(BASE + "layout: {a: [1\n")
    yield "section not a mapping", _utf8(BASE + "layout: [1, 2]\n")
    yield "unknown section", _utf8(BASE + "lay_out: {}\n")
    yield "resolution huge", _utf8(BASE + "projector:\n  resolution: [1000000000, 1000000000]\n")


def _geometry_cases():
    for name, text in [
        ("tangent_angle 0.001 deg", "paraboloid:\n  tangent_angle: 0.001 deg\n"),
        ("tangent_angle 0 deg", "paraboloid:\n  tangent_angle: 0 deg\n"),
        ("tangent_angle 89.999 deg", "paraboloid:\n  tangent_angle: 89.999 deg\n"),
        ("vertical_extent 1e6 mm", "paraboloid:\n  vertical_extent: 1e6 mm\n"),
        ("vertical_extent 1e-9 mm", "paraboloid:\n  vertical_extent: 1e-9 mm\n"),
        ("tolerance 1000 mm", "dome:\n  tolerance: 1000 mm\n"),
        ("tolerance 1 um", "dome:\n  tolerance: 1 um\n"),
        ("tolerance 1e-7 mm", "dome:\n  tolerance: 1e-7 mm\n"),
        ("cop_to_vertex 1e300 m", "layout:\n  cop_to_vertex: 1e300 m\n"),
        ("sample_to_rim 1 um", "layout:\n  sample_to_rim: 1 um\n"),
        ("throw_ratio 1e300", "projector:\n  throw_ratio: 1e300\n"),
    ]:
        yield name, _utf8(BASE + text)


def corpus(scale: int = 1, seed: int = 11):
    """(class, name, payload) for every hostile case; ``scale`` multiplies the random classes."""
    rng = random.Random(seed)
    classes = {
        "encoding": _encoding_cases(rng, scale), "size": _size_cases(scale), "nesting": _nesting_cases(scale),
        "aliases": _alias_cases(scale), "numbers": _number_cases(), "digits": _digit_cases(),
        "extends": _extends_cases(), "tags": _tag_cases(), "structure": _structure_cases(),
        "geometry": _geometry_cases(),
    }
    return [(cls, name, payload) for cls, cases in classes.items() for name, payload in cases]


# -- running a case --------------------------------------------------------------------------------

_opened: list[str] = []
_watching = False


def _audit(event: str, args) -> None:
    if _watching and event == "open" and isinstance(args[0], (str, bytes, os.PathLike)):
        _opened.append(os.fsdecode(args[0]))


sys.addaudithook(_audit)


@pytest.fixture
def arena(tmp_path, monkeypatch):
    """A working folder with a profile folder, a secret outside the search path and a symlink to it."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("RIGCAD_PROFILES", raising=False)
    (tmp_path / "secret").mkdir()
    secret = tmp_path / "secret" / "secret.yaml"
    secret.write_text(f"{SECRET}: 1\n")
    work = tmp_path / "work"
    work.mkdir()
    (work / "link.yaml").symlink_to(secret)
    return tmp_path


def run_case(arena: Path, payload, capsys, command: str = "design") -> tuple[int, str, float]:
    """Write the case, run ``rigcad <command>`` on it in-process and check the contract."""
    global _watching
    work = arena / "work"
    path = work / "p.yaml"
    if isinstance(payload, str):  # an extends: value
        value = payload.replace("SECRET_ABS", str(arena / "secret" / "secret.yaml"))
        payload = _utf8(f"extends: {value}\nlayout:\n  cop_to_vertex: 30 cm\n")
    path.write_bytes(payload)
    out = arena / "exports"
    capsys.readouterr()
    _opened.clear()
    _watching = True
    t0 = time.thread_time()  # CPU seconds of this thread: neither a loaded machine nor threads an earlier test left running stretch them
    try:
        rc = main([command, str(path), "--exports", str(out)])
    finally:
        _watching = False
    elapsed = time.thread_time() - t0
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.strip()]
    assert rc in (1, 2), f"accepted (exit {rc})"
    assert len(lines) == 1 and lines[0].startswith("rigcad: error: "), err[-2000:]
    assert "Traceback" not in err
    assert SECRET not in err and "root:" not in err, err
    assert not out.exists() or not any(p.is_file() for p in out.rglob("*")), "files written for a refused profile"
    secret_dir = (arena / "secret").resolve()  # by path: the standard library's secrets.py is not the secret
    forbidden = [p for p in _opened if Path(p).resolve().is_relative_to(secret_dir)
                 or p.startswith(("/etc/", "/proc/", "/dev/"))]
    assert not forbidden, f"opened {forbidden}"
    assert not Path("PWNED").exists() and not (work / "PWNED").exists()
    assert elapsed < 2.0, f"{elapsed:.2f} s"
    return rc, lines[0], elapsed


CORPUS = corpus()


def test_the_corpus_covers_every_class_with_300_cases():
    classes = {cls for cls, _, _ in CORPUS}
    assert classes == {"encoding", "size", "nesting", "aliases", "numbers", "digits", "extends", "tags",
                       "structure", "geometry"}
    assert len(CORPUS) >= 300, len(CORPUS)


@pytest.mark.parametrize("cls", sorted({cls for cls, _, _ in CORPUS}))
def test_every_hostile_profile_is_one_line_fast_and_writes_nothing(arena, capsys, cls):
    slowest = 0.0
    for c, name, payload in CORPUS:
        if c != cls:
            continue
        try:
            _, _, elapsed = run_case(arena, payload, capsys)
        except AssertionError as err:
            raise AssertionError(f"{cls} / {name}: {err}") from None
        slowest = max(slowest, elapsed)


def _message(arena, capsys, payload: bytes) -> str:
    return run_case(arena, payload, capsys)[1]


def test_messages_name_what_is_wrong_and_where(arena, capsys):
    m = _message(arena, capsys, (BASE + "description: caf\u00e9\n").encode("latin-1"))
    assert "p.yaml:2" in m and "not UTF-8" in m and "offset 37" in m
    m = _message(arena, capsys, _utf8(BASE + "layout:\n  cop\x00: 1\n"))
    assert "p.yaml:3" in m and "U+0000" in m
    m = _message(arena, capsys, _bomb(10, 6, "layout"))
    assert f"more than {MAX_NODES} values" in m
    m = _message(arena, capsys, _utf8("a: " + "[" * 500 + "]" * 500 + "\n"))
    assert f"more than {MAX_DEPTH} levels" in m and "p.yaml:1" in m
    m = _message(arena, capsys, _utf8(BASE + "layout:\n  cop_to_vertex: '３0 cm'\n"))
    assert "layout.cop_to_vertex" in m and "U+FF13" in m and "ASCII digits" in m
    m = _message(arena, capsys, _utf8(BASE + "dome:\n  table_rows: " + "9" * 5000 + "\n"))
    assert "dome.table_rows" in m and "p.yaml:3" in m
    m = _message(arena, capsys, _utf8(BASE + "paraboloid:\n  tangent_angle: 0.001 deg\n"))
    assert "p.yaml:3" in m and "paraboloid.tangent_angle" in m and "at least 10" in m
    m = _message(arena, capsys, _utf8(BASE + "paraboloid:\n  vertical_extent: 1e6 mm\n"))
    assert "p.yaml:3" in m and "paraboloid.vertical_extent" in m and "10 m" in m
    m = _message(arena, capsys, _utf8(BASE + "dome:\n  tolerance: 1000 mm\n"))
    assert "p.yaml:3" in m and "dome.tolerance" in m and "<= 0.001 mm" in m
    m = _message(arena, capsys, _utf8(BASE + "dome:\n  tolerance: 1e-7 mm\n"))
    assert "p.yaml:3" in m and "dome.tolerance" in m and "however many rows" in m


@pytest.mark.parametrize("target", ["/etc/passwd", "../../x", "../secret/secret.yaml", "link.yaml", "SECRET_ABS"])
def test_extends_outside_the_search_path_is_refused_without_reading(arena, capsys, target):
    rc, message, _ = run_case(arena, target, capsys)
    assert rc == 2 and "p.yaml:1" in message
    assert "outside the profile search path" in message and "not read" in message


def test_extends_inside_the_search_path_still_works(arena, capsys):
    """A name beside the profile or on the search path, or a relative path that stays inside
    ./profiles (the working directory's profile folder) is read."""
    (arena / "profiles" / "sub").mkdir(parents=True)
    (arena / "profiles" / "base.yaml").write_text("extends: achutha2006\n")
    (arena / "profiles" / "sub" / "child.yaml").write_text("extends: ../base.yaml\nlayout:\n  cop_to_vertex: 30 cm\n")
    (arena / "work" / "named.yaml").write_text("extends: base\n")
    assert main(["profile", "show", "profiles/sub/child.yaml"]) == 0
    assert main(["profile", "show", str(arena / "work" / "named.yaml")]) == 0


@pytest.mark.parametrize("name, payload", [
    ("binary", bytes(range(256))), ("utf-16", "nozzle: 0.4 mm\n".encode("utf-16")), ("bomb", _bomb(10, 6, "x")),
    ("deep", _utf8("a: " + "[" * 200 + "]" * 200 + "\n")), ("extends /etc/passwd", _utf8("extends: /etc/passwd\n")),
    ("5000 digits", _utf8("layer_height: " + "1" * 5000 + "\n"))])
def test_printer_files_cross_the_same_boundary(tmp_path, name, payload):
    global _watching
    path = tmp_path / "printer.yaml"
    path.write_bytes(payload)
    _opened.clear()
    _watching = True
    try:
        with pytest.raises(RigcadError) as info:
            load_printer(path)
    finally:
        _watching = False
    assert "printer.yaml" in str(info.value)
    assert not [p for p in _opened if p.startswith("/etc/")]


# -- hypothesis over the YAML text -----------------------------------------------------------------

_TOKENS = ["extends: achutha2006\n", "layout:\n", "  cop_to_vertex: ", "paraboloid:\n", "  tangent_angle: ",
           "dome:\n", "  table_rows: ", "  tolerance: ", "description: ", "&a ", "*a", "[", "]", "{", "}", ", ",
           ": ", "- ", "\n", "  ", "'", '"', "!!python/object/apply:os.system ", "!!binary ", "---\n", "? ",
           "1e400", "9" * 50, " mm", " deg", ".inf", "\u00a0", "\uff11", "\x00", "\t", "#", "\\", "%YAML 1.1\n",
           "<<: *a\n", "~", "extends: ", "/etc/passwd", "../"]
yaml_texts = st.lists(st.one_of(st.sampled_from(_TOKENS), st.text(max_size=8)), max_size=40).map("".join)


def _hypothesis_case(arena_path: Path, text: str) -> None:
    import contextlib
    import io

    global _watching
    work = arena_path / "work"
    path = work / "h.yaml"
    path.write_bytes(text.encode("utf-8", "surrogatepass"))
    out = arena_path / "hexports"
    err = io.StringIO()
    _opened.clear()
    _watching = True
    t0 = time.thread_time()  # CPU seconds of this thread: neither a loaded machine nor threads an earlier test left running stretch them
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            rc = main(["profile", "show", str(path)])
    finally:
        _watching = False
    elapsed = time.thread_time() - t0
    lines = [line for line in err.getvalue().splitlines() if line.strip()]
    if rc != 0:
        assert rc in (1, 2) and len(lines) == 1 and lines[0].startswith("rigcad: error: "), err.getvalue()[-2000:]
        assert not out.exists()
        assert elapsed < 2.0, f"{elapsed:.2f} s"
    assert not [p for p in _opened if p.startswith(("/etc/", "/proc/", "/dev/"))]


def _hypothesis_arena(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("hyp")
    (root / "work").mkdir()
    return root


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(text=yaml_texts)
def test_hypothesis_yaml_text_never_crashes(tmp_path_factory, text):
    _hypothesis_case(_hypothesis_arena(tmp_path_factory), text)


# -- the large version: make stress ----------------------------------------------------------------

@pytest.mark.stress
def test_stress_corpus_of_2000(arena, capsys):
    cases = corpus(scale=6, seed=2006)
    rng = random.Random(7)
    while len(cases) < 2000:  # more random junk, NULs and bombs to reach the size
        cases.append(("binary", "junk", bytes(rng.randrange(256) for _ in range(rng.randrange(1, 5000)))))
    slowest = 0.0
    for cls, name, payload in cases:
        try:
            slowest = max(slowest, run_case(arena, payload, capsys)[2])
        except AssertionError as err:
            raise AssertionError(f"{cls} / {name}: {err}") from None
    print(f"{len(cases)} hostile cases, slowest {slowest:.2f} s")


@pytest.mark.stress
@settings(max_examples=2000, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(text=yaml_texts)
def test_stress_hypothesis_yaml_text(tmp_path_factory, text):
    _hypothesis_case(_hypothesis_arena(tmp_path_factory), text)
