# `make test-list`: the names of everything `make test` runs, one per line, in its order: the
# HOST_TESTS binaries relative to $(BUILD) (e.g. test/test_crc32, crc-nibble/test/test_crc32),
# then the TEST_SCRIPTS as repository paths. ctest registers the same names (cmake/
# j288_tests.cmake); scripts/ci-cmake.sh compares the two lists so the builds cannot drift.
# Owner: cmake. (Recipes expand at run time: every fragment's additions are in the lists.)
.PHONY: test-list
test-list:
	@printf '%s\n' $(patsubst $(BUILD)/%,%,$(HOST_TESTS)) $(TEST_SCRIPTS)
