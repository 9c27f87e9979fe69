# Two entry points on a fresh clone: `make reproduce` (the paper) and `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
JOBS   ?= 2

.PHONY: reproduce test install bench peers getfem clean-results clean-numba-cache docs linkcheck clean-docs

# Numba's on-disk cache (cache=True) keys a kernel on its own source file only: a kernel that inlines
# one from another module keeps the old compiled code after that module changes. So the compiled
# kernels are dropped whenever any vemkit source is newer than the last drop (recompiled on first use).
NUMBA_STAMP := $(VENV)/.numba-cache-sources
VEMKIT_SOURCES := $(shell find vemkit -name '*.py' 2>/dev/null)

$(NUMBA_STAMP): $(VEMKIT_SOURCES) | $(STAMP)
	find vemkit -path '*__pycache__*' \( -name '*.nbi' -o -name '*.nbc' \) -delete
	touch $(NUMBA_STAMP)

clean-numba-cache:
	find vemkit -path '*__pycache__*' \( -name '*.nbi' -o -name '*.nbc' \) -delete
	rm -f $(NUMBA_STAMP)

# The tested versions: requirements.lock pins every package the extras below pull in (constraints:
# a dependency added to pyproject.toml and not yet in the lock still installs, unpinned). `make lock`
# refreshes the lock (see the lock block at the end).
EXTRAS := report,workflow,slurm,test,lint,mpi
LOCK   := requirements.lock

# The mpi extra (solver.linear: petsc) builds petsc and mpi4py from source against Debian's MPICH and
# OpenBLAS/LAPACK, which tools/install_mpi_libs.sh installs when missing (as root; else one line says
# what to install). PETSc without Fortran, C++ or CUDA (no gfortran; an nvcc on PATH is not used).
# mpi4py from source too: its wheel carries another MPI than Debian's libmpich. The first build
# takes ~20 min on 2 cores; pip caches the wheels (~/.cache/pip): later installs take seconds.
# petsc is installed first: petsc4py's build environment needs it, and so finds its cached wheel.
export MPICC ?= mpicc
export PETSC_CONFIGURE_OPTIONS ?= --with-fc=0 --with-cxx=0 --with-x=0 --with-cuda=0

$(STAMP): pyproject.toml $(LOCK)
	@bash tools/install_mpi_libs.sh
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -c $(LOCK) petsc
	$(BIN)/python -m pip install --quiet --no-binary mpi4py -c $(LOCK) -e ".[$(EXTRAS)]"
	touch $(STAMP)

install: $(STAMP)

# gmsh (a dependency: mesh family tet, kind delaunay): its wheel's library links X11/OpenGL client
# libraries; tools/install_gmsh_libs.sh installs the Debian packages holding them when gmsh cannot
# load them and this runs as root (on this project's image they are all there: one line, no change).
GMSH_STAMP := $(VENV)/.gmsh-libs
$(GMSH_STAMP): $(STAMP)
	@bash tools/install_gmsh_libs.sh $(BIN)/python
	@touch $(GMSH_STAMP)
install: $(GMSH_STAMP)
test: $(GMSH_STAMP)
reproduce: $(GMSH_STAMP)

# The documentation site (docs/, Sphinx + MyST + furo, sphinx-gallery): docs/_build/html. Its packages
# (the `docs` extra) get their own stamp, so `make test` does not install them. -W: a warning fails.
# Generated at build time: docs/_generated (scene keys, API pages, paper and verification tables and
# figures) and docs/gallery (the executed examples). CI runs `make docs` (.ci/run).
DOCS_STAMP := $(VENV)/.installed-docs
SPHINXOPTS ?= -W --keep-going -q

$(DOCS_STAMP): pyproject.toml $(LOCK) | $(STAMP)
	$(BIN)/python -m pip install --quiet -c $(LOCK) -e ".[docs]"
	touch $(DOCS_STAMP)

docs: $(DOCS_STAMP) $(NUMBA_STAMP)
	MPLBACKEND=Agg $(BIN)/sphinx-build -b html $(SPHINXOPTS) docs docs/_build/html

# the site's own links and anchors (external links are not checked: no network here)
linkcheck: $(DOCS_STAMP) $(NUMBA_STAMP)
	MPLBACKEND=Agg $(BIN)/sphinx-build -b linkcheck $(SPHINXOPTS) docs docs/_build/linkcheck

clean-docs:
	rm -rf docs/_build docs/_generated docs/api docs/gallery docs/sg_execution_times.rst

reproduce: $(STAMP) $(NUMBA_STAMP)
	$(BIN)/snakemake -j$(JOBS) --quiet rules

# VEMKIT_REQUIRE_MPI: the MPI tests (tests/mpi_jobs.py) fail instead of skipping without MPI
test: $(STAMP) $(NUMBA_STAMP)
	VEMKIT_REQUIRE_MPI=1 $(BIN)/python -m pytest -q

