# Two commands from a fresh clone: `make demo` and `make test`. Each bootstraps .venv on its own:
# pinned wheels (requirements.txt), then the att_msgs and tf2_msgs interfaces built with rosidl into the venv
# prefix, then this package (editable) and the demo's plan-signing key pair (att-keygen). Stamps make
# a second run fast.
SHELL := /bin/bash
PYTHON ?= python3.11
VENV := .venv
PREFIX := $(abspath $(VENV))
PY := $(PREFIX)/bin/python
BUILD_ENV := PATH=$(PREFIX)/bin:$$PATH CMAKE_PREFIX_PATH=$(PREFIX) AMENT_PREFIX_PATH=$(PREFIX)
INTERFACES := $(shell find att_msgs_py/interfaces -type f)
PYTEST_ARGS ?=
# one BLAS/OpenMP thread: the solvers' matrices are small, and on a loaded 2-core machine threaded BLAS
# made them 4-5x slower (the benchmarks are run the same way, see BENCHMARKS.md)
export OMP_NUM_THREADS ?= 1

.PHONY: setup bytecode test test-fast test-long lint demo clean

setup: $(VENV)/.stamp-package

$(VENV)/.stamp-venv:
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check pip==26.3
	touch $@

# --no-compile: pip compiles one file at a time; the bytecode is written once the interfaces and the
# package are in (.stamp-package, two processes)
$(VENV)/.stamp-deps: requirements.txt $(VENV)/.stamp-venv
	$(PY) -m pip install --quiet --disable-pip-version-check --no-compile -r requirements.txt
	touch $@

# tf2_msgs (the /tf type: its standard TFMessage definition, no wheel on PyPI) first, then att_msgs
$(VENV)/.stamp-interfaces: $(INTERFACES) $(VENV)/.stamp-deps
	mkdir -p build
	set -e; for pkg in tf2_msgs:att_msgs_py/interfaces/tf2_msgs att_msgs:att_msgs_py/interfaces; do \
	  name=$${pkg%%:*}; src=$${pkg#*:}; rm -rf build/$$name; \
	  $(BUILD_ENV) cmake -S $$src -B build/$$name -DCMAKE_INSTALL_PREFIX=$(PREFIX) \
	    -DPython3_EXECUTABLE=$(PY) -DBUILD_TESTING=OFF > build/$$name.configure.log 2>&1 \
	    || { tail -40 build/$$name.configure.log; exit 1; }; \
	  $(BUILD_ENV) cmake --build build/$$name -j2 > build/$$name.build.log 2>&1 \
	    || { tail -40 build/$$name.build.log; exit 1; }; \
	  $(BUILD_ENV) cmake --install build/$$name > build/$$name.install.log 2>&1; \
	done
	$(PY) -c "import att_msgs.msg, att_msgs.srv, att_msgs.action, tf2_msgs.msg"
	touch $@

# the bytecode of every installed module, written here because Python may not write it itself: with
# PYTHONDONTWRITEBYTECODE set, every process (each node, worker, example) would compile numpy, scipy,
# CasADi and rclpy's Python anew when it starts
$(VENV)/.stamp-package: setup.py package.xml pyproject.toml $(VENV)/.stamp-interfaces
	$(PY) -m pip install --quiet --disable-pip-version-check --no-deps --no-build-isolation -e .
	$(PREFIX)/bin/att-keygen --if-missing
	$(PY) -m compileall -q -j 2 $$($(PY) -c "import sysconfig; print(sysconfig.get_paths()['purelib'])") > /dev/null
	touch $@

# the suite's own modules, whose sources change between runs (compileall rewrites only what changed)
bytecode: setup
	$(PY) -m compileall -q att_msgs_py att_sim att_planner > /dev/null

# the habits first (seconds): ruff's rules and the import contracts (pyproject.toml), then every test:
# the ROS-free ones on both cores (pytest-xdist), then the ones that start nodes or a DDS participant one
# at a time (each on its own random ROS domain; timing-sensitive). Both parts run; either failing fails.
# The `long` tests (minutes each) are left to `make test-long`.
test: lint bytecode
	status=0; \
	$(PY) -m pytest test -m "not ros and not long" -n 2 $(PYTEST_ARGS) || status=$$?; \
	$(PY) -m pytest test -m "ros and not long" $(PYTEST_ARGS) || status=$$?; \
	exit $$status

# the tests that take minutes each (a whole imaging orbit through the nodes), apart from `make test`
test-long: lint bytecode
	$(PY) -m pytest test -m long $(PYTEST_ARGS)

# the ROS-free unit tests only: no nodes, no DDS, nothing slow (a quick check while working)
test-fast: lint bytecode
	$(PY) -m pytest test -m "not ros and not slow" $(PYTEST_ARGS)

lint: setup
	$(PREFIX)/bin/ruff check .
	$(PREFIX)/bin/lint-imports --no-logo --no-cache

demo: bytecode
	$(PREFIX)/bin/att-demo

clean:
	rm -rf build $(VENV) *.egg-info
