# Two commands for users: `make demo` and `make test`. Both create .venv from nothing.
# For developers: `make check`, the fast loop (every test but the slow ones, two processes).
PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
TEST_STAMP := $(VENV)/.installed-test
DEMO_MODEL ?= models/rs25_hotfire.toml
DEMO_OUT   ?= out/greenrun

.PHONY: demo test check browser bench clean verification docs

# Install with uv (from PyPI into the venv: parallel downloads, several times faster than pip);
# pip if uv cannot be had. The venv is made without pip (ensurepip: about 10 s here); the
# interpreter's own pip installs uv into it. `make demo` installs the package alone; `make test` adds the test
# extra. No bytecode at install: compiling every module of the venv (scipy, plotly, dask, ...)
# cost 55 CPU-s of a 76 s install here; `make demo` lets Python write the bytecode of the modules
# it imports as it imports them, and so does `make test` (its warm-up, docs build and pytest
# processes), after compiling taos once ($(PYC)).
# The numba kernels compile on first use and are cached: `make demo` compiles only what the
# Green Run needs, `make test` warms every kernel first.
$(STAMP): pyproject.toml setup.py
	$(PYTHON) -c 'import sys; assert sys.version_info >= (3, 11), "Python 3.11+ needed"'
	$(PYTHON) -m venv --without-pip $(VENV)
	( ( $(PYTHON) -m pip --python $(BIN)/python install --quiet uv 2>/dev/null || \
	    ( $(BIN)/python -m ensurepip >/dev/null && $(BIN)/python -m pip install --quiet uv ) ) && \
	  $(BIN)/uv pip install --quiet --python $(BIN)/python -e . ) || \
	  ( $(BIN)/python -m ensurepip >/dev/null; $(BIN)/python -m pip install --quiet --no-compile -e . )
	touch $(STAMP)

# The bench extra: the MuJoCo peer of benchmarks/bench_taos3d.py; pip: tests/test_install.py
# and tests/test_plugins.py build and install wheels with it.
$(TEST_STAMP): $(STAMP)
	$(BIN)/uv pip install --quiet --python $(BIN)/python -e '.[test,bench]' pip 2>/dev/null || \
	  $(BIN)/python -m pip install --quiet --no-compile -e '.[test,bench]'
	touch $(TEST_STAMP)

# numba's on-disk cache keys each kernel on its own file only: a kernel that inlines code from
# another file (the friction laws' bearing steps, the 3-D step) or reads its constants keeps its
# old machine code when only that other file changes. So when a file whose code numba compiles
# changes, `make test` drops the whole kernel cache and warms it again, in two processes at once
# (each compiles its own share of the kernels; about a minute on 2 cores); a fresh clone has no
# cache to drop. Those files (KERNEL_SOURCES): the modules that import numba or declare kernels
# and the modules they take names from (`python3 taos/cli/warmup.py --sources`, static; checked
# against the loaded kernels by tests/test_kernel_sources.py). Other changes (the report, the
# CLI, ...) keep the cache.
KERNEL_SOURCES := $(shell $(PYTHON) taos/cli/warmup.py --sources)
TAOS_SOURCES := $(shell find taos -name '*.py' -not -path '*/__pycache__/*')
PYC  := $(VENV)/.pyc
WARM := $(VENV)/.warm
# The Python bytecode (.pyc) of taos, after any change under taos/: where PYTHONDONTWRITEBYTECODE
# is set nothing writes it otherwise, and every `taos` process then compiles ~600 modules from
# source (about 1 s of start-up a process; benchmarks/RESULTS.md). The venv's packages are not
# compiled ahead (all 14,000 modules: 24 CPU-s, 15 s before the warm-up could start): every
# process of `make test` runs with PYTHONDONTWRITEBYTECODE emptied ($(PYW)), so the first one to
# import a module writes its bytecode (about 3,400 modules, 7 CPU-s; atomic, so two processes
# importing it at once are safe).
PYW := PYTHONDONTWRITEBYTECODE=
$(PYC): $(TEST_STAMP) $(TAOS_SOURCES)
	$(BIN)/python -m compileall -q -j 2 taos >/dev/null
	touch $(PYC)

$(WARM): $(TEST_STAMP) $(KERNEL_SOURCES) taos/cli/warmup.py | $(PYC)
	find taos masv -path '*/__pycache__/*' \( -name '*.nbi' -o -name '*.nbc' \) -delete
	$(PYW) $(BIN)/python -m taos.cli.warmup --part 1/2 & one=$$!; \
	  $(PYW) $(BIN)/python -m taos.cli.warmup --part 2/2; two=$$?; wait $$one && exit $$two
	touch $(WARM)

# On a cold kernel cache a second process compiles the planar simulation's kernels beside the
# Green Run's 3-D ones (taos/cli/warmup.py; a second of loading when the cache is warm), and the
# dwells' C libraries (taos/planar/_cdwell.py: about 0.4 CPU-s a law, nothing when cached).
demo: $(STAMP)
	@PYTHONDONTWRITEBYTECODE= $(BIN)/python -m taos.cli.warmup --only "simulate,C dwells" >/dev/null 2>&1 & w=$$!; \
	  PYTHONDONTWRITEBYTECODE= $(BIN)/taos greenrun $(DEMO_MODEL) --engine taos --out $(DEMO_OUT); \
	  rc=$$?; wait $$w; exit $$rc
	@echo "Green Run report: $(DEMO_OUT)/index.html"

