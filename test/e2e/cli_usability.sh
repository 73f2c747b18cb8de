#!/usr/bin/env bash
# What a new user tripped on in the first hour, each checked against j288-sim: the bus options
# before the command as after it; one range per quantity, checked where the value is given and
# named by where it came from (a kp in the config is the config's error, not "--kp"); $J288_BAUD
# for the buses of a config; `--config F stop` naming the bus that is busy; scan saying
# "possible duplicate ids" when two servos answer one id; scripts/bench-robot.sh running on its
# own; the man page listing every command apart, with every command's options; the docs' claims
# about the log's columns, the packages to purge and the python to use. Run from the
# repo root with BIN set (make test does). Waits poll, bounded.
set -u
cd "$(dirname "$0")/../.."
. test/e2e/lib_e2e.sh
SIM_DIR=$E2E_TMP
. test/e2e/lib_sim.sh
trap 'sim_cleanup TERM' EXIT
need_built "$J288" "$SIM"
e2e_need_python

sim_start_linked a --ids 1,2,3 --quiet --exit-after "$(e2e_scaled 120)" --dup 2 || exit 1
DEV_A=$DEV LOG_A=$SIM_DIR/a.log
sim_start_linked b --ids 1 --quiet --exit-after "$(e2e_scaled 120)" || exit 1
DEV_B=$DEV LOG_B=$SIM_DIR/b.log
M=(--margin-us 1000000)

# logged FILE REGEX: up to 20 s for the simulator to have logged a matching command.
logged() {
    for _ in $(seq 1 "$(e2e_scaled 400)"); do grep -Eq -- "$2" "$1" 2>/dev/null && return 0; sleep 0.05; done
    echo "never logged: /$2/"; return 1
}

# ---- the bus options before the command (2af1ea0: "unknown option '--margin-us'") ------------
expect_true margin_before_command "$J288" --port "$DEV_B" --margin-us 1000000 scan --ids 1
expect_true retries_echo_before_command bash -c \
    "'$J288' --port '$DEV_B' --retries 1 --margin-us 1000000 status --id 1 >/dev/null"
expect_bad global_margin_range 2 '^j288: --margin-us: 0 is out of range 1\.\.10000000$' \
    "$J288" --port "$DEV_B" --margin-us 0 scan

# ---- one range per quantity, named by where it came from --------------------------------------
# The command line takes what the config takes (2af1ea0: 1..1000000 here, 0-10000000 there).
expect_true margin_as_in_config "$J288" --port "$DEV_B" scan --ids 1 --margin-us 2000000
printf 'buses:\n  - {name: left, port: %s, margin_us: 0}\njoints:\n  - {name: hip, id: 1}\n' "$DEV_B" \
    >"$E2E_TMP/margin0.yaml"
expect_bad config_margin_range 1 "margin0\.yaml:2: bus 'left': margin_us: 0 is out of range \(1-10000000\)" \
    "$J288" --config "$E2E_TMP/margin0.yaml" status
# A kp the wire cannot carry is the file's error when the file is read (2af1ea0 loaded it, then
# said "--kp: 1e+09 is out of range for the wire" though no --kp was given).
printf 'buses:\n  - {name: left, port: %s, margin_us: 1000000}\njoints:\n  - name: hip\n    id: 1\n    kp: 1e9\n' \
    "$DEV_B" >"$E2E_TMP/kp.yaml"
expect_bad config_kp_named_by_file nonzero "kp\.yaml:6: joint 'hip': kp: 1e9 is out of range \(0 to 2128\.4\)" \
    "$J288" hold --joint hip --config "$E2E_TMP/kp.yaml" --duration 0.1
expect_bad option_kp_range 2 '^j288 calibrate: --kp: 3000 is out of range 0\.\.2128\.4$' \
    "$J288" calibrate --id 1 --port "$DEV_B" --kp 3000

# ---- $J288_BAUD for a config's buses (2af1ea0 ignored it: Wine could not open them) -----------
printf 'buses:\n  - {name: left, port: %s, margin_us: 1000000}\njoints:\n  - {name: hip, id: 1}\n' "$DEV_B" \
    >"$E2E_TMP/robot.yaml"
