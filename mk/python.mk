# The Python package (python/j288: ctypes over $(SO_LIB); pip: pyproject.toml and setup.py).
#   make python       the shared library, copied into the package in place:
#                     PYTHONPATH=python python3 -c 'import j288; print(j288.__version__)'
#   python tests      python/tests with pytest against j288-sim and this build's $(SO_LIB), in
#                     `make test` (scripts/python-test.sh)
#   make pip-check    pip install into a fresh venv, the tests against it, a wheel
.PHONY: python python-test pip-check
PY_SO := python/j288/libj288.so

$(PY_SO): $(SO_REAL)
	cp $(SO_REAL) $@

python: $(PY_SO)

python-test: $(SO_LIB) $(SIM_BIN)
	$(call RUN_TESTS,scripts/python-test.sh)

TEST_SCRIPTS += scripts/python-test.sh
TEST_DEPS += $(SO_LIB) $(SIM_BIN)

pip-check: $(SIM_BIN)
	BUILD=$(BUILD) BIN=$(BIN) bash scripts/pip-check.sh
