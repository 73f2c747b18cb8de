# Codec area: golden vectors from the independent Python generator, and the check that the
# committed copies equal a fresh regeneration (so they cannot drift from the generator).

CODEC_VEC_GEN := tools/vectors/gen_vectors.py
CODEC_VEC_FILES := $(addprefix test/vectors/,commands.txt replies.txt si.txt si_commands.txt \
                     golden_vectors.h)

.PHONY: vectors vectors-check

# Regenerate the committed vectors (commit the result together with the generator change).
vectors:
	$(PYTHON) $(CODEC_VEC_GEN) --out test/vectors

# Regenerate into the build folder and compare with the committed files.
vectors-check:
	BUILD=$(BUILD) PYTHON=$(PYTHON) bash tools/vectors/check-drift.sh

TEST_SCRIPTS += tools/vectors/check-drift.sh

# Instruction counts of the codec's hot paths on the host (valgrind callgrind), see
# docs/performance.md "Codec on the host". Prints one line per mode.
CODEC_BENCH := $(BUILD)/bench/codec_bench
CODEC_BENCH_N ?= 20000
CODEC_BENCH_MODES := crc-table crc-nibble crc-bitwise cmd-encode reply-decode parse-chunk \
                     parse-bytes cmd-from-si

$(CODEC_BENCH): test/bench/codec_bench.c $(LIB_A) $(LIB_HDR)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS_LIB) $(CFLAGS_COMMON) $< $(LIB_A) -o $@ $(LDFLAGS_COMMON) -lm

.PHONY: bench-codec
bench-codec: $(CODEC_BENCH)
	@command -v valgrind >/dev/null || { echo "bench-codec: valgrind not found; install the Debian package valgrind" >&2; exit 1; }
	@ir() { valgrind --tool=callgrind --callgrind-out-file=/dev/null $(CODEC_BENCH) $$1 $(CODEC_BENCH_N) 2>&1 | \
	        sed -n 's/.*Collected : *//p'; }; \
	base=$$(ir none); \
	echo "instructions per call ($(CODEC_BENCH_N) calls each, $(CC), $(OPT)):"; \
	for m in $(CODEC_BENCH_MODES); do \
	    t=$$(ir $$m); echo "  $$m: $$(( (t - base) / $(CODEC_BENCH_N) ))"; \
	done

# The codec tests again with each compile-time CRC backend (J288_CONFIG_CRC_BACKEND): slice4,
# nibble, bitwise, and HW through J288_CONFIG_CRC_HW_FUNCTION (a stand-in from test/support). Each
# variant is a sub-build in $(BUILD)/crc-<variant>; its binaries run in `make test`.
CODEC_CRC_VARIANTS := slice4 nibble bitwise hw
CODEC_CRC_FLAGS_slice4 := -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_SLICE4
CODEC_CRC_FLAGS_nibble := -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_NIBBLE
CODEC_CRC_FLAGS_bitwise := -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_BITWISE
CODEC_CRC_FLAGS_hw := -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_HW \
                      -DJ288_CONFIG_CRC_HW_FUNCTION=codec_hw_crc_stub
CODEC_CRC_TEST_NAMES := test_crc32 test_frame test_parser
CODEC_CRC_TESTS := $(foreach v,$(CODEC_CRC_VARIANTS),$(CODEC_CRC_TEST_NAMES:%=$(BUILD)/crc-$(v)/test/%))

.PHONY: codec-force
codec-force:

# One sub-make per variant builds all its test binaries (grouped pattern targets).
$(CODEC_CRC_TEST_NAMES:%=$(BUILD)/crc-\%/test/%): $(UNITY)/unity.c codec-force
	@$(MAKE) --no-print-directory BUILD=$(BUILD)/crc-$* UNITY_DIR=$(abspath $(UNITY)) \
	    CC=$(CC) EXTRA_CFLAGS='$(EXTRA_CFLAGS) $(CODEC_CRC_FLAGS_$*)' \
	    $(CODEC_CRC_TEST_NAMES:%=$(BUILD)/crc-$*/test/%)

HOST_TESTS += $(CODEC_CRC_TESTS)
