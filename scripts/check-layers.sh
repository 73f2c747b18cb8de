#!/usr/bin/env bash
# usage: scripts/check-layers.sh
# Layers keep to their side (issue 28): no code reads or writes a private field of another
# module's struct: the tools and host/ none of the joint's, bus's, scheduler's, serial port's or
# robot's; lib/src/sched.c none of j288_bus_t's. Fails naming each offending line. A few
# seconds (KEEP=1 keeps the scratch tree and says where).
#
# How, so that the compiler, not a pattern, decides which struct a field belongs to: a struct is
# private where its header says so, in a comment starting "Private" at the top level of its body
# (private from there to its end) or in the comment just before it (all of it). The script copies
# lib/ port/ host/ tools/ examples/ into a scratch tree, wraps each private part in macros
# (line numbers unchanged) and compiles every C file there with gcc -fsyntax-only. For a file of
# the struct's own module the macros are empty; for any other they make the private part a
# member of its own (`struct { ... } j288_private_;`), so that naming one of its fields is an
# error ("has no member named"). A module, for header DIR/S.h: S.h, S.c and S_priv.h in DIR
# (lib/src for lib/include/j288), and the files OWNERS adds. An error inside a module's own
# header (an inline helper of bus_priv.h compiled from sched.c) is that module's. Tests are
# exempt (they exercise a module's inside on purpose). The Windows files are compiled with
# mingw-w64, the DDS bridge against idlc's headers, where installed (CI=true: a missing tool is
# a failure, scripts/need.sh).
set -u
export LC_ALL=C
cd "$(dirname "$0")/.." || exit 1

# Modules of more files than S.h, S.c and S_priv.h: "HEADER: further files of its module".
OWNERS='
lib/include/j288/joint.h: lib/src/joint_cal.c
host/j288_rt.h: host/j288_rt_os.h host/j288_rt_linux.c host/j288_rt_win32.c
port/desktop/j288_serial.h: port/desktop/j288_serial_os.h port/linux/j288_linux.c port/windows/j288_windows.c
port/linux/j288_linux.h: port/desktop/j288_serial_os.h port/linux/j288_linux.c
port/windows/j288_windows.h: port/desktop/j288_serial_os.h port/windows/j288_windows.c
'
# Files allowed to read private fields for now, each "FILE: why". Keep it empty.
ALLOW='
'

tmp=$(mktemp -d)
if [ -n "${KEEP:-}" ]; then echo "check-layers: scratch tree $tmp"; else trap 'rm -rf "$tmp"' EXIT; fi
S=$tmp/src
mkdir -p "$S"
cp -r lib port host tools examples "$S/"
printf '%s\n' "$OWNERS" >"$tmp/owners.txt"
printf '%s\n' "$ALLOW" | grep -v '^#' >"$tmp/allow.txt"
: >"$tmp/private.txt"

