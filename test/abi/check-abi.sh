#!/usr/bin/env bash
# usage: BUILD=... CC=... J288_CFLAGS=... J288_LDFLAGS=... test/abi/check-abi.sh
# A program built with the library's [layout] options (j288/config.h) links and runs; built
# with another value of any of them, it does not link, and the linker names the program's
# values (j288_abi_r<ring>_m<retries>_f<float>). Run by `make test` and `make check-abi`.
set -u
. test/e2e/lib_e2e.sh
trap e2e_cleanup_tmp EXIT
lib=$BUILD/lib/libj288.a
flags="${J288_CFLAGS:--std=c99} -Wno-error -Ilib/include"
tag=$(${NM:-nm} -g --defined-only "$lib" | sed -n 's/.* \(j288_abi_r[0-9]*_m[0-9]*_f[01]\)$/\1/p')
IFS=_ read -r _ _ r m f <<<"$tag"
r=${r#r} m=${m#m} f=${f#f}

# build NAME EXTRA_FLAGS: compile and link test/abi/uses_bus.c; E2E_RC and E2E_ERR as e2e_run.
build() {
    # shellcheck disable=SC2086
    e2e_run $CC $flags $2 test/abi/uses_bus.c "$lib" -o "$E2E_TMP/$1" ${J288_LDFLAGS:-}
}
if [ -n "$tag" ]; then e2e_pass tag_in_library; else e2e_fail tag_in_library "no j288_abi_* object in $lib"; fi

build same ""
if [ "$E2E_RC" -eq 0 ] && "$E2E_TMP/same"; then e2e_pass same_values_link; else
    e2e_fail same_values_link "exit $E2E_RC: $E2E_ERR"; fi
# The same values spelled otherwise (no u suffix, parentheses) are the same layout.
build spelled "-DJ288_CONFIG_RX_RING_SIZE=($r) -DJ288_CONFIG_MAX_RETRIES=$m"
if [ "$E2E_RC" -eq 0 ]; then e2e_pass same_values_spelled_otherwise_link; else
    e2e_fail same_values_spelled_otherwise_link "exit $E2E_RC: $E2E_ERR"; fi

# mismatch NAME FLAGS WANT: the link fails naming WANT.
mismatch() {
    build "$1" "$2"
    if [ "$E2E_RC" -ne 0 ] && grep -q "undefined reference to .$3'" <<<"$E2E_ERR"; then e2e_pass "$1"
    else e2e_fail "$1" "exit $E2E_RC, want an undefined reference to $3: $E2E_ERR"; fi
}
r2=$([ "$r" = 128 ] && echo 64 || echo 128)
m2=$([ "$m" = 5 ] && echo 4 || echo 5)
f2=$((1 - f))
mismatch other_ring_size "-DJ288_CONFIG_RX_RING_SIZE=${r2}u" "j288_abi_r${r2}_m${m}_f${f}"
mismatch other_max_retries "-DJ288_CONFIG_MAX_RETRIES=${m2}u" "j288_abi_r${r}_m${m2}_f${f}"
mismatch other_si_float "-DJ288_CONFIG_SI_FLOAT=$f2" "j288_abi_r${r}_m${m}_f${f2}"
e2e_summary