expect_bad env_baud_for_config 2 "^j288 status: \\\$J288_BAUD: 'fast' is not a whole number$" \
    env J288_BAUD=fast "$J288" --config "$E2E_TMP/robot.yaml" status
expect_bad env_baud_for_top 2 "^j288 top: \\\$J288_BAUD: 'fast' is not a whole number$" \
    env J288_BAUD=fast "$J288" top --config "$E2E_TMP/robot.yaml" --once
expect_true baud_option_for_config bash -c \
    "'$J288' --config '$E2E_TMP/robot.yaml' status --baud 4000000 >/dev/null"

# ---- --config F stop names the bus that is busy (2af1ea0: "bus right: bus 'bus': ...") -------
t_stop_names_busy_bus() {
    local pid rc
    printf 'buses:\n  - {name: left, port: %s}\n  - {name: right, port: %s}\njoints:\n  - {name: a, bus: left, id: 1}\n  - {name: b, bus: right, id: 1}\n' \
        "$DEV_A" "$DEV_B" >"$E2E_TMP/two.yaml"
    : >"$LOG_B"
    "$J288" --port "$DEV_B" hold --id 1 --duration 30 --watchdog off "${M[@]}" >/dev/null 2>&1 &
    pid=$!
    BG_PIDS+=("$pid")
    logged "$LOG_B" ' id=1 status=1 ' || return 1
    "$J288" --config "$E2E_TMP/two.yaml" stop >"$E2E_TMP/out" 2>"$E2E_TMP/err"; rc=$?
    stop_pids TERM "$pid"
    [ $rc -eq 1 ] || { echo "exit $rc"; return 1; }
    grep -q "^broadcast lock sent on 1 of 2 buses$" "$E2E_TMP/out" &&
        grep -Eq "^j288 stop: bus 'right': .* is in use by PID $pid" "$E2E_TMP/err" &&
        ! grep -q "bus 'bus'" "$E2E_TMP/err" || { cat "$E2E_TMP/out" "$E2E_TMP/err"; return 1; }
}
e2e_check stop_names_busy_bus t_stop_names_busy_bus

# ---- scan: two servos answering one id --------------------------------------------------------
t_scan_duplicate_ids() {
    "$J288" --port "$DEV_A" scan --ids 1,2,3 "${M[@]}" >"$E2E_TMP/out" 2>"$E2E_TMP/err" || { cat "$E2E_TMP/err"; return 1; }
    grep -Eq '^2 +lock .*  \(possible duplicate ids\)$' "$E2E_TMP/out" &&
        [ "$(grep -c 'possible duplicate' "$E2E_TMP/out")" -eq 1 ] &&
        grep -q '^note: id 2: more bytes came after its reply: possible duplicate ids .*vendor' "$E2E_TMP/err" ||
        { cat "$E2E_TMP/out" "$E2E_TMP/err"; return 1; }
    "$J288" --port "$DEV_A" scan --json --ids 1,2,3 "${M[@]}" 2>/dev/null >"$E2E_TMP/out" || return 1
    python3 -c 'import json, sys
o = json.load(open(sys.argv[1]))
assert [(s["id"], s["possible_duplicate"]) for s in o] == [(1, False), (2, True), (3, False)], o' "$E2E_TMP/out"
}
e2e_check scan_duplicate_ids t_scan_duplicate_ids

# The rest checks scripts and docs, not the programs' memory: not under memcheck
# (scripts/test-valgrind.sh), where it took two minutes.
if [ -n "${J288_VALGRIND:-}" ]; then
    e2e_summary
    exit $?
fi

