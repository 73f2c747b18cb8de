# The STM32 port's build checks and the flashable firmware against ST's real HAL:
#   make firmware      examples/stm32_hal for its boards, against ST's sources fetched by
#                      scripts/fetch-st.sh into build/st/ (skipped with a notice without them)
# CI builds the port and the example against the HAL stub only (`make arm`, mk/target.mk).

# J288_STM32_DCACHE=1 on a core without a data cache stops with an #error that says why.
TEST_SCRIPTS += test/stm32/dcache_needs_a_cache.sh