bench: $(STAMP) $(NUMBA_STAMP)
	$(BIN)/python benchmarks/assembly.py
	$(BIN)/python benchmarks/contact.py
	$(BIN)/python benchmarks/sweep.py
	$(BIN)/python benchmarks/meshing.py
	$(BIN)/python benchmarks/assembly_k2.py
	$(BIN)/python benchmarks/threads.py

# vemkit k = 1 against scikit-fem and GetFEM P1 on the same triangle meshes (benchmarks/peers.py),
# and k = 2 against their P2 at equal error (benchmarks/peers_order2.py; docs/benchmarks/peers.md).
# GetFEM: python3-getfem for /usr/bin/python3, installed here when missing and root, else skipped
# with one line. PEERS_ARGS=--quick: a smoke test (both scripts; PEERS_ORDER2_ARGS: the second's own).
PEERS_ARGS ?=
PEERS_ORDER2_ARGS ?= $(filter --quick,$(PEERS_ARGS))
getfem:
	@bash benchmarks/peers/install_getfem.sh

peers: $(STAMP) $(NUMBA_STAMP) getfem
	$(BIN)/python benchmarks/peers.py $(PEERS_ARGS)
	$(BIN)/python benchmarks/peers_order2.py $(PEERS_ORDER2_ARGS)

clean-results:
	rm -rf results/*.nc results/tables results/figures results/solutions results/meshes results/errors results/benchmarks logs

# The SLURM profile on a real one-node SLURM cluster set up on this host (Debian, as root: installs
# slurm-wlm, slurmdbd, munge, mariadb-server; starts and then stops its own daemons). Not part of
# `make test`. MODE=no-accounting: the same without slurmdbd (job status through squeue); MODE=mpi:
# workflow/cluster/solve_mpi.sbatch on 2 ranks against a serial solve (no slurmdbd).
MODE ?= accounting
.PHONY: cluster-test
cluster-test: $(STAMP) $(NUMBA_STAMP)
	$(BIN)/python workflow/cluster/cluster_test.py --mode $(MODE)

# ---- lint and format (issue 23 item 8) --------------------------------------------------------
# `make lint`: ruff check (rules in pyproject.toml [tool.ruff.lint]), ruff format --check, and mypy
# on the public API (the files in [tool.mypy]); each runs, and lint fails if any of them failed.
# `make format` rewrites the tree: the import order (ruff's isort rules) and then ruff format.
.PHONY: lint format
lint: $(STAMP)
	@status=0; \
	echo "ruff check"; $(BIN)/ruff check --output-format concise . || status=1; \
	echo "ruff format --check"; $(BIN)/ruff format --check --output-format concise . || status=1; \
	echo "mypy (public API)"; $(BIN)/mypy || status=1; \
	exit $$status

format: $(STAMP)
	$(BIN)/ruff check --select I --fix .
	$(BIN)/ruff format .

# ---- lock (issue 23 item 8) -------------------------------------------------------------------
# `make lock`: resolve pyproject.toml's dependencies and extras (the docs extra too) afresh in a throw-away venv (newest
# versions the package index serves within the bounds) and pin them in requirements.lock (pip freeze,
# without vemkit itself). Then `make install` (the lock is newer than the venv's stamp) and `make test`
# before committing the new lock.
LOCK_VENV := $(VENV)-lock
.PHONY: lock
lock:
	rm -rf $(LOCK_VENV)
	$(PYTHON) -m venv $(LOCK_VENV)
	$(LOCK_VENV)/bin/python -m pip install --quiet --upgrade pip
	@bash tools/install_mpi_libs.sh
	$(LOCK_VENV)/bin/python -m pip install --quiet petsc
	$(LOCK_VENV)/bin/python -m pip install --quiet --no-binary mpi4py ".[$(EXTRAS),docs]"
	{ echo "# The tested dependency versions (make lock; make install installs with them as constraints)."; \
	  echo "# $$($(LOCK_VENV)/bin/python -c 'import platform, sys; print(f"Python {platform.python_version()} on {sys.platform}")'), $$(date -u +%Y-%m-%d)"; \
	  $(LOCK_VENV)/bin/python -m pip freeze --exclude vemkit; } > $(LOCK).tmp
	mv $(LOCK).tmp $(LOCK)
	rm -rf $(LOCK_VENV) build
	@echo "$(LOCK): $$(grep -vc '^#' $(LOCK)) packages pinned"

# ---- docs-check (issue 23 item 7: the built site in a real browser) ---------------------------
# Every main page of the built site (DOCS_HTML) opened in headless Chromium (Debian's chromium,
# installed by docs/tools/install_chromium.sh when missing and root, else the browser part is
# skipped with one line), one screenshot per page into DOCS_SHOTS; fails on a page that does not
# load, a missing or undrawn image, a missing stylesheet or script, or an internal link to no file.
DOCS_HTML  ?= docs/_build/html
DOCS_SHOTS ?= docs/_build/screenshots
.PHONY: docs-check chromium
chromium:
	@bash docs/tools/install_chromium.sh

docs-check: docs chromium
	$(PYTHON) docs/tools/docs_check.py $(DOCS_HTML) --out $(DOCS_SHOTS)
