/* j288_host_wait_win32.c - j288_host_wait() on Windows: one WaitForMultipleObjects() over the
 * ports' read events (j288_windows_wait_any(); the Linux one is host/j288_host_wait.c). */
#include "j288_host_wait.h"

unsigned j288_host_wait(j288_linux_t *const ports[], unsigned n, uint32_t timeout_us, bool ready[])
{
    return j288_windows_wait_any(ports, n, timeout_us, ready);
}
