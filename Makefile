# blastfrac: two-command quick start (`make demo`, `make test`) on a machine with Python 3.11+ and make.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
DEMO   := examples/circular_rock/demo.toml

.PHONY: demo test validate bench gpu-check gpu-pack clean

$(VENV)/.installed: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e .
	touch $@

$(VENV)/.installed-test: $(VENV)/.installed
	$(BIN)/python -m pip install --quiet -e ".[test]"
	touch $@

## demo: create .venv, install, run the default scenario and write its figures to out/demo
demo: $(VENV)/.installed
	$(BIN)/blastfrac run $(DEMO) --out out/demo
	@echo "figures: out/demo/fracture_pattern.png out/demo/displacement_snapshots.png out/demo/gas_pressure.png out/demo/*.png"

## test: install the test extras and run the test suite (no slow tests) on two worker processes
test: $(VENV)/.installed-test
	$(BIN)/python -m pytest -q -n 2

EXAMPLES := examples/circular_rock/scenario.toml examples/single_hole/scenario.toml \
            examples/confined_blast/scenario_P0.toml examples/confined_blast/scenario_P15.toml \
            examples/confined_blast/scenario_P30.toml

## validate: long verification runs and the paper's examples at full resolution (not in CI)
validate: $(VENV)/.installed-test
	$(BIN)/python -m pytest -q -m slow
	for s in $(EXAMPLES); do $(BIN)/blastfrac run $$s || exit 1; done
	$(BIN)/python examples/confined_blast/compare.py --out out/confined_blast_compare
	$(BIN)/python examples/rock_fronts/candidates.py --out out/rock_fronts
	$(BIN)/python examples/charge_resolution/study.py --out out/charge_resolution

## bench: performance suite (throughput and scaling), results printed and appended to benchmarks/
bench: $(VENV)/.installed
	$(BIN)/blastfrac bench

## gpu-check: on a machine with a CUDA GPU, its throughput and run times and their agreement with the CPU (out/gpu_check)
gpu-check: $(VENV)/.installed
	$(BIN)/python benchmarks/gpu_check.py

## gpu-pack: for a lent GPU machine without Warp: the dependencies in parts of a call's size (.gpu/pK; benchmarks/gpu_pack.py)
gpu-pack: $(VENV)/.installed
	$(BIN)/python benchmarks/gpu_pack.py

clean:
	rm -rf out .pytest_cache
