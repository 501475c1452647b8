# beamfx: Debian 12 + apt DOLFINx 0.5.2. `make run` / `make test` install everything first.
SHELL := /bin/bash
VENV  := .venv
PY    := $(VENV)/bin/python
MPIRUN := mpirun --allow-run-as-root --oversubscribe -n 2

export SETUPTOOLS_USE_DISTUTILS := stdlib
export VTK_DEFAULT_OPENGL_WINDOW := vtkEGLRenderWindow
export OMPI_MCA_rmaps_base_oversubscribe := 1
export PYTHONUNBUFFERED := 1

.PHONY: install run test test-slow bench bench-peers bench-solid-scaling bench-frame-scaling lint clean

install:
	bash scripts/install.sh

run: install
	$(VENV)/bin/beamfx run

# ParaView's pvpython runs on its own after the rest: on a loaded machine it sometimes aborts
# while creating its X window (tests/scenes/test_paraview.py retries that start-up failure)
# BEAMFX_JIT_CFLAGS: the suite compiles its kernels with -O0 into a cache folder of their own
# (beamfx.solvers.forms): compiling is most of a cold run, and -O0 compiles about 4x faster
test: export BEAMFX_JIT_CFLAGS := -O0 -g0
test: install
	$(PY) -m pytest -n 2 -m "not slow and not mpi and not paraview" tests
	$(PY) -m pytest -p no:cacheprovider -m "paraview and not slow" tests
	$(MPIRUN) $(PY) -m pytest -p no:cacheprovider -m "mpi and not slow" tests/; rc=$$?; \
	  if [ $$rc -eq 5 ]; then echo "(no MPI tests collected)"; rc=0; fi; exit $$rc

test-slow: export BEAMFX_JIT_CFLAGS := -O0 -g0
test-slow: install
	$(PY) -m pytest -m slow tests

bench: install
	$(VENV)/bin/beamfx bench --report docs/validation

# the 231k-unknown solid on 1 and 2 ranks (about 2 min on a quiet 2-core machine)
bench-solid-scaling: install
	$(PY) -m beamfx.bench.solid_scaling run docs/validation
	$(MPIRUN) $(PY) -m beamfx.bench.solid_scaling run docs/validation
	$(PY) -m beamfx.bench.solid_scaling report docs/validation

# BCC lattice frames of 10³ to 10⁶ unknowns on 1 and 2 ranks, MUMPS and CG + BoomerAMG (long:
# each 10⁶ row, in its own process, takes minutes and up to 12 GB; not part of `make test`)
FRAME_CELLS := 2 5 10
bench-frame-scaling: install
	$(PY) -m beamfx.bench.frame_scaling run docs/validation $(FRAME_CELLS)
	$(MPIRUN) $(PY) -m beamfx.bench.frame_scaling run docs/validation $(FRAME_CELLS)
	$(PY) -m beamfx.bench.frame_scaling run docs/validation 22 --linear iterative --kinematics linear
	$(PY) -m beamfx.bench.frame_scaling run docs/validation 22 --linear iterative --kinematics finite
	$(MPIRUN) $(PY) -m beamfx.bench.frame_scaling run docs/validation 22 --linear iterative --kinematics linear
	$(MPIRUN) $(PY) -m beamfx.bench.frame_scaling run docs/validation 22 --linear iterative --kinematics finite
	$(PY) -m beamfx.bench.frame_scaling report docs/validation

# beamfx beside Exudyn, PyElastica, CalculiX, OpenSeesPy and pyBModes (peer venv PEERS_VENV,
# default .venv-peers; not part of `make test`); report in docs/validation/peers*.md
PEERS := build/peers
PEERS_VENV ?= .venv-peers
PEERS_PY := $(PEERS_VENV)/bin/python
bench-peers: install
	PEERS_VENV=$(PEERS_VENV) bash scripts/install_peers.sh
	$(PY) -m beamfx.bench.peers export $(PEERS)
	$(PEERS_PY) peers/exudyn_cases.py $(PEERS)
	$(PEERS_PY) peers/elastica_cases.py $(PEERS)
	$(PEERS_PY) peers/calculix_cases.py $(PEERS)
	$(PY) -m beamfx.bench.peers $(PEERS) docs/validation
	$(PY) -m beamfx.bench.frame_peers export $(PEERS)
	$(PEERS_PY) peers/opensees_frame.py $(PEERS)
	$(PY) -m beamfx.bench.frame_peers $(PEERS) docs/validation
	$(PY) -m beamfx.bench.star_dome_peers export $(PEERS)
	$(PEERS_PY) peers/opensees_star_dome.py $(PEERS)
	$(PY) -m beamfx.bench.star_dome_peers $(PEERS) docs/validation
	$(PEERS_PY) peers/pybmodes_blade.py $(PEERS)

lint: install
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .

clean:
	rm -rf $(VENV) build dist *.egg-info .pytest_cache .ruff_cache
	find . -name __pycache__ -type d -prune -not -path './.git/*' -exec rm -rf {} +
