#!/usr/bin/env bash
# hard-need.sh TOOL PACKAGE...: succeed when TOOL is on PATH. Otherwise, with CI=true fail;
# outside CI print a one-line notice naming the Debian packages to install and fail with
# status 1 so that the caller can skip its step (`hard-need.sh x pkg || exit 0`).
tool=$1; shift
command -v "$tool" >/dev/null 2>&1 && exit 0
if [ "${CI:-}" = true ]; then
    echo "error: $tool not found (CI=true: a missing tool is a failure); install: $*" >&2
    exit 2
fi
echo "notice: skipping, $tool not found; install with: apt-get install -y --no-install-recommends $*" >&2
exit 1