# ---- scripts/bench-robot.sh on its own (2af1ea0: "e2e_scaled: command not found") -----------
t_bench_robot_runs() {
    DURATION=0.2 bash scripts/bench-robot.sh >"$E2E_TMP/out" 2>"$E2E_TMP/err" || { cat "$E2E_TMP/err"; return 1; }
    ! grep -q 'command not found\|invalid floating point' "$E2E_TMP/err" &&
        grep -Eq '^4 buses x 3 servos \(robot\) +[0-9]+$' "$E2E_TMP/out" || { cat "$E2E_TMP/out" "$E2E_TMP/err"; return 1; }
}
e2e_check bench_robot_runs t_bench_robot_runs

# ---- what the docs say about the programs and packages -----------------------------------------
# (test/e2e/docs_run.sh runs the commands the docs show; these are the claims it cannot run)
t_readme_csv_columns() {
    # the robot form's log columns as tools/j288/README.md lists them (2af1ea0 listed
    # "time_s, cycle, joint, bus, id, fresh, known, ..." for a header that is not that)
    local doc
    "$J288" --config "$E2E_TMP/robot.yaml" log --duration 0.05 --csv "$E2E_TMP/r.csv" >/dev/null || return 1
    doc=$(grep '^| `log \[--rate HZ\]' tools/j288/README.md | sed -n 's/.*(`\([a-z_,]*\)`), then `\([a-z_,]*\)`.*/\1,\2/p')
    [ "$doc" = "$(head -n1 "$E2E_TMP/r.csv")" ] || { echo "README: '$doc'"; echo "header: '$(head -n1 "$E2E_TMP/r.csv")'"; return 1; }
}
e2e_check readme_csv_columns t_readme_csv_columns
t_readme_purge_names_every_package() {
    # "sudo apt purge ..." must name every package debian/control builds (2af1ea0: libj288-0
    # alone, which leaves j288-tools and j288-dds installed)
    local line p
    line=$(tr '\n' ' ' <README.md | grep -o 'sudo apt purge [a-z0-9 .-]*' | head -n1)
    for p in $(sed -n 's/^Package: //p' debian/control); do
        [[ " $line " == *" $p "* ]] || { echo "README's '$line' leaves $p installed"; return 1; }
    done
}
e2e_check readme_purge_names_every_package t_readme_purge_names_every_package
t_readme_pip_uses_debian_python() {
    # the offline pip line needs Debian's python3-setuptools and python3-wheel: the system's
    # /usr/bin/python3, as pip-check.sh uses (2af1ea0: "python3", which under pyenv failed with
    # "invalid command 'bdist_wheel'")
    grep -q '^/usr/bin/python3 -m venv --system-site-packages v && v/bin/pip install --no-build-isolation \.$' README.md &&
        grep -q '^/usr/bin/python3 -m venv --system-site-packages ' scripts/pip-check.sh
}
e2e_check readme_pip_uses_debian_python t_readme_pip_uses_debian_python

# ---- the man page: every command apart, with its options -------------------------------------
t_man_page() {
    local c
    bash scripts/man-include.sh "$J288" "$E2E_TMP/j288.h2m" || return 1
    help2man --no-info --name test --include "$E2E_TMP/j288.h2m" "$J288" >"$E2E_TMP/j288.1" || return 1
    # each command a paragraph of its own in the list (2af1ea0: "calibrate fit ... top live ...")
    for c in $("$J288" --help | sed -n '/^commands:/,/^$/s/^  \([a-z]*\) .*/\1/p'); do
        grep -A1 '^\.TP$' "$E2E_TMP/j288.1" | grep -qx "$c" && grep -q "^\.SS \"j288 $c\"$" "$E2E_TMP/j288.1" ||
            { echo "$c: no entry or no section"; return 1; }
    done
    ! grep -q 'calibrate.*top' "$E2E_TMP/j288.1" || { echo "calibrate and top run together"; return 1; }
    grep -q '^  up / down        target + / - one step' "$E2E_TMP/j288.1" &&
        grep -q '^\.SS "j288 \\-\\-config FILE log|status|hold|stop (the whole robot)"$' "$E2E_TMP/j288.1"
}
if bash scripts/need.sh help2man help2man; then
    e2e_check man_page t_man_page
elif [ "${CI:-}" = true ]; then
    e2e_fail man_page "help2man missing"
fi
e2e_summary