# Wrap the private parts in J288_PRIV_BEGIN_<header>/_END_<header>; list "TYPE HEADER" for each
# struct with one (its tag as "struct TAG", its typedef name).
cat >"$tmp/wrap.awk" <<'EOF'
BEGIN { id = rel; gsub(/[^A-Za-z0-9]/, "_", id); beg = "J288_PRIV_BEGIN_" id; end = "J288_PRIV_END_" id }
function strip(s) { # the line's code without comments, for brace counting
    if (incom) { if (!sub(/^.*\*\//, "", s)) return ""; incom = 0 }
    gsub(/\/\*([^*]|\*+[^*\/])*\*+\//, "", s); sub(/\/\/.*/, "", s)
    if (sub(/\/\*.*/, "", s)) incom = 1
    return s
}
{
    line = $0; wascom = incom; code = strip($0); pre = ""; first = 0
    if (!instruct && code ~ /(^|[^A-Za-z0-9_])struct([ \t]+[A-Za-z0-9_]+)?[ \t]*\{/) {
        tag = ""
        if (match(code, /struct[ \t]+[A-Za-z0-9_]+/)) { tag = substr(code, RSTART + 6, RLENGTH - 6); gsub(/[ \t]/, "", tag) }
        open = (lastcom ~ /Private/)
        if (open) sub(/\{/, "{ " beg, line)
        instruct = 1; depth = 0; first = 1
    }
    if (instruct && depth == 1 && !first && !open && line ~ /^[ \t]*\/\*[ \t]*Private/) { pre = beg " "; open = 1 }
    o = gsub(/\{/, "{", code); c = gsub(/\}/, "}", code)
    was = depth; if (instruct) depth += o - c
    if (instruct && was >= 1 && depth == 0) {
        if (open) {
            sub(/\}/, end " }", line)
            if (tag != "") print "struct " tag " " rel >>list
            if (match(code, /\}[ \t]*[A-Za-z0-9_]+[ \t]*;/)) {
                name = substr(code, RSTART + 1, RLENGTH - 2); gsub(/[ \t;]/, "", name); print name " " rel >>list
            }
        }
        open = 0; instruct = 0
    }
    print pre line
    if (code ~ /[^ \t]/) lastcom = ""
    else if (wascom || $0 ~ /\/\*/) lastcom = lastcom " " $0
}
EOF
find "$S" -name '*.h' | sort | while read -r h; do
    awk -v rel="${h#"$S/"}" -v list="$tmp/private.txt" -f "$tmp/wrap.awk" "$h" >"$h.new" && mv "$h.new" "$h"
done
# A typedef of a private struct's tag elsewhere (typedef struct j288_robot j288_robot_t;).
while read -r kw tag hdr; do
    [ "$kw" = struct ] || continue
    grep -rhoE "typedef[ \t]+struct[ \t]+${tag}[ \t]+[A-Za-z0-9_]+[ \t]*;" "$S" |
        sed -E "s/.*[ \t]([A-Za-z0-9_]+)[ \t]*;/\\1 ${hdr//\//\\/}/"
done <"$tmp/private.txt" | sort -u >"$tmp/typedefs.txt"
cat "$tmp/typedefs.txt" >>"$tmp/private.txt"

# own(FILE, HEADER): FILE is of the module whose private fields HEADER declares.
cat >"$tmp/own.awk" <<'EOF'
FILENAME ~ /private.txt$/ { hdr[$1 == "struct" ? "struct " $2 : $1] = $NF; hdrs[$NF] = 1; next }
FILENAME ~ /owners.txt$/ { o_ = $1; sub(/:$/, "", o_); for (i = 2; i <= NF; i++) extra[o_, $i] = 1; next }
FILENAME ~ /allow.txt$/ { a_ = $1; sub(/:$/, "", a_); if (a_ != "") allow[a_] = 1; next }
function own(f, h,   dir, stem) {
    dir = h; sub(/\/[^\/]*$/, "", dir); stem = h; sub(/^.*\//, "", stem); sub(/\.h$/, "", stem)
    if (dir == "lib/include/j288") dir = "lib/src"
    return (f == h) || (f == (dir "/" stem ".c")) || (f == (dir "/" stem "_priv.h")) || ((h, f) in extra)
}
EOF
# The macros for FILE: empty for its own module's structs (so that another module's private
# field reached through one of them still shows), a member of its own for the rest.
cat "$tmp/own.awk" - >"$tmp/defs.awk" <<'EOF'
END {
    for (h in hdrs) {
        id = h; gsub(/[^A-Za-z0-9]/, "_", id)
        if (own(f, h)) { print "-DJ288_PRIV_BEGIN_" id "="; print "-DJ288_PRIV_END_" id "=" }
        else { print "-DJ288_PRIV_BEGIN_" id "=struct {"; print "-DJ288_PRIV_END_" id "=} j288_private_;" }
    }
}
EOF
# Which struct an error names, and whether the file it is in is that struct's module.
cat "$tmp/own.awk" - >"$tmp/verdict.awk" <<'EOF'
function type_header(s,   t, a) { # the header of the private struct the error names
    t = s; sub(/.*error: '/, "", t); sub(/'.*/, "", t); sub(/^(const |volatile )*/, "", t)
    if (t in hdr) return hdr[t]
    if (s ~ /\{aka '/) { a = s; sub(/.*\{aka '(const |volatile )*/, "", a); sub(/'.*/, "", a); if (a in hdr) return hdr[a] }
    return ""
}
{
    f = $0; sub(/:.*/, "", f)
    if ($0 ~ /has no member named/ && (h = type_header($0)) != "") {
        if (!own(f, h) && !(f in allow)) { print $0 " (private to " h ")"; reads++ }
    } else if ($0 ~ /unknown field .* specified in initializer/) { # no type named: f must own one
        ok = (f in allow); for (h in hdrs) if (own(f, h)) ok = 1
        if (!ok) { print $0 " (a private field)"; reads++ }
    } else { print; other++ }
}
END { printf "%d %d\n", reads, other > "/dev/stderr" }
EOF

jobs=$(nproc 2>/dev/null || echo 2) n=0
cc_files() { # cc_files COMPILER FLAGS... -- FILES...: each file in the background, $jobs at once
    local cc=$1 flags=() f defs; shift
    while [ "$1" != -- ]; do flags+=("$1"); shift; done; shift
    for f in "$@"; do
        [ -e "$S/$f" ] || continue
        mapfile -t defs < <(awk -v f="$f" -f "$tmp/defs.awk" "$tmp/private.txt" "$tmp/owners.txt" "$tmp/allow.txt")
        while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n; done
        n=$((n + 1))
        (cd "$S" && "$cc" -fsyntax-only -std=c99 -fmax-errors=0 "${defs[@]}" "${flags[@]}" "$f") \
            >"$tmp/errors.$n.txt" 2>&1 &
    done
}
lib=(-Ilib/include)
linux=("${lib[@]}" -Iport/desktop -Iport/linux)
host=("${linux[@]}" -Ihost)
tool=("${host[@]}" -D_XOPEN_SOURCE=700)
: >"$tmp/errors.txt"
cc_files gcc "${lib[@]}" -Ilib/src -- lib/src/*.c
cc_files gcc "${linux[@]}" -- port/desktop/*.c port/linux/*.c examples/linux/*.c
cc_files gcc "${host[@]}" -- host/j288_number.c host/j288_robot.c host/j288_robot_config.c \
    host/j288_rt.c host/j288_rt_linux.c
cc_files gcc "${tool[@]}" -Itools/j288 -- tools/j288/*.c
cc_files gcc "${lib[@]}" -Itools/j288-sim -- tools/j288-sim/*.c
cc_files gcc "${lib[@]}" -Iport/stm32_hal -I"$PWD/test/stm32/stub" -Iexamples/stm32_hal -- \
    port/stm32_hal/*.c examples/stm32_hal/*.c
cc_files gcc "${lib[@]}" -Iport/template -- port/template/*.c
missing=()
if bash scripts/need.sh x86_64-w64-mingw32-gcc mingw-w64 2>/dev/null || [ "${CI:-}" = true ]; then
    cc_files x86_64-w64-mingw32-gcc "${lib[@]}" -Iport/desktop -Iport/windows -Ihost -- \
        port/desktop/*.c port/windows/*.c host/j288_robot.c host/j288_rt.c host/j288_rt_win32.c
else missing+=(x86_64-w64-mingw32-gcc); fi
if { command -v idlc && pkg-config --exists CycloneDDS; } >/dev/null 2>&1 || [ "${CI:-}" = true ]; then
    mkdir -p "$tmp/dds"
    for idl in tools/j288-dds/idl/*.idl; do
        idlc -t -I tools/j288-dds/idl -o "$tmp/dds" "$idl" >>"$tmp/errors.txt" 2>&1
    done
    read -ra dds <<<"$(pkg-config --cflags CycloneDDS 2>/dev/null)"
    cc_files gcc "${tool[@]}" -Itools/j288-dds -I"$tmp/dds" "${dds[@]}" -- tools/j288-dds/*.c
else missing+=("idlc and CycloneDDS (for tools/j288-dds)"); fi

wait
cat "$tmp"/errors.*.txt >>"$tmp/errors.txt" 2>/dev/null
sed -i "s|$S/||g" "$tmp/errors.txt"
# A file compiled twice (gcc and mingw) reports its errors twice: once each.
sort -u "$tmp/errors.txt" | grep -E ': (fatal )?error:|error:' |
    awk -f "$tmp/verdict.awk" "$tmp/private.txt" "$tmp/owners.txt" "$tmp/allow.txt" - 2>"$tmp/counts.txt"
read -r reads other <"$tmp/counts.txt"

status=0
[ ${#missing[@]} -gt 0 ] && echo "notice: check-layers: not compiled (not installed): ${missing[*]}" >&2
if [ "$other" -gt 0 ]; then
    echo "check-layers: $other error(s) other than a private field: the check could not compile these" >&2
    status=1
fi
if [ "$reads" -gt 0 ]; then
    echo "check-layers: $reads read(s) of another module's private fields (use, or add, its accessor)" >&2
    status=1
fi
[ $status -eq 0 ] && echo "check-layers: ok ($(awk '{ print $NF }' "$tmp/private.txt" | sort -u | wc -l) headers with private structs)"
exit $status
