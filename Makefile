# The two commands a new user needs: `make demo` and `make test`. Both create .venv on first use.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
OUT := out

.PHONY: demo test validate report-check bench lint fuzz docs venv clean

venv: $(STAMP)

$(STAMP): pyproject.toml
	@$(PYTHON) -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else "pushrecovery needs Python >= 3.11; set PYTHON=python3.11")'
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[all,dev]'
	$(BIN)/python -m compileall -q src  # the bytecode, as a wheel install compiles it
	@touch $(STAMP)

demo: $(STAMP)
	@mkdir -p $(OUT)
	$(BIN)/pushrecovery bounds
	$(BIN)/pushrecovery classify --x 0.0 --xdot 0.7
	$(BIN)/pushrecovery report --out $(OUT)/report
	@echo "open $(OUT)/report/index.html"

test: docs
	$(BIN)/python -m pytest -q -n 2 -m "not validate and not browser"

# The long physics validations (pytest marker `validate`): the full grids and horizons whose
# short versions run in `make test`.
validate: $(STAMP)
	$(BIN)/python -m pytest -q -n 2 -m validate

# The report of a non-default body as a reader sees it: headless Chromium (Debian's package,
# installed here when missing) takes a screenshot (out/report-check/screenshot.png) and the DOM.
report-check: $(STAMP)
	@command -v chromium >/dev/null || (apt-get update -qq && apt-get install -y -qq chromium)
	$(BIN)/python -m pytest -q -m browser tests/test_report_browser.py

# The site (Sphinx): guides, topics, the API reference from the docstrings and the CLI reference
# from click, into out/docs; a warning (a broken reference, a malformed docstring) fails the build.
docs: $(STAMP)
	$(BIN)/sphinx-build -q -W --keep-going -j 2 -b html -d $(OUT)/doctrees docs $(OUT)/docs
	@echo "open $(OUT)/docs/index.html"

bench: $(STAMP)
	$(BIN)/python benchmarks/run.py

# Hostile input (docs/reliability.md): the API properties with 50x the examples, then 10,000
# command lines and mutated C3D/CSV/TOML files in crash-isolated workers; one summary line.
fuzz: $(STAMP)
	HYPOTHESIS_PROFILE=fuzz $(BIN)/python -m pytest -q -n 2 tests/test_api_hostile.py tests/test_hostile.py
	$(BIN)/python tests/fuzz/campaign.py --cases 10000 --seed 0

lint: $(STAMP)
	$(BIN)/ruff check src tests benchmarks examples
	$(BIN)/ruff format --check src tests benchmarks examples
	$(BIN)/mypy src
	$(BIN)/lint-imports

clean:
	rm -rf $(VENV) $(OUT)
