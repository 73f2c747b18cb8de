#!/usr/bin/env bash
# Every j288 and j288-sim command shown in README.md, tools/j288/README.md and docs/*.md, run
# against j288-sim (test/e2e/docs_run.py: what runs, how devices map, the markers that say a
# command is not run; the convention is in docs/architecture.md, "Commands in the docs"), and
# the READMEs' `make demo` output against `make demo`. The three groups of files run side by
# side, each with a simulator and a scratch folder of its own (most of the time goes to the
# docs' own durations: log --duration 5, calibrate). DOCS_RUN_VERBOSE=1 lists every command,
# run or not, with its time. Run from the repo root with BIN set (make test does).
set -u
cd "$(dirname "$0")/../.."
. test/e2e/lib_e2e.sh
SIM_DIR=$E2E_TMP
. test/e2e/lib_sim.sh
trap 'sim_cleanup TERM' EXIT
need_built "$J288" "$SIM"
e2e_need_python

# group N FILE...: a simulator (servos 0-14: no id the docs probe is absent, so that a long
# reply margin costs nothing; hip and knee where the docs' example output has them, inside the
# limits the docs give hip), a robot config over it, and docs_run.py over FILE... in the
# background, its lines in $E2E_TMP/out.N.
group() {
    local n=$1 work=$E2E_TMP/work.$1; shift
    sim_start_linked "docs$n" --ids 0,1,2,3,4,5,6,7,8,9,10,11,12,13,14 --quiet --exit-after "$(e2e_scaled 300)" \
        --start-angle 1:0.3 --start-angle 2:1.0 --start-angle 3:-0.5 || return 1
    mkdir -p "$work/build"
    ln -s "$(cd "$BIN" && pwd)" "$work/build/bin"
    printf 'buses:\n  - name: left\n    port: %s\n    margin_us: 1000000\njoints:\n  - name: hip\n    bus: left\n    id: 1\n    limits: [-1.5, 1.5]\n    kp: 20.0\n    kd: 2.5\n  - name: knee\n    bus: left\n    id: 2\n' \
        "$DEV" >"$work/robot.yaml"
    python3 test/e2e/docs_run.py ${DOCS_RUN_VERBOSE:+-v} --dev "$DEV" --log "$SIM_DIR/docs$n.log" \
        --bin "$BIN" --work "$work" "$@" >"$E2E_TMP/out.$n" 2>&1 &
    BG_PIDS+=($!)
}
t0=$SECONDS
group 1 README.md || exit 1
group 2 tools/j288/README.md || exit 1
group 3 docs/*.md || exit 1
for p in "${BG_PIDS[@]}"; do wait "$p"; done
cat "$E2E_TMP"/out.[123]
E2E_TESTS=$(cat "$E2E_TMP"/out.[123] | grep -c '^docs_run:[^ ]*:\(PASS\|FAIL\)')
E2E_FAILURES=$(cat "$E2E_TMP"/out.[123] | grep -c '^docs_run:[^ ]*:FAIL')
echo "docs_run: $((SECONDS - t0)) s in all"
e2e_summary