# The browser tests need Debian's chromium; install it when missing (root, as in CI).
browser:
	@command -v chromium >/dev/null 2>&1 || { \
	  if [ "$$(id -u)" = 0 ]; then \
	    (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null) ; \
	  else echo "chromium missing: run 'sudo apt-get install chromium' for the browser tests"; fi; }

# The documentation site (Sphinx, warnings are errors): runs the user guide's commands on the
# shipped models for its pictures, so it takes a few minutes. Output: docs/_build/html.
DOCS_STAMP := $(VENV)/.docs-installed
$(DOCS_STAMP): $(TEST_STAMP)
	$(BIN)/uv pip install --quiet --python $(BIN)/python -e '.[docs]' 2>/dev/null || \
	  $(BIN)/python -m pip install --quiet -e '.[docs]'
	touch $(DOCS_STAMP)

# pytest exits 5 when it collects no tests; treat that as success, anything else as is.
# The documentation is built (sphinx -W: no warnings) at the same time as the tests, in the
# background (its output in docs/_build/sphinx.log, shown if it fails; a failed build fails
# `make test`), so both cores stay busy. The user guide's commands and the gallery's examples
# run once, in the docs build: right after it, still in the background, tests/test_docs.py and
# tests/test_examples.py check what that build's runs wrote (TAOS_TEST_DOCS_STATUS names the
# file holding the build's exit status; without it, as in `make check` or plain pytest, or
# after a failed build, those tests run the commands and examples themselves); the main run
# leaves those two files out. Two pytest processes (pytest-xdist; the tests
# share no output folder or port); a worker that runs out of tests takes half of the other's
# queue (--dist worksteal: no worker idles while a long test runs on the other at the end; both cuts
# fall between test modules where they can, tests/_xdist_modules.py, so no module fixture is built twice;
# benchmarks/sim_test_order.py).
DOCS_STATUS := $(CURDIR)/docs/_build/sphinx.status
# pytest rewrites every test module's asserts when it imports it, and caches the result in
# tests/__pycache__ only where bytecode may be written: with PYTHONDONTWRITEBYTECODE set, each
# pytest process parsed and rewrote ~130 test modules again (8.6 -> 4.1 CPU-s a collection).
PYTEST := $(PYW) $(BIN)/python -m pytest -q -p no:cacheprovider
SPHINX := $(PYW) MPLBACKEND=Agg $(BIN)/python -m sphinx -b html -W --keep-going -q docs docs/_build/html
test: $(PYC) $(WARM) browser $(DOCS_STAMP)
	@rm -rf docs/_build docs/_generated; mkdir -p docs/_build; \
	  ( $(SPHINX) >docs/_build/sphinx.log 2>&1; echo $$? >$(DOCS_STATUS).tmp; mv $(DOCS_STATUS).tmp $(DOCS_STATUS); \
	    TAOS_TEST_DOCS_STATUS=$(DOCS_STATUS) $(PYTEST) tests/test_docs.py tests/test_examples.py \
	      >docs/_build/test_docs.log 2>&1; echo $$? >docs/_build/test_docs.status ) & \
	  docs=$$!; \
	  $(PYTEST) -n 2 --dist worksteal --durations=25 --ignore=tests/test_docs.py --ignore=tests/test_examples.py tests; \
	  rc=$$?; if [ $$rc -eq 5 ]; then echo "pytest: no tests collected"; rc=0; fi; \
	  wait $$docs; drc=$$(cat $(DOCS_STATUS) 2>/dev/null || echo 1); \
	  trc=$$(cat docs/_build/test_docs.status 2>/dev/null || echo 1); \
	  echo "tests/test_docs.py tests/test_examples.py (after the docs build):"; tail -n 40 docs/_build/test_docs.log; \
	  if [ "$$trc" != 0 ] && [ $$rc -eq 0 ]; then rc=1; fi; \
	  if [ "$$drc" = 0 ]; then echo "Documentation: docs/_build/html/index.html"; \
	  else cat docs/_build/sphinx.log; echo "make test: the documentation build failed (exit $$drc)"; \
	    [ $$rc -ne 0 ] || rc=1; fi; exit $$rc

# The fast loop while developing: every test except those marked slow (the end-to-end runs: the
# Green Run report, Monte Carlo campaigns, the installed wheel, time-domain limit cycles, the
# live viewer), on two processes (pytest-xdist), without the documentation build. About 5 minutes
# on 2 cores once the kernel cache is warm (after a kernel-file change the warm-up adds about 30 s).
check: $(PYC) $(WARM) browser
	@$(PYTEST) -n 2 --dist worksteal -m "not slow" tests; rc=$$?; \
	  if [ $$rc -eq 5 ]; then echo "pytest: no tests collected"; rc=0; fi; exit $$rc

# the verification suite (tests/verification) and its table docs/verification.md
verification: $(TEST_STAMP)
	$(BIN)/python scripts/verification_report.py

bench: $(STAMP)
	for b in benchmarks/bench_*.py; do $(BIN)/python $$b || exit 1; done

docs: $(DOCS_STAMP)
	rm -rf docs/_build docs/_generated
	$(SPHINX)
	@echo "Documentation: docs/_build/html/index.html"

clean:
	rm -rf $(VENV) out .pytest_cache docs/_build docs/_generated
