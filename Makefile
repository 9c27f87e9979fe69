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
	$(BIN)/python -m pip install --quiet -e ".[test,slurm]"
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

clean-results:
	rm -rf results/*.nc results/tables results/figures results/solutions results/meshes results/errors results/benchmarks logs
