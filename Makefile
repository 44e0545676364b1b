# The two commands a newcomer needs: `make report` and `make test`.
# Both create .venv on first use and reinstall only when pyproject.toml changes.

PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: test typecheck docs report report-full bench lint models fuzz clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[all]'
	touch $(STAMP)

test: $(STAMP)
	$(BIN)/python -m pytest tests properties --benchmark-disable -n auto

# mypy over the whole package (configuration: pyproject.toml's [tool.mypy]).
typecheck: $(STAMP)
	$(BIN)/mypy refsim

# The documentation site (docs/site/) into docs/_build/html, a warning
# being an error: first the tutorials' code runs (the doctest builder), then
# the pages are written, reusing the doctrees the first pass read.
SPHINX := $(BIN)/sphinx-build -W --keep-going -q -d docs/_build/doctrees docs/site
docs: $(STAMP)
	$(SPHINX) -b doctest docs/_build/doctest
	$(SPHINX) -b html docs/_build/html

# The quick report (about two minutes); report-full measures everything, its
# sweeps on two processes (about twelve minutes on two cores).
report: $(STAMP)
	$(BIN)/refsim report

report-full: $(STAMP)
	$(BIN)/refsim report --full --workers 2

bench: $(STAMP)
	$(BIN)/python -m pytest tests/benchmarks --benchmark-only --benchmark-columns=min,median,max,rounds

lint: $(STAMP)
	$(BIN)/ruff check .

models: $(STAMP)
	$(BIN)/python models/generate.py

# The fuzz campaign (tests/fuzz/campaign.py): MINUTES of mutants and API
# probes from SEED on WORKERS processes; the table, results.json and the
# reproducers go to fuzz-out/.
MINUTES ?= 10
SEED    ?= 1
WORKERS ?= 2
fuzz: $(STAMP)
	$(BIN)/python -m tests.fuzz.campaign --minutes $(MINUTES) --seed $(SEED) \
		--workers $(WORKERS) --out fuzz-out

clean:
	rm -rf $(VENV) reports/out docs/_build fuzz-out .pytest_cache .hypothesis .benchmarks
