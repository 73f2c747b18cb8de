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
