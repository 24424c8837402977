# poppy — the two commands a new machine needs are `make run` and `make test`.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin

.PHONY: run test test-fast test-loaded lint completions bench clean sim-deps

$(BIN)/activate:
	@echo "creating the virtualenv $(VENV)…"
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip

$(VENV)/.installed: pyproject.toml | $(BIN)/activate
	@echo "installing poppy and its dependencies into $(VENV) (about a minute)…"
	$(BIN)/pip install --quiet -e '.[all]'
	touch $@

$(VENV)/.installed-test: pyproject.toml | $(BIN)/activate
	@echo "installing poppy, its dependencies and the test tools into $(VENV) (a minute or two)…"
	$(BIN)/pip install --quiet -e '.[all,test]'
	touch $(VENV)/.installed $@

run: $(VENV)/.installed
	$(BIN)/poppy demo

# Parallel pytest workers: `auto` is two per core (tests/conftest.py), since most tests wait
# (wire timing, servers, subprocesses) more than they compute; three per core made the idle
# run slower. The `poppy` commands the tests run wait for their emulators' replies as long as
# the load needs (POPPY_REPLY_FLOOR_S, see docs/testing.md); TEST_WORKERS=4 for four,
# TEST_WORKERS=0 runs in one process.
TEST_WORKERS ?= auto
# The modules that mostly wait (documentation examples sleeping as written, the README tour,
# scans waiting out absent motors: tests/helpers/parts.py) run in workers of their own.
WAITING_WORKERS ?= 3

# The whole suite in parallel workers, a test module per worker (see tests/conftest.py): the
# modules that mostly wait in WAITING_WORKERS of their own beside the others, so that the cores
# stay busy while they wait; the OpenGL tests in a pytest process of their own; and mypy. All
# four at once (tests/together.sh: the others' output follows the first's, then a recap, and
# any failure fails `make test`).
test: $(VENV)/.installed-test
	$(BIN)/ruff check poppy_core poppy_cli tests bench
	$(BIN)/ruff format --check poppy_core poppy_cli tests bench
	sh tests/together.sh \
		'env POPPY_TEST_PART=rest $(BIN)/pytest -m "not gl" -n $(TEST_WORKERS) --dist loadgroup' \
		'env POPPY_TEST_PART=waiting $(BIN)/pytest -m "not gl" -n $(WAITING_WORKERS) --dist loadgroup' \
		'$(BIN)/mypy' 'env POPPY_TEST_PART=gl $(BIN)/pytest -m gl'

# The inner loop (under 90 s on a quiet machine): lint, then every test not marked `slow`.
test-fast: $(VENV)/.installed-test
	$(BIN)/ruff check poppy_core poppy_cli tests bench
	$(BIN)/ruff format --check poppy_core poppy_cli tests bench
	$(BIN)/pytest -q -m "not slow" -n $(TEST_WORKERS) --dist loadgroup

# The whole suite with LOOPS busy loops beside it (default 2, one per core), as on a shared CI
# machine: a test that measures a timing instead of an arrival, an order or a shape fails here.
# tests/loaded.sh stops the loops when the run ends. TARGET=test-fast for the inner loop.
LOOPS ?= 2
TARGET ?= test
test-loaded: $(VENV)/.installed-test
	LOOPS=$(LOOPS) sh tests/loaded.sh $(MAKE) $(TARGET)

lint: $(VENV)/.installed-test
	$(BIN)/ruff check poppy_core poppy_cli tests bench
	$(BIN)/ruff format --check poppy_core poppy_cli tests bench
	$(BIN)/mypy

completions: $(VENV)/.installed
	_POPPY_COMPLETE=source_bash $(BIN)/poppy > completions/poppy.bash
	_POPPY_COMPLETE=source_zsh $(BIN)/poppy > completions/poppy.zsh
	_POPPY_COMPLETE=source_fish $(BIN)/poppy > completions/poppy.fish

# Offscreen rendering for `poppy sim render` (EGL, or OSMesa on machines without a GPU).
SIM_PACKAGES := libegl1 libegl-mesa0 libgl1 libgl1-mesa-dri libosmesa6
sim-deps:
	$(if $(filter 0,$(shell id -u)),,sudo) apt-get install -y $(SIM_PACKAGES)

bench: $(VENV)/.installed-test
	$(BIN)/python -m bench

clean:
	rm -rf $(VENV) .pytest_cache .mypy_cache .ruff_cache
