# `make demo` (the README's first command): builds the tool and the simulator only (no
# Unity, no download: a compiler and make suffice), then runs scripts/demo.sh, the j288 tool
# against j288-sim on a pseudo-terminal (results in $(BUILD)/demo/).
# Owner: cli.

.PHONY: demo
demo: $(BIN)/j288 $(BIN)/j288-sim
	BUILD=$(BUILD) BIN=$(BIN) bash scripts/demo.sh
