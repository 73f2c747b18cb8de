#!/usr/bin/env bash
# usage: [CC=cc] [ST_DIR=build/st ARM_CC=arm-none-eabi-gcc] bash test/stm32/dcache_needs_a_cache.sh
# (from the repository root) J288_STM32_DCACHE=1 on a core without a data cache (a Cortex-M4:
# its CMSIS headers declare no cache maintenance) must stop the build with an #error that says
# why, and nothing else, not with implicit declarations; on a Cortex-M7 it must build. The HAL
# stub models both cores (__DCACHE_PRESENT=0U or 1U). With ST_DIR and ARM_CC (mk/firmware.mk,
# after scripts/fetch-st.sh) the same against ST's real F4 and, when fetched, H7 HAL (there with
# J288_STM32_DCACHE=0 too: the port's D-cache check reads CMSIS's SCB and MPU).
set -u
cc=${CC:-cc}
flags=(-std=c99 -Wall -Wextra -Werror -fsyntax-only -Ilib/include -Iport/stm32_hal -Itest/stm32/stub)
fail=0

if ! "$cc" "${flags[@]}" -DJ288_STM32_DCACHE=1 -D__DCACHE_PRESENT=1U port/stm32_hal/j288_stm32.c; then
    echo "FAIL: J288_STM32_DCACHE=1 on a core with a data cache does not build"; fail=1
fi
if out=$("$cc" "${flags[@]}" -DJ288_STM32_DCACHE=1 -D__DCACHE_PRESENT=0U port/stm32_hal/j288_stm32.c 2>&1); then
    echo "FAIL: J288_STM32_DCACHE=1 on a core without a data cache builds"; fail=1
elif ! grep -q 'J288_STM32_DCACHE=1 needs a core with a data cache' <<<"$out" ||
    [ "$(grep -c 'error:' <<<"$out")" -ne 1 ]; then
    echo "FAIL: the build does not stop with the one error that says why:"; echo "$out" | head -n 5; fail=1
fi
if ! "$cc" "${flags[@]}" -DJ288_STM32_DCACHE=0 -D__DCACHE_PRESENT=0U port/stm32_hal/j288_stm32.c; then
    echo "FAIL: J288_STM32_DCACHE=0 on a core without a data cache does not build"; fail=1
fi
if [ -n "${ST_DIR:-}" ] && [ -n "${ARM_CC:-}" ]; then
    st=(-Iport/stm32_hal -Ilib/include -isystem "$ST_DIR/cmsis_core/Include" -std=c99 -Wall -Wextra
        -Werror -fsyntax-only -DUSE_HAL_DRIVER)
    f4=(-mcpu=cortex-m4 -mthumb -DSTM32F446xx -Iexamples/stm32_hal/nucleo_f446re
        -isystem "$ST_DIR/stm32f4xx_hal_driver/Inc" -isystem "$ST_DIR/cmsis_device_f4/Include")
    if out=$("$ARM_CC" "${st[@]}" "${f4[@]}" -DJ288_STM32_DCACHE=1 port/stm32_hal/j288_stm32.c 2>&1); then
        echo "FAIL: J288_STM32_DCACHE=1 builds against the F4 HAL"; fail=1
    elif ! grep -q 'J288_STM32_DCACHE=1 needs a core with a data cache' <<<"$out" ||
        [ "$(grep -c 'error:' <<<"$out")" -ne 1 ]; then
        echo "FAIL: against the F4 HAL the build does not stop with the one error that says why:"
        echo "$out" | head -n 5; fail=1
    fi
    if [ -f "$ST_DIR/stm32h7xx_hal_driver/.tag" ]; then
        h7=(-mcpu=cortex-m7 -mthumb -DSTM32H743xx -Itest/stm32/h7
            -isystem "$ST_DIR/stm32h7xx_hal_driver/Inc" -isystem "$ST_DIR/cmsis_device_h7/Include")
        if ! "$ARM_CC" "${st[@]}" "${h7[@]}" -Wpedantic -Wconversion -Wshadow -DJ288_STM32_DCACHE=1 \
            port/stm32_hal/j288_stm32.c; then
            echo "FAIL: J288_STM32_DCACHE=1 does not build against the H7 HAL"; fail=1
        fi
        # J288_STM32_DCACHE=0 on the M7: the D-cache / MPU check against CMSIS's SCB and MPU
        if ! "$ARM_CC" "${st[@]}" "${h7[@]}" -Wpedantic -Wconversion -Wshadow -DJ288_STM32_DCACHE=0 \
            port/stm32_hal/j288_stm32.c; then
            echo "FAIL: J288_STM32_DCACHE=0 does not build against the H7 HAL"; fail=1
        fi
    else
        echo "dcache_needs_a_cache: no H7 HAL in $ST_DIR, its check skipped"
    fi
fi
[ $fail -eq 0 ] && echo "dcache_needs_a_cache: OK"
exit $fail
