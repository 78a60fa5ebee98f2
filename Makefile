# rigcad: `make stl` runs the main job on the default profile, `make test` the tests.
# Both create the virtual environment (.venv) they need from pyproject.toml + requirements.lock.

PYTHON ?= python3.11
VENV := .venv
PY := $(VENV)/bin/python
PROFILE ?= achutha2006
PRINTER ?= prusa_mk3s
# Debian packages the project runs (the G-code slicer; the browser the 3D view is tested in, driven by
# playwright as /usr/bin/chromium; Node.js and npm for the Khronos glTF validator the tests run on
# rig.glb); installed when missing, never assumed.
SYSTEM_TOOLS := prusa-slicer chromium nodejs npm
# The Khronos glTF validator (npm gltf-validator, pinned), installed into build/node by `make tools`;
# tests/export/validate_gltf.js runs it with Node.js
GLTF_VALIDATOR_VERSION := 2.0.0-dev.3.10
GLTF_VALIDATOR := build/node/node_modules/gltf-validator/package.json
SUDO := $(shell [ "$$(id -u)" -eq 0 ] || echo sudo)
EXPORTS ?= exports
# pytest keeps its assertion-rewritten test modules in __pycache__ only when Python may write
# bytecode; with PYTHONDONTWRITEBYTECODE set (some images set it) each xdist worker rewrites all of
# them on every run: `pytest --collect-only` of make test's tests 18 s without the cache, 10 s with.
unexport PYTHONDONTWRITEBYTECODE

# numpy's huge-page advice off for every command here, as `rigcad` sets it (rigcad.cli.main.process_defaults)
export NUMPY_MADVISE_HUGEPAGE ?= 0

.PHONY: all stl design docs check gcode view manual tools test test-e2e test-all test-slow test-portable bench stress mutate clean distclean help

all: stl

help:
	@echo "make stl      - design and build the default profile ($(PROFILE)) into $(EXPORTS)/$(PROFILE)/"
	@echo "make check    - 3D ray check of $(PROFILE) through the exported meshes (after make stl)"
	@echo "make gcode    - print files + G-code (PrusaSlicer) for PRINTER=$(PRINTER) -> $(EXPORTS)/$(PROFILE)/fab/$(PRINTER)/"
	@echo "make view     - the assembled rig in 3D: $(EXPORTS)/$(PROFILE)/view/rig.html (one self-contained file)"
	@echo "make manual   - assembly and calibration manual for PRINTER=$(PRINTER) -> $(EXPORTS)/$(PROFILE)/manual/$(PRINTER)/"
	@echo "make docs     - run the documented commands on $(PROFILE); every figure and picture of README.md and docs/"
	@echo "make test     - the fast test suite (default run, < 5 min on 2 cores)"
	@echo "make test-e2e - the whole-command and whole-rig runs make test leaves out (CI runs both)"
	@echo "make test-slow - only the slow tests (the whole rig through PrusaSlicer)"
	@echo "make test-all - every test, slow ones included"
	@echo "make test-portable - the numerical tests as other CPUs compute them (BLAS kernels, numpy SIMD off, generic numba)"
	@echo "make stress   - numerical stress suite: 500 random profiles (hypothesis)"
	@echo "make bench    - run time against error for each accuracy knob -> build/bench/; each speed ratio against bench/results/ (REFRESH=1 updates it)"
	@echo "make mutate   - mutation testing (mutmut) of the numerical core, each module against its own tests"
	@echo "               -> bench/results/mutation.json, mutation.md (MUTATE='group ...' runs some; --list names them)"
	@echo "make clean    - remove $(EXPORTS)/ ; make distclean also removes $(VENV)/"

$(VENV)/.installed: pyproject.toml requirements.lock
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -c requirements.lock -e ".[cad,dev,dask,ocp]"
	touch $@

venv: $(VENV)/.installed

tools:
	@missing=""; for t in $(SYSTEM_TOOLS); do command -v $$t >/dev/null || missing="$$missing $$t"; done; \
	if [ -n "$$missing" ]; then \
	  echo "installing$$missing (apt-get)"; \
	  $(SUDO) apt-get update -qq && DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends $$missing; \
	fi
	@grep -qs '"version": "$(GLTF_VALIDATOR_VERSION)"' $(GLTF_VALIDATOR) || \
	  npm install --prefix build/node --no-save --no-audit --no-fund --loglevel=error gltf-validator@$(GLTF_VALIDATOR_VERSION)

stl: $(VENV)/.installed
	$(VENV)/bin/rigcad stl $(PROFILE) --exports $(EXPORTS)

design: stl

check: stl
	$(VENV)/bin/rigcad check $(PROFILE) --exports $(EXPORTS)

view: $(VENV)/.installed
	$(VENV)/bin/rigcad view $(PROFILE) --exports $(EXPORTS)

manual: $(VENV)/.installed stl
	$(VENV)/bin/rigcad manual $(PROFILE) --printer $(PRINTER) --exports $(EXPORTS)

# Every figure and picture README.md and docs/*.md show, from the documented commands run on the
# default profile (docs/figures.md): docs/figures.json, the pictures, the numbers in the pages.
# About 10 minutes on 2 cores; niced, as it shares the machine.
docs: $(VENV)/.installed tools
	nice -n 10 $(PY) docs/figures.py run

