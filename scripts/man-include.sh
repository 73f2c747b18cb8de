#!/usr/bin/env bash
# usage: scripts/man-include.sh J288_BIN [OUT]   (OUT: the file to write; default stdout)
# help2man's include file for the j288 man page (cmake/j288_tools.cmake): a COMMANDS section
# with every command's own --help, as `j288 COMMAND --help` prints it (the commands listed by
# `j288 --help`), and the robot form's (`j288 --config FILE log --help`), each verbatim (roff
# no-fill, backslashes and leading dots escaped), so that the man page has every option.
set -euo pipefail
bin=$1
[ $# -lt 2 ] || exec >"$2"
# verbatim: a help text as roff that prints it unchanged
verbatim() {
    echo ".nf"
    sed -e 's/\\/\\e/g' -e "s/^\\([.']\\)/\\\\\\&\\1/"
    echo ".fi"
}
cmds=$("$bin" --help | sed -n '/^commands:/,/^$/s/^  \([a-z][a-z]*\) .*/\1/p')
[ -n "$cmds" ] || { echo "man-include: no commands in $bin --help" >&2; exit 1; }
echo "[COMMANDS]"
echo "Each command's options, as \\fBj288 \\fICOMMAND\\fB \\-\\-help\\fR prints them."
for c in $cmds; do
    echo ".SS \"j288 $c\""
    "$bin" "$c" --help | verbatim
done
echo ".SS \"j288 \\-\\-config FILE log|status|hold|stop (the whole robot)\""
"$bin" --config /dev/null log --help | verbatim
