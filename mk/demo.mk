# `make demo` (the README's first command): builds everything, then runs scripts/demo.sh,
# the j288 tool against j288-sim on a pseudo-terminal (results in $(BUILD)/demo/).
# Owner: cli.

.PHONY: demo
demo: all $(BIN)/j288 $(BIN)/j288-sim
	BUILD=$(BUILD) BIN=$(BIN) bash scripts/demo.sh
