# obsdesign: every target installs what it needs first (Debian packages, then a virtualenv).
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
SUDO   := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
DEBS   := libcdd-dev libgmp-dev

.PHONY: install run test test-slow test-explore bench bench-quick lint clean

install: $(VENV)/.installed

$(VENV)/.debs:
	@dpkg -s $(DEBS) >/dev/null 2>&1 || { $(SUDO) apt-get update -qq && $(SUDO) DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $(DEBS); }
	@[ -d $(VENV) ] || $(PYTHON) -m venv $(VENV)
	@touch $@

$(VENV)/.installed: $(VENV)/.debs pyproject.toml
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[dev]'
	@touch $@

run: install
	$(VENV)/bin/obsdesign check specs/

test: install
	$(PY) -m pytest -q

test-explore: install
	HYPOTHESIS_PROFILE=explore $(PY) -m pytest -q

test-slow: install
	$(PY) -m pytest -q -m slow

bench: install
	$(PY) benchmarks/run.py

bench-quick: install
	OBSDESIGN_BENCH_QUICK=1 $(PY) benchmarks/run.py

lint: install
	$(VENV)/bin/ruff check obsdesign tests benchmarks
	$(VENV)/bin/ruff format --check obsdesign tests benchmarks

clean:
	rm -rf $(VENV) build *.egg-info
