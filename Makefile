# obsdesign: every target installs what it needs first (Debian packages, then a virtualenv).
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
SUDO   := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
DEBS   := libcdd-dev libgmp-dev

.PHONY: install run test test-slow test-explore bench bench-quick lint clean mutation

install: $(VENV)/.installed

# besides DEBS, what a fresh Debian lacks to build pycddlib (no Linux wheel: pip compiles it)
# and make the virtualenv: a C toolchain, the Python headers, ensurepip (docs review 45)
$(VENV)/.debs:
	@need="$(DEBS)"; \
	command -v cc >/dev/null 2>&1 || need="$$need build-essential"; \
	$(PYTHON) -c 'import os, sys, sysconfig; sys.exit(not os.path.exists(os.path.join(sysconfig.get_paths()["include"], "Python.h")))' || need="$$need python3-dev"; \
	$(PYTHON) -c 'import ensurepip' 2>/dev/null || need="$$need python3-venv"; \
	dpkg -s $$need >/dev/null 2>&1 || { $(SUDO) apt-get update -qq && $(SUDO) env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$need; }
	@# a .venv without pip (left by a venv made before python3-venv was there) is made again
	@$(PY) -m pip --version >/dev/null 2>&1 || $(PYTHON) -m venv --clear $(VENV)
	@touch $@

$(VENV)/.installed: $(VENV)/.debs pyproject.toml
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[dev,distributed,parquet,control]'
	@touch $@

run: install
	$(VENV)/bin/obsdesign check specs/

test: install
	$(PY) -m pytest -q

test-explore: install
	HYPOTHESIS_PROFILE=explore $(PY) -m pytest -q

test-slow: install
	$(PY) -m pytest -q -m slow

# compileall: an installed package ships its bytecode; the editable install's sources are
# compiled here so that cold-start figures do not time the compiler (PYTHONDONTWRITEBYTECODE
# stops Python from caching it, not from reading it)
bench: install
	$(PY) -m compileall -q obsdesign
	$(PY) benchmarks/run.py

bench-quick: install
	$(PY) -m compileall -q obsdesign
	OBSDESIGN_BENCH_QUICK=1 $(PY) benchmarks/run.py

lint: install
	$(VENV)/bin/ruff check obsdesign tests benchmarks
	$(VENV)/bin/ruff format --check obsdesign tests benchmarks

# Mutation testing (docs/mutation.md), outside the default suite. `make mutation` mutates
# obsdesign/certify/ ([tool.mutmut] in pyproject.toml) against the kernel's tests;
# `make mutation MUTATION_SCOPE=claims` mutates the methods' claim checks (MUTATION_CLAIMS)
# against the default suite (MUTATION_TESTS), in a scratch copy (build/mutation-claims).
# Prints the score (equivalent mutants listed in docs/mutation.md excluded) and every mutant
# not killed (`mutmut show NAME` shows one).
MUTATION_SCOPE ?= kernel
MUTATION_CLAIMS := obsdesign/methods/*/claims.py obsdesign/lyap.py obsdesign/methods/lyapunov/* obsdesign/methods/impulsive/core.py obsdesign/methods/setinvariant/certificate.py
MUTATION_TESTS ?= tests/
MUTATION_JOBS ?= $(shell nproc 2>/dev/null || echo 2)

define MUTATION_SCORE_PY
import pathlib, re, subprocess, sys
mutmut, prefix, doc = sys.argv[1:4]
out = subprocess.run([mutmut, "results", "--all", "true"], capture_output=True, text=True).stdout
st = {k: v.strip() for k, v in re.findall(r"^\s*(\S+__mutmut_\d+): (.+)$$", out, re.M) if re.match(prefix, k)}
text = pathlib.Path(doc).read_text(encoding="utf-8") if pathlib.Path(doc).exists() else ""
sec = text.split("## Equivalent mutants", 1)[1].split("\n## ", 1)[0] if "## Equivalent mutants" in text else ""
eq = set(re.findall(r"`(\S+__mutmut_\d+)`", sec)) & st.keys()
killed = [k for k, v in st.items() if v in ("killed", "timeout") and k not in eq]
left = sorted(k for k, v in st.items() if v not in ("killed", "timeout") and k not in eq)
wrongly = sorted(k for k in eq if st[k] in ("killed", "timeout"))
total = len(st) - len(eq)
for k in left:
    print(f"  {st[k]:>10}  {k}")
for k in wrongly:
    print(f"  listed as equivalent but killed: {k}")
print(f"mutation score {len(killed)}/{total} = {100 * len(killed) / max(total, 1):.1f}% "
      f"({len(st)} mutants, {len(eq)} equivalent excluded, {len(left)} not killed)")
endef
export MUTATION_SCORE_PY

define MUTATION_CLAIMS_PY
import pathlib, sys
p = pathlib.Path(sys.argv[1])
s = p.read_text(encoding="utf-8")
head, tail = s.split("[tool.mutmut]", 1)
rest = tail.split("\n[", 1)[1] if "\n[" in tail else ""
q = lambda xs: "[" + ", ".join('"' + x + '"' for x in xs) + "]"
cfg = ("[tool.mutmut]\nsource_paths = [\"obsdesign/\"]\nonly_mutate = " + q(sys.argv[3:]) + "\n"
       "also_copy = [\"specs/\"]\npytest_add_cli_args_test_selection = " + q(sys.argv[2].split()) + "\n")
p.write_text(head + cfg + ("\n[" + rest if rest else ""), encoding="utf-8")
endef
export MUTATION_CLAIMS_PY

mutation: install
ifeq ($(MUTATION_SCOPE),claims)
	rm -rf build/mutation-claims && mkdir -p build/mutation-claims
	cp -r obsdesign tests specs pyproject.toml build/mutation-claims/
	$(PY) -c "$$MUTATION_CLAIMS_PY" build/mutation-claims/pyproject.toml "$(MUTATION_TESTS)" $(MUTATION_CLAIMS)
	cd build/mutation-claims && ../../$(VENV)/bin/mutmut run --max-children $(MUTATION_JOBS) > mutmut-run.log 2>&1 || { tail -c 3000 mutmut-run.log; exit 1; }
	cd build/mutation-claims && ../../$(PY) -c "$$MUTATION_SCORE_PY" ../../$(VENV)/bin/mutmut 'obsdesign\.methods\.' ../../docs/mutation.md
else
	rm -rf mutants && mkdir -p build
	$(VENV)/bin/mutmut run --max-children $(MUTATION_JOBS) > build/mutmut-run.log 2>&1 || { tail -c 3000 build/mutmut-run.log; exit 1; }
	$(PY) -c "$$MUTATION_SCORE_PY" $(VENV)/bin/mutmut 'obsdesign\.certify\.' docs/mutation.md
endif

clean:
	rm -rf $(VENV) build *.egg-info
