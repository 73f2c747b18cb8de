#!/usr/bin/env bash
# usage: scripts/check-symbols.sh ARCHIVE [NM]
# lib/ must reference no allocator, stdio, process-exit or other OS symbol. Fails, naming the
# object and symbol, on:
#  - any undefined symbol on the deny list (malloc family, printf family, stdio, abort/exit,
#    assert's helper, time and signal functions), and
#  - any undefined symbol outside the allow list: the archive's own j288_* functions and the
#    freestanding string functions the library may use (memcpy, memset, memmove, memcmp),
#    plus compiler runtime helpers (__aeabi_*, __udivdi3-style libgcc, __stack_chk_*).
set -euo pipefail
lib=${1:?usage: check-symbols.sh ARCHIVE [NM]}
nm=${2:-nm}
[ -f "$lib" ] || { echo "check-symbols: no such archive: $lib" >&2; exit 1; }

deny='^(malloc|calloc|realloc|free|aligned_alloc|posix_memalign|memalign|valloc|reallocarray|strdup|strndup|sbrk|brk|mmap|printf|fprintf|sprintf|snprintf|vprintf|vfprintf|vsprintf|vsnprintf|dprintf|puts|fputs|fputc|putc|putchar|fwrite|fread|fopen|fclose|fflush|fgets|getc|getchar|scanf|sscanf|fscanf|perror|stdout|stderr|stdin|abort|exit|_exit|_Exit|quick_exit|atexit|__assert_fail|__assert|__assert_func|assert|raise|signal|time|clock|clock_gettime|gettimeofday|sleep|usleep|nanosleep|read|write|open|close|ioctl|errno|__errno_location|setjmp|longjmp|getenv|system)$'
allow='^(j288_[A-Za-z0-9_]+|memcpy|memset|memmove|memcmp|__aeabi_[A-Za-z0-9_]+|__(u)?(div|mod)[sdt]i3|__gnu_[A-Za-z0-9_]+|__stack_chk_(fail|guard)|_GLOBAL_OFFSET_TABLE_)$'

# "object: symbol" for every undefined reference.
refs=$("$nm" -A -u "$lib" 2>/dev/null | awk '{ obj=$1; sub(/:[^:]*$/, "", obj); print obj, $NF }' | sort -u)
bad=0
while read -r obj sym; do
    [ -n "${sym:-}" ] || continue
    if [[ "$sym" =~ $deny ]]; then
        echo "check-symbols: $obj references forbidden symbol $sym" >&2; bad=1
    elif ! [[ "$sym" =~ $allow ]]; then
        echo "check-symbols: $obj references $sym, which is not on the allow list" >&2; bad=1
    fi
done <<< "$refs"
n=$(printf '%s\n' "$refs" | grep -c . || true)
if [ $bad -ne 0 ]; then
    echo "check-symbols: FAILED ($lib)" >&2
    exit 1
fi
echo "check-symbols: ok: $n undefined references in $lib, none to an allocator, stdio or exit"
