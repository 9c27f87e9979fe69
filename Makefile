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

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[report,workflow,slurm,test]"
	touch $(STAMP)

install: $(STAMP)

# The documentation site (docs/, Sphinx + MyST + furo, sphinx-gallery): docs/_build/html. Its packages
# (the `docs` extra) get their own stamp, so `make test` does not install them. -W: a warning fails.
# Generated at build time: docs/_generated (scene keys, API pages, paper and verification tables and
# figures) and docs/gallery (the executed examples). CI runs `make docs` (.ci/run).
DOCS_STAMP := $(VENV)/.installed-docs
SPHINXOPTS ?= -W --keep-going -q

$(DOCS_STAMP): pyproject.toml | $(STAMP)
	$(BIN)/python -m pip install --quiet -e ".[docs]"
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

test: $(STAMP) $(NUMBA_STAMP)
	$(BIN)/python -m pytest -q

bench: $(STAMP) $(NUMBA_STAMP)
	$(BIN)/python benchmarks/assembly.py
	$(BIN)/python benchmarks/contact.py
	$(BIN)/python benchmarks/sweep.py
	$(BIN)/python benchmarks/meshing.py
	$(BIN)/python benchmarks/assembly_k2.py

# vemkit k = 1 against scikit-fem and GetFEM P1 on the same triangle meshes (benchmarks/peers.py,
# README "Side by side with GetFEM and scikit-fem"). GetFEM: python3-getfem for /usr/bin/python3,
# installed here when missing and root, else skipped with one line. PEERS_ARGS=--quick: a smoke test.
PEERS_ARGS ?=
getfem:
	@bash benchmarks/peers/install_getfem.sh

peers: $(STAMP) $(NUMBA_STAMP) getfem
	$(BIN)/python benchmarks/peers.py $(PEERS_ARGS)

clean-results:
	rm -rf results/*.nc results/tables results/figures results/solutions results/meshes results/errors results/benchmarks logs

# The SLURM profile on a real one-node SLURM cluster set up on this host (Debian, as root: installs
# slurm-wlm, slurmdbd, munge, mariadb-server; starts and then stops its own daemons). Not part of
# `make test`. MODE=no-accounting: the same without slurmdbd (job status through squeue).
MODE ?= accounting
.PHONY: cluster-test
cluster-test: $(STAMP) $(NUMBA_STAMP)
	$(BIN)/python workflow/cluster/cluster_test.py --mode $(MODE)
