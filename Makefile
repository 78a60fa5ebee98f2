# rigcad: `make stl` runs the main job on the default profile, `make test` the tests.
# Both create the virtual environment (.venv) they need from pyproject.toml + requirements.lock.

PYTHON ?= python3.11
VENV := .venv
PY := $(VENV)/bin/python
PROFILE ?= achutha2006
PRINTER ?= prusa_mk3s
# Debian packages the project runs (the G-code slicer; the browser the 3D view is tested in, driven by
# playwright as /usr/bin/chromium); installed when missing, never assumed.
SYSTEM_TOOLS := prusa-slicer chromium
SUDO := $(shell [ "$$(id -u)" -eq 0 ] || echo sudo)
EXPORTS ?= exports

.PHONY: all stl design docs check gcode view manual tools test test-all test-slow bench stress mutate clean distclean help

all: stl

help:
	@echo "make stl      - design and build the default profile ($(PROFILE)) into $(EXPORTS)/$(PROFILE)/"
	@echo "make check    - 3D ray check of $(PROFILE) through the exported meshes (after make stl)"
	@echo "make gcode    - print files + G-code (PrusaSlicer) for PRINTER=$(PRINTER) -> $(EXPORTS)/$(PROFILE)/fab/$(PRINTER)/"
	@echo "make view     - the assembled rig in 3D: $(EXPORTS)/$(PROFILE)/view/rig.html (one self-contained file)"
	@echo "make manual   - assembly and calibration manual for PRINTER=$(PRINTER) -> $(EXPORTS)/$(PROFILE)/manual/$(PRINTER)/"
	@echo "make test     - the fast test suite (default run, < 10 min)"
	@echo "make test-slow - only the slow tests (the whole rig through PrusaSlicer)"
	@echo "make test-all - every test, slow ones included"
	@echo "make stress   - numerical stress suite: 500 random profiles (hypothesis)"
	@echo "make bench    - run time against error for each accuracy knob -> bench/results/*.json, *.png"
	@echo "make mutate   - mutation testing (mutmut) of the numerical core, each module against its own tests"
	@echo "               -> bench/results/mutation.json, mutation.md (MUTATE='group ...' runs some; --list names them)"
	@echo "make clean    - remove $(EXPORTS)/ ; make distclean also removes $(VENV)/"

$(VENV)/.installed: pyproject.toml requirements.lock
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -c requirements.lock -e ".[cad,dev,dask]"
	touch $@

venv: $(VENV)/.installed

tools:
	@missing=""; for t in $(SYSTEM_TOOLS); do command -v $$t >/dev/null || missing="$$missing $$t"; done; \
	if [ -n "$$missing" ]; then \
	  echo "installing$$missing (apt-get)"; \
	  $(SUDO) apt-get update -qq && DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends $$missing; \
	fi

stl: $(VENV)/.installed
	$(VENV)/bin/rigcad stl $(PROFILE) --exports $(EXPORTS)

design: stl

check: stl
	$(VENV)/bin/rigcad check $(PROFILE) --exports $(EXPORTS)

view: $(VENV)/.installed
	$(VENV)/bin/rigcad view $(PROFILE) --exports $(EXPORTS)

manual: $(VENV)/.installed stl
	$(VENV)/bin/rigcad manual $(PROFILE) --printer $(PRINTER) --exports $(EXPORTS)

docs: check view
	cp $(EXPORTS)/achutha2006/view/rig.png docs/rig.png
	cp $(EXPORTS)/achutha2006/rays.png docs/rays.png
	cp $(EXPORTS)/achutha2006/check/spot.png $(EXPORTS)/achutha2006/check/theta_map.png docs/
	mkdir -p docs/parts && cp $(EXPORTS)/achutha2006/renders/*.png docs/parts/

test: $(VENV)/.installed tools
	$(PY) -m pytest -q -n auto --dist loadfile -m "not slow and not stress"

test-slow: $(VENV)/.installed tools
	$(PY) -m pytest -q -m slow

gcode: $(VENV)/.installed tools
	$(VENV)/bin/rigcad fab $(PROFILE) --printer $(PRINTER) --exports $(EXPORTS) --gcode

bench: $(VENV)/.installed stl
	$(PY) bench/dome.py
	$(PY) bench/mirror_mesh.py
	$(PY) bench/raycheck.py --exports $(EXPORTS)
	$(PY) bench/tolerance.py
	$(PY) bench/fab_stages.py
	$(PY) bench/tessellation.py
	$(PY) bench/ray_count.py --exports $(EXPORTS)
	$(PY) bench/float32.py --exports $(EXPORTS)
	$(PY) bench/make_stl.py
	$(PY) bench/basis.py
	$(PY) bench/optimize.py

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
