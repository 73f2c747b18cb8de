#!/usr/bin/env bash
# usage: [CC=cc] bash test/stm32/dcache_needs_a_cache.sh   (from the repository root)
# J288_STM32_DCACHE=1 on a core without a data cache (a Cortex-M4: its CMSIS headers declare
# no cache maintenance) must stop the build with an #error that says why, not with implicit
# declarations. The HAL stub models such a core with __DCACHE_PRESENT=0U.
set -u
cc=${CC:-cc}
flags=(-std=c99 -Wall -Wextra -Werror -fsyntax-only -Ilib/include -Iport/stm32_hal -Itest/stm32/stub)
fail=0

if ! "$cc" "${flags[@]}" -DJ288_STM32_DCACHE=1 -D__DCACHE_PRESENT=1U port/stm32_hal/j288_stm32.c; then
    echo "FAIL: J288_STM32_DCACHE=1 on a core with a data cache does not build"; fail=1
fi
if out=$("$cc" "${flags[@]}" -DJ288_STM32_DCACHE=1 -D__DCACHE_PRESENT=0U port/stm32_hal/j288_stm32.c 2>&1); then
    echo "FAIL: J288_STM32_DCACHE=1 on a core without a data cache builds"; fail=1
elif ! grep -q 'J288_STM32_DCACHE=1 needs a core with a data cache' <<<"$out"; then
    echo "FAIL: the build stops without saying why:"; echo "$out" | head -n 5; fail=1
fi
if ! "$cc" "${flags[@]}" -DJ288_STM32_DCACHE=0 -D__DCACHE_PRESENT=0U port/stm32_hal/j288_stm32.c; then
    echo "FAIL: J288_STM32_DCACHE=0 on a core without a data cache does not build"; fail=1
fi
[ $fail -eq 0 ] && echo "dcache_needs_a_cache: OK"
exit $fail
