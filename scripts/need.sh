#!/usr/bin/env bash
# usage: scripts/need.sh TOOL PACKAGE...
# "TOOL is needed": succeed when TOOL is on PATH. Otherwise, with CI=true, an error naming the
# Debian packages (exit 2); outside CI a one-line notice saying what to install (exit 1), so
# that the caller skips its step. In make: $(call REQUIRE,tool,packages) (Makefile); in a
# script: bash scripts/need.sh tool packages || exit $(( $? == 1 ? 0 : 1 ))
tool=$1; shift
command -v "$tool" >/dev/null 2>&1 && exit 0
if [ "${CI:-}" = true ]; then
    echo "error: $tool not found (CI=true: a missing tool is a failure); install: $*" >&2
    exit 2
fi
echo "notice: skipping, $tool not found; install with: apt-get install -y --no-install-recommends $*" >&2
exit 1
