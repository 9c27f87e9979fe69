# Two entry points on a fresh clone: `make reproduce` (the paper) and `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
JOBS   ?= 2

.PHONY: reproduce test install bench clean-results

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[report,workflow,slurm,test]"
	touch $(STAMP)

install: $(STAMP)

reproduce: $(STAMP)
	$(BIN)/snakemake -j$(JOBS) --quiet rules

test: $(STAMP)
	$(BIN)/python -m pytest -q

bench: $(STAMP)
	$(BIN)/python benchmarks/assembly.py
	$(BIN)/python benchmarks/contact.py
	$(BIN)/python benchmarks/sweep.py
	$(BIN)/python benchmarks/meshing.py
	$(BIN)/python benchmarks/assembly_k2.py

clean-results:
	rm -rf results/*.nc results/tables results/figures results/solutions results/meshes results/errors results/benchmarks logs

# The SLURM profile on a real one-node SLURM cluster set up on this host (Debian, as root: installs
# slurm-wlm, slurmdbd, munge, mariadb-server; starts and then stops its own daemons). Not part of
# `make test`. MODE=no-accounting: the same without slurmdbd (job status through squeue).
MODE ?= accounting
.PHONY: cluster-test
cluster-test: $(STAMP)
	$(BIN)/python workflow/cluster/cluster_test.py --mode $(MODE)
