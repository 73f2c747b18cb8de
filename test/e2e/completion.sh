#!/usr/bin/env bash
# usage: [BIN=build/bin] test/e2e/completion.sh [COMPLETION_FILE]
# The bash completion (default tools/completion/j288.bash; scripts/check-consumers.sh passes
# the installed one with the installed tools first on PATH): commands, options of the tool and
# of a command, joint names from the robot config given with --config (not the buses'),
# option values, and j288-sim's options. Completion asks the tools' --help: j288 and j288-sim
# are found on PATH, BIN first.
set -u
cd "$(dirname "$0")/../.."
. test/e2e/lib_e2e.sh
trap e2e_cleanup_tmp EXIT
file=$(realpath "${1:-tools/completion/j288.bash}")
[ $# -ge 1 ] || PATH=$(realpath "$BIN"):$PATH
. "$file"

# complete_words LINE: the candidates bash would offer for LINE (completed at its end).
complete_words() {
    local line=$1 fn
    read -ra COMP_WORDS <<<"$line"
    [[ $line == *" " ]] && COMP_WORDS+=("")
    COMP_CWORD=$((${#COMP_WORDS[@]} - 1)) COMP_LINE=$line COMP_POINT=${#line}
    COMPREPLY=()
    fn=$(complete -p "${COMP_WORDS[0]}" | sed -n 's/.*-F \([^ ]*\) .*/\1/p')
    "$fn" "${COMP_WORDS[0]}" "${COMP_WORDS[COMP_CWORD]}" "${COMP_WORDS[COMP_CWORD - 1]}"
    printf '%s\n' "${COMPREPLY[@]}" | sort
}
# offers NAME LINE WANT...: the candidates for LINE include every WANT.
offers() {
    local name=$1 line=$2 w got; shift 2
    got=$(complete_words "$line")
    for w in "$@"; do
        grep -qx -- "$w" <<<"$got" || { e2e_fail "$name" "'$line' offers [$(echo $got)], not $w"; return; }
    done
    e2e_pass "$name"
}
# offers_exactly NAME LINE WORDS: the candidates for LINE are exactly WORDS (space-separated).
offers_exactly() {
    local got; got=$(complete_words "$2" | tr '\n' ' ')
    [ "$got" = "$3 " ] && e2e_pass "$1" || e2e_fail "$1" "'$2' offers [$got], want [$3]"
}

cmds=$(j288 --help | sed -n '/^commands:/,/^$/s/^  \([a-z][a-z-]*\) .*/\1/p')
# shellcheck disable=SC2086
offers commands "j288 " $cmds
offers_exactly command_prefix "j288 cal" calibrate
offers global_options "j288 --" --port --baud --config --version
offers_exactly global_option_prefix "j288 --con" --config
offers move_options "j288 move --" --pos --speed --side --id --joint --config --duration --arrive
offers move_options_after_port "j288 --port /dev/ttyUSB0 move --po" --port --pos
# the bus options before the command take values too: 3000 is not the command
offers_exactly options_after_global_margin "j288 --margin-us 3000 --retries 1 jog --st" --step
offers global_bus_options "j288 --" --margin-us --echo --retries
offers_exactly side_values "j288 move --side " "joint output rotor"
cfg=$E2E_TMP/robot.yaml
cat >"$cfg" <<'YAML'
# two buses, three joints
buses:
  - name: left                 # not a joint
    port: /dev/ttyUSB0
  - {name: right, port: /dev/ttyUSB1}
joints:
  - name: hip
    bus: left
    id: 1
  - {name: knee, bus: left, id: 2}
  - name: ankle   # the last
    id: 3
YAML
offers_exactly joint_names "j288 status --config $cfg --joint " "ankle hip knee"
offers_exactly joint_names_global_config "j288 --config $cfg move --joint k" knee
offers_exactly joint_names_without_config "j288 move --joint " ""
offers sim_options "j288-sim --" --ids --link --truth --seed --exit-after
e2e_summary
