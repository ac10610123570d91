# Entry points for a fresh machine; each builds the virtual environment it needs.
#   make mission     install seminspect, compile its kernels, run the default inspection mission
#   make test        install seminspect with test tools and run the test suite
#   make docs        build the API reference from the docstrings into build/docs
#   make reproduce   regenerate every measured table of docs/reproduction.md (about 79 minutes on 2 cores)
#   make lock        rewrite requirements.lock from the versions installed in .venv
# Installs take the exact versions of requirements.lock (the ones behind the published
# figures); pyproject.toml keeps version ranges for people who use seminspect as a library.
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
LOCK := requirements.lock

.PHONY: mission test lint docs bench reproduce lock clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(VENV)/.installed-run: pyproject.toml $(LOCK) | $(BIN)/python
	$(BIN)/python -m pip install --quiet -c $(LOCK) -e .
	touch $@

$(VENV)/.installed-test: pyproject.toml $(LOCK) | $(BIN)/python
	$(BIN)/python -m pip install --quiet -c $(LOCK) -e '.[test]'
	touch $@ $(VENV)/.installed-run

# numba compiles each kernel on its first call and caches it beside the source. One short
# mission right after install, on the default world and with its pictures, compiles what
# missions use and stores the world's collision grid in seminspect's cache, so that the first
# mission a user runs starts warm: the compilation (tens of seconds) moves to the install.
WARM_UP_RUN := $(VENV)/warm-up-run
$(VENV)/.compiled: $(VENV)/.installed-run
	@echo 'Compiling the kernels with one short mission (a minute or two, once per install)...'
	rm -rf $(WARM_UP_RUN)
	$(BIN)/seminspect mission --budget 300 --out $(WARM_UP_RUN) > /dev/null
	rm -rf $(WARM_UP_RUN)
	touch $@

mission: $(VENV)/.compiled
	$(BIN)/seminspect mission

test: $(VENV)/.installed-test
	$(BIN)/python -m pytest -n 2 -q

lint: $(VENV)/.installed-test
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

# Into build/docs (mkdocs.yml), pages generated from the package tree (docs/hooks/); any
# warning fails the build.
docs: $(VENV)/.installed-test
	$(BIN)/mkdocs build --strict

reproduce: $(VENV)/.installed-test
	$(BIN)/python bench/reproduction.py --fresh

# After changing a dependency in pyproject.toml: install the new version in .venv, then lock.
lock: | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[test]'
	$(BIN)/python scripts/lock_requirements.py
	touch $(VENV)/.installed-test $(VENV)/.installed-run

clean:
	rm -rf $(VENV) runs build .pytest_cache .ruff_cache
