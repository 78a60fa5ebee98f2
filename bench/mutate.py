"""Mutation testing of the numerical core with mutmut 3: does each module's own test file fail
when one line of the module is changed?

Run from the repository root: ``.venv/bin/python bench/mutate.py [GROUP ...] [--max-children N]``
(``make mutate`` runs every group; ``--list`` names them, smallest first). Each group is a few
modules mutated against only their own test files (the table below), so a group finishes in
minutes rather than running the whole suite once per mutant. A group runs in its own copy of the
tree as committed (git archive HEAD), build/mutate/<group>/ (mutmut writes its mutants/ folder there), configured by a setup.cfg
written beside it, so groups never share mutmut's state.

Writes bench/results/mutation.json: per module the mutants killed, survived, timed out and with no
test reaching them, and the score, killed (timeouts included: a mutant that hangs the test is
caught) over all mutants tried. Groups not run keep their last entry. And bench/results/mutation.md:
every survivor's diff, with its explanation from bench/mutation_survivors.toml (an equivalent mutant,
or a claim no one makes) where it has one. mutmut's "no tests" and "survived" both count against the
score; a mutant left "not checked" (a run stopped early) is listed and counted apart.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import time
import tomllib
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "bench" / "results"
EXPLAINED = ROOT / "bench" / "mutation_survivors.toml"

# group -> (modules mutated, their own test files). Smallest first: `make mutate` runs them in order.
GROUPS: dict[str, tuple[list[str], list[str]]] = {
    "fab.outlines": (["rigcad/fab/outlines.py"], ["tests/fab/test_outlines.py"]),
    # the tests of the limits only: the Monte Carlo's tests start process pools and a dask cluster
    # in mutmut's own process (its clean run), whose workers mutmut then reaps as if they were its
    # mutants' and stops (KeyError in wait_for_result)
    "tolerance.limits": (["rigcad/tolerance/limits.py"],
                         [f"tests/tolerance/test_tolerance.py::{t}" for t in (
                             "test_inverse_limit_holds_at_the_limit_and_fails_at_twice_it",
                             "test_limit_search_at_its_two_ends",
                             "test_limit_rows_ranked_by_budget_and_a_zero_tolerance")]),
    # the rows on a hand-made report (test_tolerances.py, milliseconds) and the printed table;
    # test_raycheck.py's others keep their claims (every shipped profile passes on a real report, a
    # coarse tessellation fails naming its key, the CLI) but trace rigs: minutes a mutant
    "check.tolerances": (["rigcad/check/tolerances.py"],
                         ["tests/check/test_tolerances.py",
                          "tests/check/test_raycheck.py::test_the_table_is_fixed_width_with_a_verdict_per_row"]),
    "fab.estimate": (["rigcad/fab/estimate.py"], ["tests/fab/test_estimate.py"]),
    "basis.sh": (["rigcad/basis/sh.py"], ["tests/basis/test_sh.py"]),
    # the one Monte Carlo (rigcad.check.montecarlo) and the rank correlations the tolerance report adds
    # (not the tests that start a process pool or a dask cluster, as tolerance.limits; their claim,
    # the same bits on every engine, compares two runs of the same mutant and cannot kill one)
    # (tests/check/test_montecarlo.py: its parts one at a time, seconds)
    "montecarlo": (["rigcad/check/montecarlo.py", "rigcad/tolerance/montecarlo.py"],
                   ["tests/check/test_montecarlo.py"] + [f"tests/tolerance/test_tolerance.py::{t}" for t in (
                       "test_monte_carlo_is_not_vacuous", "test_monte_carlo_spots_match_an_independent_retrace",
                       "test_a_sample_does_not_depend_on_the_run_size", "test_limit_search_at_its_two_ends",
                       "test_scheduler_without_dask_says_what_to_install")]),
    "optics.small": (
        ["rigcad/optics/paraboloid.py", "rigcad/optics/thin_lens.py", "rigcad/optics/misalignment.py"],
        ["tests/optics/test_paraboloid.py", "tests/optics/test_design.py"],
    ),
    # poses, the stand-in solids and the design's incidence map, against their own unit tests (closed
    # forms, a few seconds): the ray checks that also use them take minutes per mutant
    "optics.frames": (["rigcad/optics/frames.py", "rigcad/optics/solids.py", "rigcad/optics/incidence.py"],
                      ["tests/optics/test_frames.py", "tests/optics/test_solids.py", "tests/optics/test_incidence.py"]),
    "optics.trace2d": (["rigcad/optics/trace2d.py"], ["tests/optics/test_trace2d.py"]),
    "optics.splitter": (["rigcad/optics/splitter.py"], ["tests/optics/test_splitter.py"]),
    "fab.staircase": (["rigcad/fab/staircase.py"], ["tests/fab/test_staircase.py"]),
    # the meridians' own tests only (closed forms, foot points: seconds). The mirror mesh's tests
    # (tests/export/test_mirror_mesh.py) also measure them against the exact parabola and dome, but
    # build four meshes per run: with them a mutant of the foot-point solver took 30-100 s here and
    # the group would have needed well over an hour
    "optics.surfaces": (["rigcad/optics/surfaces.py"], ["tests/optics/test_surfaces.py"]),
    "basis.gram": (["rigcad/basis/gram.py"], ["tests/basis/test_gram.py"]),
    "basis.zonal": (["rigcad/basis/zonal.py"], ["tests/basis/test_zonal.py"]),
    "optics.design": (["rigcad/optics/design.py"], ["tests/optics/test_design.py"]),
    # small runs of the Table 3.1 rig (500 rays; analytic, and smooth at a coarse tessellation) and
    # readings of hand-built traces (test_raycheck_parts.py, seconds); test_raycheck.py keeps its
    # claims (every shipped profile passes at full size, the CLI, the same bytes from two interpreters)
    "check.raycheck": (["rigcad/check/raycheck.py"], ["tests/check/test_raycheck_parts.py"]),
    # test_bom.py's hand-built inputs and test_manual's tests on the Table 3.1 rig that need no fab run;
    # test_manual.py's others keep their claims (the pins from a real split, the manual's files and
    # their determinism, the CLI's refusal) but cost ~20 s a mutant (the fab stage, the pictures)
    "manual.bom": (["rigcad/manual/bom.py"],
                   ["tests/manual/test_bom.py"] + [f"tests/manual/test_manual.py::{t}" for t in (
                       "test_paint_volumes_follow_the_coating_stack", "test_paint_margin_is_the_profiles",
                       "test_revolved_area_matches_the_paraboloids_closed_form",
                       "test_bolts_are_found_in_the_recipes_and_sized_from_the_grip",
                       "test_the_tower_hardware_is_the_towers_and_follows_the_mounting_threads")]),
    "optics.dome": (["rigcad/optics/dome.py"], ["tests/optics/test_dome.py"]),
    "optics.focus": (["rigcad/optics/focus.py"], ["tests/optics/test_focus.py"]),
    # tubes and boxes built here (test_split_parts.py, seconds) and the rounding-tie test; the Table 3.1
    # dome and plate splits (test_split.py, test_split_form3.py) keep their claims (the real parts'
    # pieces, pins off the mirror, the beam slots avoided) but cost ~30 s a mutant
    # the seating's maths and refusals on hand-made reports (seconds); the e2e test of three simulated
    # layings keeps its claim (the planted spread measured) but costs ~2 min a mutant
    "calibrate.seating": (["rigcad/calibrate/seating.py"],
                          [f"tests/calibrate/test_seating.py::{t}" for t in (
                              "test_the_spread_is_the_pooled_variance_about_each_labels_mean",
                              "test_the_fits_standard_errors_are_reported_not_taken_out",
                              "test_the_interval_covers_the_true_spread_95_times_in_100",
                              "test_the_verdict_compares_the_profiles_seating",
                              "test_runs_that_cannot_measure_it_are_refused_naming_the_file",
                              "test_a_rig_that_moved_between_the_calibrations_is_refused",
                              "test_a_tilt_that_moved_is_named_in_degrees",
                              "test_the_command_refuses_in_one_line_and_writes_nothing",
                              "test_the_command_writes_the_measurement")]),
    "fab.split": (["rigcad/fab/split.py"],
                  ["tests/fab/test_split_parts.py",
                   "tests/fab/test_split.py::test_pin_points_tied_to_rounding_are_chosen_in_their_order_on_every_cpu"]),
}

# mutmut 3.8 stops a mutant after 2 x this x (its tests' clean time + 5 s) of CPU, a timeout (its
# default 15). The clean run that mutmut times compiles the analytic tracer's numba kernels (~23 s,
# cached on disk for the mutants after it): tolerance.limits's tests then take ~25 s clean and ~3 s
# a mutant, so 15x would wait ~15 min of CPU on each of the 29 mutants that hang the limit search's
# bisection; 1x still waits ~20 times a mutant's own run. fab.split's mutants of _mirror_region's
# sampling loop hang it (~8 s of tests clean: 15x waits 6.5 min each); 3x waits 80 s, ~10 times a
# surviving mutant's whole test file.
TIMEOUT_MULTIPLIER = {"tolerance.limits": 1.0, "fab.split": 3.0}

# folders the tests read, copied into each group's tree and into mutmut's mutants/ beside the code
DATA = ["profiles", "bench/results"]

# mutmut's exit codes (mutmut.stats.status_by_exit_code), folded into the four figures reported
KILLED = {1, 3}
TIMEOUT = {36, -24, 24, 152, 255}
SURVIVED = {0}
NO_TESTS = {5, 33}


def _setup_cfg(modules: list[str], tests: list[str], multiplier: float = 15.0) -> str:
    """mutmut's configuration for one group (mutmut reads setup.cfg when pyproject.toml has no
    [tool.mutmut]). The tests run as in `make test`, less the slow and stress marks."""
    lines = ["[mutmut]", "source_paths = rigcad", "only_mutate ="]
    lines += [f"    {m}" for m in modules]
    lines += ["pytest_add_cli_args_test_selection ="] + [f"    {t}" for t in tests]
    # data the tests read beside the code: the shipped profiles and the recorded bench figures
    # (test_estimate compares with PrusaSlicer's figures in bench/results/fab_estimates.json)
    lines += ["also_copy ="] + [f"    {d}" for d in DATA]
    lines += ["pytest_add_cli_args =", "    -p", "    no:cacheprovider", "    -m",
              "    not slow and not stress", "    -x"]
    # a mutant that makes its tests `multiplier` times slower than the clean run is a timeout
    # (TIMEOUT_MULTIPLIER); the constant covers the fixtures' import and build time
    lines += [f"timeout_multiplier = {multiplier}", "timeout_constant = 5.0", ""]
    return "\n".join(lines)


def prepare(group: str) -> Path:
    modules, tests = GROUPS[group]
    work = ROOT / "build" / "mutate" / group
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    # the committed tree (HEAD), not the working files: a result names the commit it measured, and
    # an edit in progress cannot leak into a run
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", "HEAD", "rigcad", "tests", "pyproject.toml", *DATA],
                             capture_output=True, check=True).stdout
    subprocess.run(["tar", "-x", "-C", str(work)], input=archive, check=True)
    (work / "commit.txt").write_text(_head() + "\n")
    (work / "setup.cfg").write_text(_setup_cfg(modules, tests, TIMEOUT_MULTIPLIER.get(group, 15.0)))
    return work


def run(group: str, max_children: int) -> dict:
    work = prepare(group)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    # tests that start a Python subprocess import the mutated tree too. The folder must exist before
    # mutmut starts: Python caches a missing sys.path entry as dead for the whole process, and the
    # tests would then import the installed (unmutated) rigcad and every mutant would survive.
    (work / "mutants").mkdir()
    env["PYTHONPATH"] = str(work / "mutants")
    t0 = time.monotonic()
    log = work / "mutmut.log"
    with log.open("w") as out:
        res = subprocess.run([sys.executable, "-m", "mutmut", "run", "--max-children", str(max_children)],
                             cwd=work, env=env, stdout=out, stderr=subprocess.STDOUT)
    seconds = time.monotonic() - t0
    (work / "seconds.txt").write_text(f"{seconds:.1f}\n")
    if res.returncode != 0:
        raise SystemExit(f"mutmut failed on {group} (exit {res.returncode}); see {log}")
    return collect(group, work, seconds)


def resume(group: str, max_children: int) -> dict:
    """Go on with a run of ``group`` that was stopped (build/mutate/<group>/ kept): mutmut lets the
    results it has stand and tests the mutants left unchecked. The modules must be unchanged."""
    work = ROOT / "build" / "mutate" / group
    _check_unchanged(group, work)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(work / "mutants")
    t0 = time.monotonic()
    with (work / "mutmut.log").open("a") as out:
        res = subprocess.run([sys.executable, "-m", "mutmut", "run", "--max-children", str(max_children)],
                             cwd=work, env=env, stdout=out, stderr=subprocess.STDOUT)
    if res.returncode != 0:
        raise SystemExit(f"mutmut failed on {group} (exit {res.returncode}); see {work / 'mutmut.log'}")
    done = work / "seconds.txt"
    # a stopped run wrote no time of its own: the figure is then this part's only
    total = (float(done.read_text()) if done.exists() else 0.0) + time.monotonic() - t0
    done.write_text(f"{total:.1f}\n")
    return collect(group, work, total)


def _check_unchanged(group: str, work: Path) -> None:
    for module in GROUPS[group][0]:
        old = subprocess.run(["git", "-C", str(ROOT), "show", f"{_commit_of(work)}:{module}"], capture_output=True,
                             text=True).stdout
        if old != (ROOT / module).read_text():
            raise SystemExit(f"{module} changed since {group}'s run: run the group again")


def retest_survivors(group: str, max_children: int) -> dict:
    """Test again, against the committed tests (HEAD), only the mutants of ``group`` that survived
    its last run (kept in build/mutate/<group>/): how the tests added for them are checked without
    re-running every mutant. The modules must be unchanged since that run. Each survivor meets
    every test of the files that reach its function (see _widen_stats). Mutants a stopped run left
    unchecked are tested too."""
    work = ROOT / "build" / "mutate" / group
    modules, tests = GROUPS[group]
    names = []
    for module in modules:
        meta = json.loads((work / "mutants" / (module + ".meta")).read_text())
        # "no tests" too: new tests may reach a function none reached before (mutmut collects the
        # coverage of the new tests before it runs the mutants); and those a stopped run left unchecked
        names += [k for k, v in meta["exit_code_by_key"].items() if v in SURVIVED or v in NO_TESTS or v is None]
    _check_unchanged(group, work)
    _widen_stats(work)
    head = _head()  # the tests' commit, named before a commit made during the run can move HEAD
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", head, "tests"], capture_output=True,
                             check=True).stdout
    for dest in (work, work / "mutants"):
        shutil.rmtree(dest / "tests")
        subprocess.run(["tar", "-x", "-C", str(dest)], input=archive, check=True)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(work / "mutants")
    t0 = time.monotonic()
    with (work / "mutmut-retest.log").open("w") as out:
        subprocess.run([sys.executable, "-m", "mutmut", "run", "--max-children", str(max_children), *names],
                       cwd=work, env=env, stdout=out, stderr=subprocess.STDOUT)
    (work / "commit.txt").write_text(f"{_commit_of(work)}, survivors retested with the tests of {head}\n")
    done = work / "seconds.txt"
    total = (float(done.read_text()) if done.exists() else 0.0) + time.monotonic() - t0
    return collect(group, work, total)


def _widen_stats(work: Path) -> None:
    """Give each function every test of the test files its tests are in. mutmut gives a function
    the tests during which it ran: one run by a module-scoped fixture (a rig, a design, a mesh
    built once per file) belongs to the first test of the file alone, and its mutants would meet
    no other test. The retest then runs them against the whole file (``-x`` stops at the first
    failure, so a killed mutant costs little more)."""
    path = work / "mutants" / "mutmut-stats.json"
    stats = json.loads(path.read_text())
    by_file: dict[str, list[str]] = {}
    for test in stats["duration_by_test"]:
        by_file.setdefault(test.split("::")[0], []).append(test)
    tests_of = stats["tests_by_mangled_function_name"]
    for function, tests in tests_of.items():
        files = {t.split("::")[0] for t in tests}
        tests_of[function] = sorted({*tests, *(t for f in files for t in by_file.get(f, []))})
    path.write_text(json.dumps(stats))


def _commit_of(work: Path) -> str:
    return (work / "commit.txt").read_text().split()[0].rstrip(",")


def collect(group: str, work: Path, seconds: float | None) -> dict:
    modules, tests = GROUPS[group]
    explained = tomllib.loads(EXPLAINED.read_text()) if EXPLAINED.exists() else {}
    per_module = {}
    survivors = []
    for module in modules:
        meta = json.loads((work / "mutants" / (module + ".meta")).read_text())
        codes = meta["exit_code_by_key"]
        counts = {"killed": 0, "survived": 0, "timeout": 0, "no_tests": 0, "not_checked": 0, "other": 0}
        for name, code in codes.items():
            if code in KILLED:
                counts["killed"] += 1
            elif code in TIMEOUT:
                counts["timeout"] += 1
            elif code in SURVIVED or code in NO_TESTS:
                counts["survived" if code in SURVIVED else "no_tests"] += 1
                # mutation.md lists unexplained no-test mutants by number only: no diff (one mutmut
                # process each, seconds apiece on a loaded machine, hundreds in a group no test reaches)
                diff = "" if code in NO_TESTS and name not in explained else subprocess.run(
                    [sys.executable, "-m", "mutmut", "show", name], cwd=work, capture_output=True, text=True).stdout
                survivors.append({"module": module, "mutant": name,
                                  "status": "survived" if code in SURVIVED else "no tests", "diff": diff})
            elif code is None:
                counts["not_checked"] += 1
            else:
                counts["other"] += 1
        tried = sum(counts.values()) - counts["not_checked"]
        caught = counts["killed"] + counts["timeout"]
        per_module[module] = {
            **counts, "total": len(codes),
            "score": round(caught / tried, 4) if tried else None,
            "tests": tests, "group": group, "group_seconds": None if seconds is None else round(seconds, 1), "commit": (work / "commit.txt").read_text().strip(),
            "run_utc": datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        }
    return {"modules": per_module, "survivors": survivors}


def write(results: dict) -> None:
    RESULTS.mkdir(parents=True, exist_ok=True)
    jpath = RESULTS / "mutation.json"
    old = json.loads(jpath.read_text()) if jpath.exists() else {"modules": {}, "survivors": []}
    rerun = set(results["modules"])
    # entries of modules no group mutates any more (removed or regrouped) are dropped
    live = {m for mods, _ in GROUPS.values() for m in mods}
    modules = {k: v for k, v in {**old["modules"], **results["modules"]}.items() if k in live}
    survivors = [s for s in old["survivors"] if s["module"] not in rerun and s["module"] in live] + results["survivors"]
    survivors.sort(key=lambda s: (s["module"], s["mutant"]))
    killed = sum(m["killed"] + m["timeout"] for m in modules.values())
    tried = sum(m["total"] - m["not_checked"] for m in modules.values())
    doc = {
        "tool": "mutmut " + _version(),
        "score_definition": "(killed + timeout) / mutants tried; survived and no-tests count against",
        "overall_score": round(killed / tried, 4) if tried else None,
        "modules": dict(sorted(modules.items())),
        "survivors": survivors,
    }
    jpath.write_text(json.dumps(doc, indent=1) + "\n")
    (RESULTS / "mutation.md").write_text(_markdown(doc))


def _head() -> str:
    return subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                          text=True, check=True).stdout.strip()


def _version() -> str:
    from importlib.metadata import version

    return version("mutmut")


def _test_files(tests: list[str]) -> str:
    """The test files of a group, with how many of their tests when it names only some."""
    files: dict[str, int] = {}
    for t in tests:
        path, _, node = t.partition("::")
        files[Path(path).name] = files.get(Path(path).name, 0) + (1 if node else 0)
    return ", ".join(f if n == 0 else f"{f} ({n} tests)" for f, n in files.items())


def _markdown(doc: dict) -> str:
    explained = tomllib.loads(EXPLAINED.read_text()) if EXPLAINED.exists() else {}
    out = ["# Mutation testing of the numerical core", "",
           f"Written by `bench/mutate.py` ({doc['tool']}); score = {doc['score_definition']}.", "",
           "| module | tests | killed | timeout | survived | no tests | not checked | score |",
           "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for name, m in doc["modules"].items():
        score = "-" if m["score"] is None else f"{100 * m['score']:.1f} %"
        out.append(f"| {name} | {_test_files(m['tests'])} | {m['killed']} | {m['timeout']} "
                   f"| {m['survived']} | {m['no_tests']} | {m['not_checked']} | {score} |")
    missing = [m for mods, _ in GROUPS.values() for m in mods if m not in doc["modules"]]
    if missing:
        out += ["", "Not run yet (no entry above): " + ", ".join(f"`{m}`" for m in missing) + "."]
    partial = [n for n, m in doc["modules"].items() if m["not_checked"]]
    if partial:
        out += ["", "Stopped before the end (their score counts only the mutants tried): "
                + ", ".join(f"`{n}`" for n in partial) + "."]
    overall = doc["overall_score"]
    out += ["", f"Overall: {'-' if overall is None else f'{100 * overall:.1f} %'} of the mutants tried killed.", "",
            "## Survivors", "",
            "Each is either explained here (an equivalent mutant, or a claim no one makes) or open: a test "
            "that should fail on it is still missing.", ""]
    module = None
    for s in doc["survivors"]:
        if s["module"] != module:  # survivors grouped by module, the open ones counted in its heading
            module = s["module"]
            mine = [x for x in doc["survivors"] if x["module"] == module]
            still_open = sum(x["mutant"] not in explained for x in mine)
            out += [f"### {module}: {len(mine)} survivors, {still_open} open", ""]
            out += _unreached(mine, explained)
        if s["status"] == "no tests" and s["mutant"] not in explained:
            continue  # listed by function above, without a diff each
        reason = explained.get(s["mutant"], {}).get("reason", "OPEN: no test kills it yet")
        out += [f"#### `{s['mutant']}` ({s['status']})", "", f"{reason}", "", "```diff",
                s["diff"].strip(), "```", ""]
    return "\n".join(out)


def _unreached(mine: list[dict], explained: dict) -> list[str]:
    """The module's unexplained "no tests" mutants as one line per function (their numbers), not a diff
    each: no test of the group calls that function at all, one missing test per function."""
    by_function: dict[str, list[str]] = {}
    for x in mine:
        if x["status"] == "no tests" and x["mutant"] not in explained:
            name, _, number = x["mutant"].rpartition("__mutmut_")
            last = name.rsplit(".", 1)[-1]  # x_function, or x\u01c1Class\u01c1method
            function = (last[2:] if last.startswith("x_") else last[1:]).replace("\u01c1", ".").strip(".")
            by_function.setdefault(function, []).append(number)
    if not by_function:
        return []
    lines = ["OPEN, no test of the group reaches these functions (mutants by number; `mutmut show` in "
             "build/mutate/<group>/ gives each diff):", ""]
    for function, numbers in by_function.items():
        numbers = sorted(numbers, key=int)
        every = numbers == [str(i) for i in range(1, len(numbers) + 1)]  # no test reaches the function
        lines.append(f"- `{function}`: {len(numbers)} ({'all its mutants' if every else ', '.join(numbers)})")
    return lines + [""]


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("groups", nargs="*", help="groups to run (default: all, smallest first)")
    p.add_argument("--max-children", type=int, default=1, help="mutants tested at once (default 1)")
    p.add_argument("--list", action="store_true", help="name the groups and their modules, then stop")
    p.add_argument("--retest-survivors", action="store_true",
                   help="test the survivors of the groups' last runs again with the committed tests")
    p.add_argument("--resume", action="store_true",
                   help="go on with the groups' stopped runs (build/mutate/<group>/), testing only the mutants left")
    p.add_argument("--collect-only", action="store_true",
                   help="re-read the results of groups already run in build/mutate/ (no mutmut run)")
    args = p.parse_args()
    if args.list:
        for g, (mods, tests) in GROUPS.items():
            print(f"{g}: {' '.join(mods)}  <-  {' '.join(tests)}")
        return
    unknown = [g for g in args.groups if g not in GROUPS]
    if unknown:
        raise SystemExit(f"unknown group(s) {unknown}; valid: {', '.join(GROUPS)}")
    for group in args.groups or list(GROUPS):
        if args.retest_survivors:
            print(f"retesting the survivors of {group} ...", flush=True)
            res = retest_survivors(group, args.max_children)
        elif args.resume:
            print(f"resuming {group} ...", flush=True)
            res = resume(group, args.max_children)
        elif args.collect_only:
            work = ROOT / "build" / "mutate" / group
            done = work / "seconds.txt"  # absent when the run was stopped: its results are partial
            res = collect(group, work, float(done.read_text()) if done.exists() else None)
        else:
            print(f"mutating {group} ...", flush=True)
            res = run(group, args.max_children)
        write(res)
        for mod, m in res["modules"].items():
            print(f"  {mod}: killed {m['killed']}, timeout {m['timeout']}, survived {m['survived']}, "
                  f"no tests {m['no_tests']}, score {m['score']}", flush=True)


if __name__ == "__main__":
    main()
