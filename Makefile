# The two commands a new user needs: `make demo` and `make test`. Both create .venv on first use.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
OUT := out

.PHONY: demo test bench lint venv clean

venv: $(STAMP)

$(STAMP): pyproject.toml
	@$(PYTHON) -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else "pushrecovery needs Python >= 3.11; set PYTHON=python3.11")'
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	@touch $(STAMP)

demo: $(STAMP)
	@mkdir -p $(OUT)
	$(BIN)/pushrecovery bounds
	$(BIN)/pushrecovery classify --x 0.0 --xdot 0.3
	$(BIN)/pushrecovery classify --x 0.0 --xdot 0.6
	$(BIN)/pushrecovery classify --x 0.0 --xdot 0.7
	$(BIN)/pushrecovery classify --x 0.0 --xdot 2.7
	$(BIN)/pushrecovery step --v0 1.2
	$(BIN)/pushrecovery simulate --model stepping --controller recovery --xdot 1.2 --plot $(OUT)/recovery.png
	$(BIN)/pushrecovery critical-push --model pendulum --controller ankle-pd --x 0.0 --direction forward
	$(BIN)/pushrecovery critical-push --model flywheel --controller mpc --x 0.0 --direction forward
	$(BIN)/pushrecovery figures --out $(OUT)/figures

test: $(STAMP)
	$(BIN)/python -m pytest -q -n 2

bench: $(STAMP)
	$(BIN)/python benchmarks/run.py

lint: $(STAMP)
	$(BIN)/ruff check src tests benchmarks examples
	$(BIN)/ruff format --check src tests benchmarks examples
	$(BIN)/mypy src

clean:
	rm -rf $(VENV) $(OUT)
