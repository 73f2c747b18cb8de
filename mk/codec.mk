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
