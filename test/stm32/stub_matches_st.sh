#!/usr/bin/env bash
# usage: [CC=cc] [ST_DIR=build/st] [BUILD=build] bash test/stm32/stub_matches_st.sh [f4|g4|h7...]
# (from the repository root) Every constant test/stm32/stub/stm32_hal_stub.h defines that ST's
# headers also define must carry ST's value, for each family the stub stands for: F4
# (stm32f446xx, the default), G4 (-DJ288_STUB_G4, stm32g474xx), H7 (-DJ288_STUB_H7,
# stm32h743xx). For each family whose sources scripts/fetch-st.sh has fetched into ST_DIR, the
# names both define (object-like, integer-valued: peripheral pointers are left out) are
# printed by one small program built twice with the host compiler, once against the stub and
# once against ST's CMSIS and HAL headers (with the boards' HAL configurations), and the two
# lists must be equal. ST's sources are not in the repository and CI has no network (Debian
# packages no STM32 headers): a family not fetched is skipped with a notice, so in CI this
# check says what it skipped and passes; it runs in `make test` and `make firmware` wherever
# `bash scripts/fetch-st.sh` has been run (ST_MIRROR=dir for a local mirror).
set -u
cc=${CC:-cc}
st=${ST_DIR:-build/st}
work=${BUILD:-build}/stub-vs-st
families=("$@")
[ ${#families[@]} -eq 0 ] && families=(f4 g4 h7)
stub=test/stm32/stub/stm32_hal_stub.h
mkdir -p "$work" || exit 1
fail=0 checked=0

for f in "${families[@]}"; do
    case $f in
    f4) def=J288_STUB_F4 dev=STM32F446xx conf=examples/stm32_hal/nucleo_f446re ;;
    g4) def=J288_STUB_G4 dev=STM32G474xx conf=examples/stm32_hal/nucleo_g474re ;;
    h7) def=J288_STUB_H7 dev=STM32H743xx conf=test/stm32/h7 ;;
    *) echo "stub_matches_st: unknown family '$f' (f4, g4, h7)" >&2; exit 2 ;;
    esac
    if ! [ -f "$st/stm32${f}xx_hal_driver/.tag" ] || ! [ -f "$st/cmsis_device_$f/.tag" ] ||
        ! [ -f "$st/cmsis_core/.tag" ]; then
        echo "stub_matches_st: $f skipped: ST's $f headers are not in $st (bash scripts/fetch-st.sh $f)"
        continue
    fi
    st_flags=(-std=gnu11 -w -D"$dev" -DUSE_HAL_DRIVER -I"$conf" -Iexamples/stm32_hal
              -isystem "$st/stm32${f}xx_hal_driver/Inc" -isystem "$st/cmsis_device_$f/Include"
              -isystem "$st/cmsis_core/Include")
    stub_flags=(-std=c99 -w -D"$def" -Itest/stm32/stub)
    # Object-like macros: NAME and its definition, from each side.
    printf '#include "stm32_hal_stub.h"\n' >"$work/stub_$f.c"
    printf '#include "stm32%sxx_hal.h"\n' "$f" >"$work/st_$f.c"
    "$cc" "${stub_flags[@]}" -E -dM "$work/stub_$f.c" >"$work/stub_$f.dm" &&
        "$cc" "${st_flags[@]}" -E -dM "$work/st_$f.c" >"$work/st_$f.dm" ||
        { echo "FAIL: $f: the headers do not preprocess"; fail=1; continue; }
    # The stub's own names (not those of the system headers it includes), valued (not empty,
    # no pointer cast), that ST defines too.
    grep -oE '^#define [A-Za-z_][A-Za-z0-9_]* ' "$stub" | awk '{print $2}' | sort -u >"$work/own_$f"
    awk '$1=="#define" && $2 !~ /\(/ && NF>=3 && $0 !~ /[*&]/ {print $2}' "$work/stub_$f.dm" |
        sort -u | comm -12 - "$work/own_$f" >"$work/stub_$f.names"
    awk '$1=="#define" && $2 !~ /\(/ {print $2}' "$work/st_$f.dm" | sort -u |
        comm -12 "$work/stub_$f.names" - >"$work/common_$f"
    {
        printf '#include <stdio.h>\n#include HEADER\nint main(void)\n{\n'
        while read -r n; do
            printf '    printf("%%s 0x%%llx\\n", "%s", (unsigned long long)(%s));\n' "$n" "$n"
        done <"$work/common_$f"
        printf '    return 0;\n}\n'
    } >"$work/probe_$f.c"
    if ! "$cc" "${stub_flags[@]}" '-DHEADER="stm32_hal_stub.h"' "$work/probe_$f.c" -o "$work/probe_stub_$f" ||
        ! "$cc" "${st_flags[@]}" "-DHEADER=\"stm32${f}xx_hal.h\"" "$work/probe_$f.c" -o "$work/probe_st_$f"; then
        echo "FAIL: $f: the probe does not build"; fail=1; continue
    fi
    "$work/probe_stub_$f" >"$work/values_stub_$f" && "$work/probe_st_$f" >"$work/values_st_$f" ||
        { echo "FAIL: $f: the probe does not run"; fail=1; continue; }
    if ! diff_out=$(diff "$work/values_st_$f" "$work/values_stub_$f"); then
        echo "FAIL: $f: the stub's constants differ from ST's (< ST, > stub):"
        echo "$diff_out" | grep '^[<>]' | sed 's/^/    /'
        fail=1
    fi
    n=$(wc -l <"$work/common_$f")
    echo "stub_matches_st: $f: $n constants compared with ST's $(cat "$st/stm32${f}xx_hal_driver/.tag") / $(cat "$st/cmsis_device_$f/.tag") headers"
    checked=$((checked + 1))
done
[ $fail -eq 0 ] && echo "stub_matches_st: OK ($checked of ${#families[@]} families checked)"
exit $fail
