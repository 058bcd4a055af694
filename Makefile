# kinplan: `make demo` and `make test` each do everything on a fresh machine.
PYTHON ?= python3
VENV   ?= .venv
BIN     = $(VENV)/bin
STAMP   = $(VENV)/.kinplan-installed
OUT    ?= out
# Test workers (pytest-xdist): one per core of a 2-core CI machine; `make test JOBS=1` runs serially.
JOBS   ?= 2

.PHONY: install demo test soak lint bench chromium clean mutation

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[dev]"
	# byte-compiled once, as pip does for a wheel (an editable install leaves it to the first
	# import, which PYTHONDONTWRITEBYTECODE=1 turns into a compile at every start-up)
	$(BIN)/python -m compileall -q kinplan cartesian
	touch $(STAMP)

install: $(STAMP)

demo: install
	$(BIN)/python examples/quickstart.py
	$(BIN)/kinplan demo lecture --out $(OUT)/lecture
	$(BIN)/kinplan demo weld --out $(OUT)/weld

# Debian's chromium renders the MeshCat playback in the browser test; the test is skipped
# (with its reason) where it cannot be installed.
chromium:
	@if ! command -v chromium >/dev/null 2>&1 && [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
		echo "installing Debian's chromium for the browser test"; \
		(apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null) \
			|| echo "could not install chromium: the browser test will be skipped"; \
	fi

lint: install
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/mypy kinplan cartesian

test: install chromium lint
	$(BIN)/python -m pytest -q -n $(JOBS) --dist worksteal --durations=15

# The long soaks and property runs (marked `slow`, left out of `make test`); CI runs them too.
soak: install
	$(BIN)/python -m pytest -q -n $(JOBS) --dist worksteal --durations=25 -m slow

# Benchmarks print tables (never timed unit tests); the peers come from the `bench` extra.
bench: install
	$(BIN)/python -m pip install --quiet -e ".[bench]" || echo "peers not installed: their rows say so"
	$(BIN)/python tests/bench/run_all.py

# Mutation score of the core modules with mutmut (long: about an hour on 2 cores; not part of
# `make test`). Writes tests/bench/MUTATION.md. MUTATION_ARGS="--modules kinplan/ik.py" runs some
# modules only, "--sample 300" a seeded sample of each module's mutants.
MUTMUT_VERSION = 3.8.1
MUTATION_ARGS ?=
mutation: install
	$(BIN)/python -m pip install --quiet "mutmut==$(MUTMUT_VERSION)"
	nice -n 19 $(BIN)/python tools/mutation.py $(MUTATION_ARGS)

clean:
	rm -rf $(VENV) build dist *.egg-info .pytest_cache .ruff_cache .mypy_cache $(OUT)
