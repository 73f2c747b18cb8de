#!/usr/bin/env bash
# examples/linux against j288-sim: a servo's status, an absent servo, a missing device and
# bad arguments. Run from the repo root with BIN set (make test does); J288_SIM may name
# another simulator binary (make test-valgrind).
set -u
. test/e2e/lib_e2e.sh
SIM=${J288_SIM:-$BIN/j288-sim}
EX=$BIN/linux-status
trap 'kill -TERM $sim_pid 2>/dev/null; wait $sim_pid 2>/dev/null; e2e_cleanup_tmp' EXIT

"$SIM" --ids 1,2 --link "$E2E_TMP/bus" --exit-after "$(e2e_scaled 120)" >"$E2E_TMP/sim.out" 2>"$E2E_TMP/sim.err" &
sim_pid=$!
for _ in $(seq 1 600); do [ -L "$E2E_TMP/bus" ] && break; sleep 0.05; done # up to 30 s

E2E_CMD_TIMEOUT=30
e2e_run "$EX" "$E2E_TMP/bus" 2
if [ "$E2E_RC" -eq 0 ] && [[ "$E2E_OUT" =~ ^servo\ 2:\ output\ [0-9.]+\ rad,\ .*\ V,\ case\ .*faults\ 0x0$ ]]; then
    e2e_pass status
else
    e2e_fail status "exit $E2E_RC, stdout '$E2E_OUT', stderr '$E2E_ERR'"
fi
expect_bad absent 1 '^linux-status: servo 3: ' "$EX" "$E2E_TMP/bus" 3
expect_bad no_device 1 '^linux-status: ' "$EX" "$E2E_TMP/nothing" 1
expect_bad usage 2 '^usage: linux-status DEVICE ID' "$EX" "$E2E_TMP/bus" 15
e2e_summary
