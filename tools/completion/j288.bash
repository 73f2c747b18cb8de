# bash completion for j288 and j288-sim (installed as share/bash-completion/completions/j288,
# with j288-sim a link to it). Commands and options come from the tools' own --help (so a new
# command or option completes without an edit here); joint names from the robot config given
# with --config; device paths for --port and --link, file names for --config, --csv, --log.
# shellcheck shell=bash

# _j288_joints FILE: the joint names of a robot config (block `- name: X` or flow
# `- {name: X, ...}` items under `joints:`; the buses' names are not joints).
_j288_joints() {
    [ -r "$1" ] || return 0
    awk '/^[^ #-]/ { in_joints = ($0 ~ /^joints:/) }
         in_joints && match($0, /(^|[{,[:space:]])name:[[:space:]]*[^,}#[:space:]]+/) {
             s = substr($0, RSTART, RLENGTH); sub(/.*name:[[:space:]]*/, "", s); print s }' "$1"
}

# _j288_help_words CMD...: the long options a --help text names.
_j288_help_words() { "$@" --help 2>&1 | grep -oE -- '--[a-z][a-z0-9-]*' | sort -u; }

_j288() {
    local cur prev words cword i cmd= config=
    _init_completion 2>/dev/null || {
        cur=${COMP_WORDS[COMP_CWORD]} prev=${COMP_WORDS[COMP_CWORD - 1]}
        words=("${COMP_WORDS[@]}") cword=$COMP_CWORD
    }
    local tool=${words[0]}
    # the command: the first word that is neither an option nor a global option's value
    for ((i = 1; i < cword; i++)); do
        case ${words[i]} in
            --config) config=${words[i + 1]}; ((i++)) ;;
            --port | --baud | --margin-us | --retries) ((i++)) ;;
            -*) ;;
            *) [ -z "$cmd" ] && cmd=${words[i]} ;;
        esac
    done
    config=${config/#\~/$HOME}
    case $prev in
        --joint) mapfile -t COMPREPLY < <(compgen -W "$(_j288_joints "$config")" -- "$cur"); return ;;
        --port) mapfile -t COMPREPLY < <(compgen -f -- "${cur:-/dev/tty}"); return ;;
        --config | --csv | --out | -o) mapfile -t COMPREPLY < <(compgen -f -- "$cur"); return ;;
        --side) mapfile -t COMPREPLY < <(compgen -W "joint rotor output" -- "$cur"); return ;;
        --mode) mapfile -t COMPREPLY < <(compgen -W "lock foc" -- "$cur"); return ;;
        --watchdog) mapfile -t COMPREPLY < <(compgen -W "on off" -- "$cur"); return ;;
        --then) mapfile -t COMPREPLY < <(compgen -W "hold lock" -- "$cur"); return ;;
    esac
    if [ -z "$cmd" ] && [[ $cur != -* ]]; then
        # the command list of `j288 --help` (indented words before their description)
        local cmds
        cmds=$("$tool" --help 2>/dev/null | sed -n '/^commands:/,/^$/s/^  \([a-z][a-z-]*\) .*/\1/p')
        mapfile -t COMPREPLY < <(compgen -W "${cmds:-encode decode scan status hold move torque stop log top plot zero calibrate}" -- "$cur")
        return
    fi
    if [ -n "$cmd" ]; then
        mapfile -t COMPREPLY < <(compgen -W "$(_j288_help_words "$tool" "$cmd")" -- "$cur")
    else
        mapfile -t COMPREPLY < <(compgen -W "$(_j288_help_words "$tool") --help" -- "$cur")
    fi
}

_j288_sim() {
    local cur=${COMP_WORDS[COMP_CWORD]} prev=${COMP_WORDS[COMP_CWORD - 1]}
    case $prev in
        --link | --log | --truth) mapfile -t COMPREPLY < <(compgen -f -- "$cur"); return ;;
    esac
    mapfile -t COMPREPLY < <(compgen -W "$(_j288_help_words "${COMP_WORDS[0]}") --help" -- "$cur")
}

complete -F _j288 j288
complete -F _j288_sim j288-sim