# --durations=15: the slowest tests on every run; --timeout (pytest-timeout): a hung test fails after
# 10 min (the slow ones, the whole rig through PrusaSlicer, after an hour) instead of stalling the run
test: $(VENV)/.installed tools
	$(PY) -m pytest -q -n auto --dist loadfile -m "not slow and not stress and not e2e" --durations=15 --timeout=600

# The whole commands and whole-rig runs make test leaves out to stay under 5 min (marked e2e); CI runs them
test-e2e: $(VENV)/.installed tools
	$(PY) -m pytest -q -n auto --dist loadfile -m "e2e and not slow and not stress" --durations=15 --timeout=600

# The numerical tests as other x86-64 CPUs compute them, on this one: OpenBLAS's kernel forced
# (Prescott: SSE3 only; SkylakeX: AVX-512; Haswell: AVX2 + FMA), numpy's SIMD dispatch switched off
# down to its baseline (numpy 2.4 refuses to disable the baseline X86_V2; names this CPU lacks are
# ignored) and numba compiled for a generic x86-64. numba keys its cache by CPU name, and the generic
# mode also keeps its own cache folder, so no machine code built for this CPU is reused there.
# A kernel this CPU cannot run (SIGILL) is skipped with a line saying so.
# The optimiser's tests (a design that must build) run in the combined mode only: they are long.
# tests/calibrate: the decoding's thresholds and the fit; tests/test_docs.py: the figures and the
# pictures' sources against this CPU's run of the documented commands (an AMD EPYC moved the dome's
# largest miss at O in its 2nd digit, and Prescott moves 7 parts' recipe hashes)
PORTABLE_TESTS := tests/optics tests/check tests/fab/test_staircase.py tests/fab/test_split.py \
	tests/fab/test_split_form3.py tests/basis tests/calibrate tests/test_docs.py
NPY_SIMD_OFF := X86_V3 X86_V4 AVX512_ICL AVX512_SPR
PORTABLE_PYTEST = $(PY) -m pytest -q -n 2 --dist loadfile -m "not slow and not stress" $(PORTABLE_TESTS)

test-portable: $(VENV)/.installed
	@echo "== test-portable: OpenBLAS Prescott, numpy SIMD off, numba generic"
	OPENBLAS_CORETYPE=Prescott NPY_DISABLE_CPU_FEATURES="$(NPY_SIMD_OFF)" NUMBA_CPU_NAME=generic \
	  NUMBA_CACHE_DIR=$(CURDIR)/build/numba-generic $(PORTABLE_PYTEST) tests/optimize
	@for k in SkylakeX:avx512f Haswell:avx2; do \
	  core=$${k%%:*}; flag=$${k##*:}; \
	  if grep -qw $$flag /proc/cpuinfo; then \
	    echo "== test-portable: OpenBLAS $$core"; OPENBLAS_CORETYPE=$$core $(PORTABLE_PYTEST) || exit 1; \
	  else echo "== test-portable: OpenBLAS $$core SKIPPED: this CPU lacks $$flag"; fi; \
	done

test-slow: $(VENV)/.installed tools
	$(PY) -m pytest -q -m slow --durations=15 --timeout=3600

gcode: $(VENV)/.installed tools
	$(VENV)/bin/rigcad fab $(PROFILE) --printer $(PRINTER) --exports $(EXPORTS) --gcode

# The benchmarks write into $(BENCH_OUT); bench/compare.py then holds each speed ratio measured within
# one run against the committed figure in bench/results/ (a drop of more than 10 %: a regression, exit 1).
# The committed figures change only when the run says so: `make bench REFRESH=1` copies the results over.
BENCH_OUT ?= build/bench
bench: $(VENV)/.installed stl
	$(PY) bench/dome.py --out $(BENCH_OUT)
	$(PY) bench/mirror_mesh.py --out $(BENCH_OUT)
	$(PY) bench/raycheck.py --exports $(EXPORTS) --out $(BENCH_OUT)
	$(PY) bench/tolerance.py --out $(BENCH_OUT)
	$(PY) bench/fab_stages.py --out $(BENCH_OUT)
	$(PY) bench/tessellation.py --out $(BENCH_OUT)
	$(PY) bench/ray_count.py --exports $(EXPORTS) --out $(BENCH_OUT)
	$(PY) bench/float32.py --exports $(EXPORTS) --out $(BENCH_OUT)
	$(PY) bench/make_stl.py --out $(BENCH_OUT)
	$(PY) bench/basis.py --out $(BENCH_OUT)
	$(PY) bench/optimize.py --out $(BENCH_OUT)
	$(PY) bench/assembly_order.py --out $(BENCH_OUT)
	$(PY) bench/startup.py --out $(BENCH_OUT)
	$(PY) bench/hugepages.py --out $(BENCH_OUT)
	$(PY) bench/commands.py --out $(BENCH_OUT)
	$(PY) bench/compare.py $(BENCH_OUT) $(if $(REFRESH),--refresh)

stress: $(VENV)/.installed
	$(PY) -m pytest -q -m stress --hypothesis-show-statistics

# Long (an hour or more on 2 cores): each group mutates a few modules of the numerical core and runs only
# their own test files, in a copy of the committed tree under build/mutate/. MUTATE picks groups.
MUTATE ?=
mutate: $(VENV)/.installed
	$(PY) bench/mutate.py $(MUTATE)

test-all: $(VENV)/.installed tools
	$(PY) -m pytest -q

clean:
	rm -rf $(EXPORTS)

distclean: clean
	rm -rf $(VENV)
